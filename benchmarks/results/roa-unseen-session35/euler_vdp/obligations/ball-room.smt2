; euler_vdp: ball:room: the ball |x| <= 1/10 (10 times the excluded ball) lies in D
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1)) (/ 1.0 100.0)) (not (and (<= (- (/ 5.0 2.0)) x0) (<= x0 (/ 5.0 2.0)) (<= (- (/ 7.0 2.0)) x1) (<= x1 (/ 7.0 2.0))))))
(check-sat)
