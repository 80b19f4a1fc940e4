; lit31_rational_roa: level:beta: β > 0
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 9901.0 10000.0) 0.0))
(check-sat)
