; lit24_lorenz_subcritical_roa: local:positive:third:000: |d^3 -V/dx0dx0dx0| <= 51/1000 on the ball |x| <= 1/800
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 640000.0)) (or (> (- (+ (* (/ 6922443.0 6250000.0) x0) (* (- (/ 4371597.0 25000000.0)) x1) (* (- (/ 19264911.0 5000000000.0)) x2) (/ 7186647.0 5000000000.0))) (/ 51.0 1000.0)) (< (- (+ (* (/ 6922443.0 6250000.0) x0) (* (- (/ 4371597.0 25000000.0)) x1) (* (- (/ 19264911.0 5000000000.0)) x2) (/ 7186647.0 5000000000.0))) (- (/ 51.0 1000.0))))))
(check-sat)
