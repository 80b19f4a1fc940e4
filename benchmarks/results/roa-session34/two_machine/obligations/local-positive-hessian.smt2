; two_machine: local:positive:hessian: x^T H x / 2 <= -30413/97178 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 6481189.0 10000000.0)) x0 x0) (* (- (/ 2317561.0 5000000.0)) x0 x1) (* (- (/ 2317561.0 5000000.0)) x1 x0) (* (- (/ 531483.0 500000.0)) x1 x1) (* (/ 30413.0 97178.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
