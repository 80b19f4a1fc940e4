; two_machine: local:decrease:hessian: x^T H x / 2 <= -70165/782781 |x|^2 for the Hessian H of the change of V at the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)
; unsat means the obligation holds
(set-logic ALL)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (>= (+ (* x0 x0) (* x1 x1)) (/ 1.0 4.0)) (<= (+ (* x0 x0) (* x1 x1)) 1.0) (> (+ (* (/ 9268573.0 10000000.0) (- (cos (* (/ 1.0 3.0) real.pi))) x0 x0) (* (/ 1.0 2.0) (+ (* (/ 1062853.0 500000.0) (- (cos (* (/ 1.0 3.0) real.pi)))) (/ 3330759.0 4000000.0)) x0 x1) (* (/ 1.0 2.0) (+ (* (/ 1062853.0 500000.0) (- (cos (* (/ 1.0 3.0) real.pi)))) (/ 3330759.0 4000000.0)) x1 x0) (* (- (/ 1359957.0 10000000.0)) x1 x1) (* (/ 70165.0 782781.0) (+ (* x0 x0) (* x1 x1)))) 0.0)))
(check-sat)
