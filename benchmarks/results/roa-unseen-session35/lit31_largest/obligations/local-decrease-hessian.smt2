; lit31_rational_roa: local:decrease:hessian: x^T H x / 2 <= -78363/944371 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 1647997.0 12500000.0)) x0 x0) (* (/ 4954777.0 100000000.0) x0 x1) (* (/ 4954777.0 100000000.0) x1 x0) (* (- (/ 15412957.0 100000000.0)) x1 x1) (* (/ 78363.0 944371.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
