; two_machine: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 70165/782781, M = 1313/500, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 19692508900.0 68082899329.0) (/ 1723969.0 312500000.0)))
(check-sat)
