; map_saddle: neighbourhood: the origin is an interior point of D (D contains a neighbourhood of it)
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (not (and (< (- 2.0) 0.0) (< 0.0 2.0) (< (- 2.0) 0.0) (< 0.0 2.0))))
(check-sat)
