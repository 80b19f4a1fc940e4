; lit24_lorenz_subcritical_roa: local:positive:radius: 36 μ^2 > M^2 n^3 ρ^2 for μ = 35491/596757, M = 51/1000, n = 3, ρ = 1/800, so -V < 0 for 0 < |x| <= ρ
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 5038444324.0 39568768561.0) (/ 70227.0 640000000000.0)))
(check-sat)
