; vdp_mu1: local:positive:hessian: x^T H x / 2 <= -71147/933135 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 680829.0 2000000.0)) x0 x0) (* (/ 823549.0 4000000.0) x0 x1) (* (/ 823549.0 4000000.0) x1 x0) (* (- (/ 313121.0 1250000.0)) x1 x1) (* (/ 71147.0 933135.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
