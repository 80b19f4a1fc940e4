; lit31_rational_roa: local:positive:hessian: x^T H x / 2 <= -20998/370811 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 1647997.0 25000000.0)) x0 x0) (* (- (/ 1637211.0 200000000.0)) x0 x1) (* (- (/ 1637211.0 200000000.0)) x1 x0) (* (- (/ 2131271.0 25000000.0)) x1 x1) (* (/ 20998.0 370811.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
