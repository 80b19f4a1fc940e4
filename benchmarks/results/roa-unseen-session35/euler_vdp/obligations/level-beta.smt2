; euler_vdp: level:beta: β > 0
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (<= (/ 513.0 500.0) 0.0))
(check-sat)
