; euler_vdp: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 19005/317158, M = 3/20, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 3250710225.0 25147299241.0) (/ 9.0 500000.0)))
(check-sat)
