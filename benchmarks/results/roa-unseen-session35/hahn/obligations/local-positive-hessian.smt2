; hahn: local:positive:hessian: x^T H x / 2 <= -3881/862436 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (>= (+ (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (<= (+ (* x1 x1) (* x2 x2)) 1.0) (> (+ (* (- (/ 1001247.0 2000000.0)) x1 x1) (* (- (/ 1066331.0 2000000.0)) x1 x2) (* (- (/ 1066331.0 2000000.0)) x2 x1) (* (- (/ 5785513.0 10000000.0)) x2 x2) (* (/ 3881.0 862436.0) (+ (* x1 x1) (* x2 x2)))) 0.0)))
(check-sat)
