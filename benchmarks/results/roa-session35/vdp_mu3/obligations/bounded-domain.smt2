; vdp_mu3: bounded:domain: the domain D lies in the box [-4, 4] x [-7, 7]
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (- 3.0) x0) (<= x0 3.0) (<= (- 6.0) x1) (<= x1 6.0) (not (and (<= (- 4.0) x0) (<= x0 4.0) (<= (- 7.0) x1) (<= x1 7.0)))))
(check-sat)
