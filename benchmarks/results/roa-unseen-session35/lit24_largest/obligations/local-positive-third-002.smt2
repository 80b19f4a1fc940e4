; lit24_lorenz_subcritical_roa: local:positive:third:002: |d^3 -V/dx0dx0dx2| <= 51/1000 on the ball |x| <= 1/800
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 640000.0)) (or (> (- (+ (* (- (/ 19264911.0 5000000000.0)) x0) (* (/ 2309317.0 2500000000.0) x1) (* (/ 1100379.0 5000000.0) x2) (/ 1057957.0 250000000.0))) (/ 51.0 1000.0)) (< (- (+ (* (- (/ 19264911.0 5000000000.0)) x0) (* (/ 2309317.0 2500000000.0) x1) (* (/ 1100379.0 5000000.0) x2) (/ 1057957.0 250000000.0))) (- (/ 51.0 1000.0))))))
(check-sat)
