; lit24_lorenz_subcritical_roa: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 399/88666, M = 338/125, n = 3, ρ = 1/800, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 1432809.0 1965414889.0) (/ 771147.0 2500000000.0)))
(check-sat)
