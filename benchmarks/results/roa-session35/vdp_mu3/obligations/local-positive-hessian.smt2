; vdp_mu3: local:positive:hessian: x^T H x / 2 <= -166/129365 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 4107721.0 5000000.0)) x0 x0) (* (/ 6578521.0 20000000.0) x0 x1) (* (/ 6578521.0 20000000.0) x1 x0) (* (- (/ 666743.0 5000000.0)) x1 x1) (* (/ 166.0 129365.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
