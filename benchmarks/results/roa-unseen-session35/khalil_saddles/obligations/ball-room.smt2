; khalil_saddles: ball:room: the ball |x| <= 1/10 (10 times the excluded ball) lies in D
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x1 x1) (* x2 x2)) (/ 1.0 100.0)) (not (and (<= (- 3.0) x1) (<= x1 3.0) (<= (- 3.0) x2) (<= x2 3.0)))))
(check-sat)
