; lit24_lorenz_subcritical_roa: neighbourhood: the origin is an interior point of D (D contains a neighbourhood of it)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (not (< 0.0 4.0)))
(check-sat)
