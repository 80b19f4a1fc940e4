; map_saddle: ball:image: the map sends the excluded ball |x| <= 1/100 into itself
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1)) (/ 1.0 10000.0)) (> (+ (* (+ (* (/ 4.0 5.0) x0) (* (/ 1.0 2.0) (* x0 x0)) (* (/ 1.0 10.0) x1)) (+ (* (/ 4.0 5.0) x0) (* (/ 1.0 2.0) (* x0 x0)) (* (/ 1.0 10.0) x1))) (* (+ (* (- (/ 1.0 5.0)) x0) (* (/ 3.0 5.0) x1) (* (/ 3.0 10.0) x0 x1)) (+ (* (- (/ 1.0 5.0)) x0) (* (/ 3.0 5.0) x1) (* (/ 3.0 10.0) x0 x1)))) (/ 1.0 10000.0))))
(check-sat)
