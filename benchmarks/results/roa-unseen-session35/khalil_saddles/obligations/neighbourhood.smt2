; khalil_saddles: neighbourhood: the origin is an interior point of D (D contains a neighbourhood of it)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (not (and (< (- 3.0) 0.0) (< 0.0 3.0) (< (- 3.0) 0.0) (< 0.0 3.0))))
(check-sat)
