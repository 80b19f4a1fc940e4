; lit24_lorenz_subcritical_roa: bounded:domain: the domain D lies in the box [-3, 3] x [-3, 3] x [-3, 3]
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) 4.0) (not (and (<= (- 3.0) x0) (<= x0 3.0) (<= (- 3.0) x1) (<= x1 3.0) (<= (- 3.0) x2) (<= x2 3.0)))))
(check-sat)
