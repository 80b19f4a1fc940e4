; lit24_lorenz_subcritical_roa: local:positive:third:001: |d^3 -V/dx0dx0dx1| <= 51/1000 on the ball |x| <= 1/800
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 640000.0)) (or (> (- (+ (* (- (/ 4371597.0 25000000.0)) x0) (* (- (/ 4569129.0 25000000.0)) x1) (* (/ 2309317.0 2500000000.0) x2) (- (/ 60651.0 39062500.0)))) (/ 51.0 1000.0)) (< (- (+ (* (- (/ 4371597.0 25000000.0)) x0) (* (- (/ 4569129.0 25000000.0)) x1) (* (/ 2309317.0 2500000000.0) x2) (- (/ 60651.0 39062500.0)))) (- (/ 51.0 1000.0))))))
(check-sat)
