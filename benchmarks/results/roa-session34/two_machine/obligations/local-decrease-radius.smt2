; two_machine: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 78312/874231, M = 21/8, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 220779696384.0 764279841361.0) (/ 441.0 80000.0)))
(check-sat)
