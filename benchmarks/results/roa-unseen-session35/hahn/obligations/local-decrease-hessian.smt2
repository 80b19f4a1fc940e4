; hahn: local:decrease:hessian: x^T H x / 2 <= -5617/624105 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (>= (+ (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (<= (+ (* x1 x1) (* x2 x2)) 1.0) (> (+ (* (- (/ 1001247.0 1000000.0)) x1 x1) (* (- (/ 1066331.0 1000000.0)) x1 x2) (* (- (/ 1066331.0 1000000.0)) x2 x1) (* (- (/ 5785513.0 5000000.0)) x2 x2) (* (/ 5617.0 624105.0) (+ (* x1 x1) (* x2 x2)))) 0.0)))
(check-sat)
