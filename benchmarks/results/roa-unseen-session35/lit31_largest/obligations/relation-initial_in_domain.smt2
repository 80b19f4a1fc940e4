; lit31_rational_roa: relation:initial in domain: I lies in D
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1)) 1.0) (not (<= (+ (* x0 x0) (* x1 x1)) 4.0))))
(check-sat)
