; lit24_lorenz_subcritical_roa: local:positive:third:111: |d^3 -V/dx1dx1dx1| <= 51/1000 on the ball |x| <= 1/800
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 640000.0)) (or (> (- (+ (* (- (/ 1876083.0 10000000.0)) x0) (* (- (/ 24768411.0 12500000.0)) x1) (* (/ 17376687.0 500000000.0) x2) (- (/ 1659399.0 625000000.0)))) (/ 51.0 1000.0)) (< (- (+ (* (- (/ 1876083.0 10000000.0)) x0) (* (- (/ 24768411.0 12500000.0)) x1) (* (/ 17376687.0 500000000.0) x2) (- (/ 1659399.0 625000000.0)))) (- (/ 51.0 1000.0))))))
(check-sat)
