; vdp_mu3: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 4244/847461, M = 72/125, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 72046144.0 79798905169.0) (/ 2592.0 9765625.0)))
(check-sat)
