"""A barrier certificate by sum-of-squares programming, for safety of a polynomial (or
rational: multiplied through by its denominator, positive on D) ODE.

Find a polynomial B (coefficients in [-1, 1]) and the largest e with

    -B - e       = s_I + sum_i a_i g_i    (so B < 0 on I, where g_i >= 0 describe I)
     B - e       = s_U + sum_j b_j u_j    (so B > 0 on U within D)
    -dB/dt - mu B - e = s_D + sum_k c_k d_k   (so dB/dt < 0 on D wherever B = 0)

with every s and every multiplier a sum of squares, for a fixed mu > 0 from a short list
(the third condition is the exponential barrier condition dB/dt <= -mu B - e; with mu
fixed the program stays convex). If e > 0, B is rounded to rationals and handed on as a
candidate: refutations of the kernel's obligations (solvers/sos_refutation.py) or the
solvers prove
it, or not.
"""
from __future__ import annotations

import time
from fractions import Fraction

from fossil_dsl.solvers.sdp import Program
from fossil_dsl.engine.rational_field import over_one_denominator
from fossil_dsl.engine.sos import MIN_MARGIN, SosFinding, field_of, rounded, set_constraints
from fossil_dsl.solvers.sos_refutation import MAX_VARIABLES
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.sets import Intersection
from fossil_dsl.plan.compile import Plan

# B of degree 2 first, then 4 where that program is not too large: with 2 states (z03,
# an SIR model whose quadratic programs are infeasible) the quartic program of 251
# variables is solved and refuted at once, where learning failed in 25 iterations; a
# 6-state non-normal linear system (probe48/c09) has no quadratic barrier and a quartic
# one of 2 465 variables (found in 5 s, refuted in 10 s). (bb25's quartic B, 1 877
# variables, once had no refutation whose Gram matrix survived rounding; it is now
# certified by it in 6.5 s.) Degree 6 last: a chemostat's Monod field (probe53/n03,
# rational) has none of degree 2 or 4 and one of 668 variables found in 0.1 s.
DEGREES = (1, 2, 3)
HIGHER_DEGREE_MAX_VARIABLES = 3000
DECAY_RATES = (1.0, 0.1, 10.0)  # mu, in the order tried
DECIMALS = 6  # kept of B's coefficients (each is at most 1)


def barrier(plan: Plan, deadline: float) -> SosFinding | None:
    started = time.monotonic()
    states = plan.states
    field, denominator = field_of(plan), P.constant(1, len(states))
    if field is None:  # a rational field (sos.applies): dB/dt = grad B . N / Q with Q > 0
        found = over_one_denominator(plan.spec.dynamics, states,
                                     plan.spec.domain.bounding_box(), plan.options.seed)
        if found is None:
            return None
        field, denominator = found
    domain = set_constraints(plan.spec.domain, states)
    initial = set_constraints(plan.spec.property.role("initial"), states)
    unsafe = set_constraints(Intersection(plan.spec.property.role("unsafe"), plan.spec.domain),
                             states)
    for degree in DEGREES:
        for mu in DECAY_RATES:
            if time.monotonic() > deadline:
                return None
            program = BarrierProgram(len(states), field, initial, [unsafe], domain, degree, mu,
                                     denominator)
            if program.count > (MAX_VARIABLES if degree == 1 else HIGHER_DEGREE_MAX_VARIABLES):
                return None
            x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
            if x is None or x[program.margin] <= MIN_MARGIN:
                continue
            formula = P.to_expr(program.exact_b(x), states)
            margin = float(x[program.margin])
            return SosFinding(formula, "B", 2 * degree, margin,
                              f"B < 0 on I, B > 0 on U, dB/dt <= -{mu:g} B on D with "
                              f"margin {margin:.3g}", time.monotonic() - started)
    return None


class BarrierProgram(Program):
    """The identities above; U given as pieces (constraint lists), B > 0 on each."""

    def __init__(self, n: int, field, initial, unsafe_pieces, domain, degree: int,
                 mu: float, denominator: P.Polynomial | None = None):
        super().__init__(n, searches=True)
        self.basis = P.monomials(n, 0, 2 * degree)
        self.coefficients = self.unknown_polynomial(self.basis, 1.0)  # -1 <= b <= 1
        self.margin = self.scalar()
        self.at_most.append(({self.margin: 1.0}, 1.0))
        b_terms = [{m: Fraction(1)} for m in self.basis]
        self._condition([(v, P.scale(t, -1)) for v, t in zip(self.coefficients, b_terms)],
                        initial)
        for piece in unsafe_pieces:
            self._condition(list(zip(self.coefficients, b_terms)), piece)
        # multiplied through by the field's denominator Q > 0 (1 for a polynomial field):
        # -grad B . N - mu B Q - e >= 0 gives dB/dt <= -mu B - e / Q
        Q = denominator or P.constant(1, n)
        flow = [(v, P.add(P.scale(P.lie_derivative(t, field), -1),
                          P.scale(P.multiply(t, Q), -mu)))
                for v, t in zip(self.coefficients, b_terms)]
        self._condition(flow, domain)

    def _condition(self, terms, constraints) -> None:
        """sum of terms - e >= 0 on the piece."""
        self.require_nonnegative(terms, constraints, (self.margin, P.constant(1, self.n)))

    def exact_b(self, x) -> P.Polynomial:
        return rounded(x, self.basis, self.coefficients, DECIMALS)
