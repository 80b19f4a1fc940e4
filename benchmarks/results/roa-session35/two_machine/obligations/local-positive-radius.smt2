; two_machine: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 128780/411487, M = 7629/500, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 597034382400.0 169321551169.0) (/ 58201641.0 312500000.0)))
(check-sat)
