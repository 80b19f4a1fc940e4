; vdp_mu1: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 71147/933135, M = 13/200, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 20247582436.0 96748992025.0) (/ 169.0 50000000.0)))
(check-sat)
