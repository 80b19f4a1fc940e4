; khalil_saddles: local:positive:hessian: x^T H x / 2 <= -94811/981273 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (>= (+ (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (<= (+ (* x1 x1) (* x2 x2)) 1.0) (> (+ (* (- (/ 1568121.0 10000000.0)) x1 x1) (* (- (/ 1518743.0 20000000.0)) x1 x2) (* (- (/ 1518743.0 20000000.0)) x2 x1) (* (- (/ 1119767.0 5000000.0)) x2 x2) (* (/ 94811.0 981273.0) (+ (* x1 x1) (* x2 x2)))) 0.0)))
(check-sat)
