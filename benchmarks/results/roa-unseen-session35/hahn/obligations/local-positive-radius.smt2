; hahn: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 3881/862436, M = 79/1000, n = 2, ρ = 1/100, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 135559449.0 185948963524.0) (/ 6241.0 1250000000.0)))
(check-sat)
