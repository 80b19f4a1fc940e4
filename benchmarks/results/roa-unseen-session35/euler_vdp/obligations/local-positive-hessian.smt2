; euler_vdp: local:positive:hessian: x^T H x / 2 <= -19005/317158 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 608191.0 5000000.0)) x0 x0) (* (/ 4842883.0 200000000.0) x0 x1) (* (/ 4842883.0 200000000.0) x1 x0) (* (- (/ 154461.0 2000000.0)) x1 x1) (* (/ 19005.0 317158.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
