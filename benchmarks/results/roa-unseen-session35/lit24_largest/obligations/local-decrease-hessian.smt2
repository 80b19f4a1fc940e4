; lit24_lorenz_subcritical_roa: local:decrease:hessian: x^T H x / 2 <= -399/88666 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) 1.0) (> (+ (* (- (/ 27573921.0 20000000.0)) x0 x0) (* (/ 213853.0 500000.0) x0 x1) (* (- (/ 32726369.0 500000000.0)) x0 x2) (* (/ 213853.0 500000.0) x1 x0) (* (- (/ 14063.0 100000.0)) x1 x1) (* (/ 44661991.0 600000000.0) x1 x2) (* (- (/ 32726369.0 500000000.0)) x2 x0) (* (/ 44661991.0 600000000.0) x2 x1) (* (- (/ 149387.0 125000.0)) x2 x2) (* (/ 399.0 88666.0) (+ (* x0 x0) (* x1 x1) (* x2 x2)))) 0.0)))
(check-sat)
