; khalil_saddles: bounded:domain: the domain D lies in the box [-4, 4] x [-4, 4]
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (- 3.0) x1) (<= x1 3.0) (<= (- 3.0) x2) (<= x2 3.0) (not (and (<= (- 4.0) x1) (<= x1 4.0) (<= (- 4.0) x2) (<= x2 4.0)))))
(check-sat)
