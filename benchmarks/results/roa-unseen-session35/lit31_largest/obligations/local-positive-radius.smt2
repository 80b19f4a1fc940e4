; lit31_rational_roa: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 20998/370811, M = 21/200, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 15872976144.0 137500797721.0) (/ 441.0 50000000.0)))
(check-sat)
