; vdp_mu3: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 166/129365, M = 133/500, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 992016.0 16735303225.0) (/ 17689.0 312500000.0)))
(check-sat)
