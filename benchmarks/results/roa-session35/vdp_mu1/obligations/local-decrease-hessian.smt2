; vdp_mu1: local:decrease:hessian: x^T H x / 2 <= -41663/892762 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 823549.0 2000000.0)) x0 x0) (* (/ 2319391.0 20000000.0) x0 x1) (* (/ 2319391.0 20000000.0) x1 x0) (* (- (/ 892191.0 10000000.0)) x1 x1) (* (/ 41663.0 892762.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
