; lit31_rational_roa: local:decrease:flat: the change of V and its gradient are 0 at the origin
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (or (< 0.0 0.0) (> 0.0 0.0) (< 0.0 0.0) (> 0.0 0.0) (< 0.0 0.0) (> 0.0 0.0)))
(check-sat)
