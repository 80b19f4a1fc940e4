; khalil_saddles: local:decrease:hessian: x^T H x / 2 <= -17773/309795 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (>= (+ (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (<= (+ (* x1 x1) (* x2 x2)) 1.0) (> (+ (* (- (/ 1518743.0 10000000.0)) x1 x1) (* (- (/ 2861569.0 20000000.0)) x1 x2) (* (- (/ 2861569.0 20000000.0)) x2 x1) (* (- (/ 118413.0 400000.0)) x2 x2) (* (/ 17773.0 309795.0) (+ (* x1 x1) (* x2 x2)))) 0.0)))
(check-sat)
