; two_machine: local:decrease:hessian: x^T H x / 2 <= -78312/874231 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic ALL)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (/ 2317561.0 2500000.0) (- (cos (* (/ 1.0 3.0) real.pi))) x0 x0) (* (/ 1.0 2.0) (+ (* (/ 531483.0 250000.0) (- (cos (* (/ 1.0 3.0) real.pi)))) (/ 1040907.0 1250000.0)) x0 x1) (* (/ 1.0 2.0) (+ (* (/ 531483.0 250000.0) (- (cos (* (/ 1.0 3.0) real.pi)))) (/ 1040907.0 1250000.0)) x1 x0) (* (- (/ 169927.0 1250000.0)) x1 x1) (* (/ 78312.0 874231.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
