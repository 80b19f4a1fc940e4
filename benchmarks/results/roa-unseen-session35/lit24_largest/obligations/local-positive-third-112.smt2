; lit24_lorenz_subcritical_roa: local:positive:third:112: |d^3 -V/dx1dx1dx2| <= 51/1000 on the ball |x| <= 1/800
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 640000.0)) (or (> (- (+ (* (- (/ 2209153.0 500000000.0)) x0) (* (/ 17376687.0 500000000.0) x1) (* (- (/ 8656261.0 25000000.0)) x2) (- (/ 3066197.0 250000000.0)))) (/ 51.0 1000.0)) (< (- (+ (* (- (/ 2209153.0 500000000.0)) x0) (* (/ 17376687.0 500000000.0) x1) (* (- (/ 8656261.0 25000000.0)) x2) (- (/ 3066197.0 250000000.0)))) (- (/ 51.0 1000.0))))))
(check-sat)
