; euler_vdp: origin:V: V(0) = 0
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (or (< 0.0 0.0) (> 0.0 0.0)))
(check-sat)
