; vdp_mu3: local:decrease:hessian: x^T H x / 2 <= -4244/847461 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 6578521.0 10000000.0)) x0 x0) (* (/ 5971651.0 20000000.0) x0 x1) (* (/ 5971651.0 20000000.0) x1 x0) (* (- (/ 284479.0 2000000.0)) x1 x1) (* (/ 4244.0 847461.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
