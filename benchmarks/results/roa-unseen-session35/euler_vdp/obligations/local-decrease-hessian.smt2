; euler_vdp: local:decrease:hessian: x^T H x / 2 <= -1757/649853 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (- (/ 2035289.0 500000000.0)) x0 x0) (* (- (/ 50989787.0 20000000000.0)) x0 x1) (* (- (/ 50989787.0 20000000000.0)) x1 x0) (* (- (/ 90988183.0 10000000000.0)) x1 x1) (* (/ 1757.0 649853.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
