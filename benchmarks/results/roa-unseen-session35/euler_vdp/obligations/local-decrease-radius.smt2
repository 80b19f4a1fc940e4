; euler_vdp: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 1757/649853, M = 21/1000, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 111133764.0 422308921609.0) (/ 441.0 1250000000.0)))
(check-sat)
