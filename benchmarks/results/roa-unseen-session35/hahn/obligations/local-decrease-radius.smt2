; hahn: local:decrease:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 5617/624105, M = 61/125, n = 2, ρ = 1/100, so the change of V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 126202756.0 43278561225.0) (/ 3721.0 19531250.0)))
(check-sat)
