; lit24_lorenz_subcritical_roa: equilibrium:x1: f1(0) = 0 (the origin is an equilibrium)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (or (< 0.0 0.0) (> 0.0 0.0)))
(check-sat)
