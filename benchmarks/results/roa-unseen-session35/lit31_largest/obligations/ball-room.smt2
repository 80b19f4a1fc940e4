; lit31_rational_roa: ball:room: the ball |x| <= 1/10 (10 times the excluded ball) lies in D
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1)) (/ 1.0 100.0)) (not (<= (+ (* x0 x0) (* x1 x1)) 4.0))))
(check-sat)
