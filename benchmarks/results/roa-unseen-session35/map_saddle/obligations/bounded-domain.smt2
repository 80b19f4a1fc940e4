; map_saddle: bounded:domain: the domain D lies in the box [-3, 3] x [-3, 3]
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (- 2.0) x0) (<= x0 2.0) (<= (- 2.0) x1) (<= x1 2.0) (not (and (<= (- 3.0) x0) (<= x0 3.0) (<= (- 3.0) x1) (<= x1 3.0)))))
(check-sat)
