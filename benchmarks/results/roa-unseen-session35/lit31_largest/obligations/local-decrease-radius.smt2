; lit31_rational_roa: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 78363/944371, M = 499/1000, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 221067351684.0 891836585641.0) (/ 249001.0 1250000000.0)))
(check-sat)
