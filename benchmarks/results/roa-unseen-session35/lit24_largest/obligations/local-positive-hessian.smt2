; lit24_lorenz_subcritical_roa: local:positive:hessian: x^T H x / 2 <= -35491/596757 |x|^2 for the Hessian H of -V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) 1.0) (> (+ (* (- (/ 3581649.0 50000000.0)) x0 x0) (* (- (/ 1079271.0 20000000.0)) x0 x1) (* (- (/ 9785391.0 2000000000.0)) x0 x2) (* (- (/ 1079271.0 20000000.0)) x1 x0) (* (- (/ 1219901.0 2000000.0)) x1 x1) (* (/ 695719.0 100000000.0) x1 x2) (* (- (/ 9785391.0 2000000000.0)) x2 x0) (* (/ 695719.0 100000000.0) x2 x1) (* (- (/ 448161.0 2000000.0)) x2 x2) (* (/ 35491.0 596757.0) (+ (* x0 x0) (* x1 x1) (* x2 x2)))) 0.0)))
(check-sat)
