; euler_vdp: bounded:domain: the domain D lies in the box [-3.5, 3.5] x [-4.5, 4.5]
; unsat means the obligation holds
(set-logic QF_NRA)
(declare-const x0 Real)
(declare-const x1 Real)
(assert (and (<= (- (/ 5.0 2.0)) x0) (<= x0 (/ 5.0 2.0)) (<= (- (/ 7.0 2.0)) x1) (<= x1 (/ 7.0 2.0)) (not (and (<= (- (/ 7.0 2.0)) x0) (<= x0 (/ 7.0 2.0)) (<= (- (/ 9.0 2.0)) x1) (<= x1 (/ 9.0 2.0))))))
(check-sat)
