; khalil_saddles: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 17773/309795, M = 1321/1000, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 1263518116.0 10663660225.0) (/ 1745041.0 1250000000.0)))
(check-sat)
