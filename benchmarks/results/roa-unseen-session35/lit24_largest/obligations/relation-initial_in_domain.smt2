; lit24_lorenz_subcritical_roa: relation:initial in domain: I lies in D
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (and (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) (/ 1.0 4.0)) (not (<= (+ (* x0 x0) (* x1 x1) (* x2 x2)) 4.0))))
(check-sat)
