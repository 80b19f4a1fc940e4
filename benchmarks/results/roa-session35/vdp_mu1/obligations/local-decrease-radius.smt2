; vdp_mu1: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 41663/892762, M = 81/1000, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 15622250121.0 199255997161.0) (/ 6561.0 1250000000.0)))
(check-sat)
