; two_machine: bounded:domain: the domain D lies in the box [-3, 4] x [-4, 2.5]
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (- 2.0) x0) (<= x0 3.0) (<= (- 3.0) x1) (<= x1 (/ 3.0 2.0)) (not (and (<= (- 3.0) x0) (<= x0 4.0) (<= (- 4.0) x1) (<= x1 (/ 5.0 2.0))))))
(check-sat)
