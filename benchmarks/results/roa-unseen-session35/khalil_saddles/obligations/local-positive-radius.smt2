; khalil_saddles: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 94811/981273, M = 37/40, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 35956502884.0 106988522281.0) (/ 1369.0 2000000.0)))
(check-sat)
