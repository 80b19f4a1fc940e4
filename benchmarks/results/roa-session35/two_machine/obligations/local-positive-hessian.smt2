; two_machine: local:positive:hessian: x^T H x / 2 <= -128780/411487 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 405037.0 625000.0)) x0 x0) (* (- (/ 9268573.0 20000000.0)) x0 x1) (* (- (/ 9268573.0 20000000.0)) x1 x0) (* (- (/ 1062853.0 1000000.0)) x1 x1) (* (/ 128780.0 411487.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
