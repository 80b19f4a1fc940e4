; lit24_lorenz_subcritical_roa: local:positive:third:222: |d^3 -V/dx2dx2dx2| <= 51/1000 on the ball |x| <= 1/800
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 640000.0)) (or (> (- (+ (* (- (/ 13031727.0 500000000.0)) x0) (* (/ 6966027.0 500000000.0) x1) (* (/ 22888743.0 125000000.0) x2) (/ 14350911.0 2500000000.0))) (/ 51.0 1000.0)) (< (- (+ (* (- (/ 13031727.0 500000000.0)) x0) (* (/ 6966027.0 500000000.0) x1) (* (/ 22888743.0 125000000.0) x2) (/ 14350911.0 2500000000.0))) (- (/ 51.0 1000.0))))))
(check-sat)
