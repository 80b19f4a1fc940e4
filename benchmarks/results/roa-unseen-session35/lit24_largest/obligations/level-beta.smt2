; lit24_lorenz_subcritical_roa: level:beta: β > 0
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(declare-const x2 Real)
(assert (<= (/ 3653.0 5000.0) 0.0))
(check-sat)
