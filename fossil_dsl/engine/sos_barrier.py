"""A barrier certificate by sum-of-squares programming, for safety of a polynomial ODE
(or rational: multiplied through by its denominator, positive on D; or with elementary
functions: each application a variable bounded by its facts, atom_facts.py).

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

from fossil_dsl.engine.polynomial_field import exact_field, padded, widened
from fossil_dsl.engine.sos import (MIN_MARGIN, SosFinding, energy_shaped, faces,
                                   interval_products, nonlinear_states, rounded,
                                   set_constraints, set_pieces)
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan
from fossil_dsl.solvers.sdp import Program
from fossil_dsl.solvers.sos_refutation import ATOMS_MAX_VARIABLES, MAX_VARIABLES

# B of degree 2 first, then 4 and 6 where the program is not too large (before I's box
# entered with its products, bb25 and probe48/c09 (6 states) needed quartic barriers,
# programs of 1 877 and 2 465 variables, and a chemostat (probe53/n03, rational) one of
# degree 6; with them they have quadratic ones, and the chemostat a quartic one)
DEGREES = (1, 2, 3)
# probe72/av37 (4 states, U outside a box: 8 pieces) has a quartic B from a program of
# 3 611 variables, solved in about 1 s
HIGHER_DEGREE_MAX_VARIABLES = 4000
# an energy-shaped B's (_nonlinear_part_basis): probe74/ax37, four masses on cubic springs
# in 8 states, has one from a program of 5 771 variables (about 5 s a decay rate)
ENERGY_MAX_VARIABLES = 8000
DECAY_RATES = (1.0, 0.1, 10.0)  # mu, in the order tried
# for a map, B(f(x)) - B(x) <= -mu B(x) - e: B(f(x)) <= (1 - mu) B(x) <= 0 where B <= 0
# needs mu <= 1
MAP_DECAY_RATES = (0.5, 0.1, 1.0)
DECIMALS = 6  # kept of B's coefficients (each is at most 1)


def barrier(plan: Plan, deadline: float, dynamics=None, min_margin: float = MIN_MARGIN,
            boundary: bool = False, degrees=None) -> SosFinding | None:
    """B for the spec's field, or for `dynamics` (a closed loop) in its place, with a
    margin above `min_margin`; with `boundary`, B > 0 on D's faces too (the kernel's
    "never leaves D"); B of twice the `degrees` in turn (by default DEGREES)."""
    started = time.monotonic()
    states = plan.states
    field = exact_field(plan, plan.spec.dynamics if dynamics is None else dynamics)
    discrete = plan.spec.time is TimeDomain.DISCRETE
    if field is None or discrete and (field.facts or P.degree(field.denominator) > 0):
        return None  # B(f(x)) of a quotient, or of a function's value, is no polynomial
    n, facts = field.variables, field.facts
    # I with its box's products: -B - e >= 0 on I with constant multipliers of I's
    # linear bounds needs -B's Hessian to be PSD, which no quadratic B positive on U
    # has; the products (x - l)(u - x) >= 0 bring the -x^2 terms (probe61/ag03, a
    # 6-state chain of masses with tanh friction: a quadratic B, else none). D's products
    # made the flow condition's programs larger for nothing (probe61/af11: 0.4 -> 2 s)
    plain_domain = set_constraints(plan.spec.domain, states)
    domain = padded(plain_domain, n) + facts
    initial = [padded(interval_products(piece), n)
               for piece in set_pieces(plan.spec.property.role("initial"), states)]
    unsafe = [padded(piece + plain_domain, n)
              for piece in set_pieces(plan.spec.property.role("unsafe"), states)]
    if boundary:
        unsafe += [padded(face, n) for face in faces(plain_domain)]
    # with facts, a quadratic B only, from small programs: those of higher degree gave
    # tiny margins (a05: degree 6, 5 s lost) or B's the kernel's refutations (at most
    # ATOMS_MAX_VARIABLES) could not prove (s12: degree 4, 8 s), and programs with many
    # applications took 8 s (bbu09)
    degrees = DEGREES if degrees is None else degrees
    for degree in (d for d in degrees if not facts or d == DEGREES[0]):
        bases = _bases(field, len(states), degree)
        for mu in MAP_DECAY_RATES if discrete else DECAY_RATES:
            if time.monotonic() > deadline:
                return None
            program = None
            for basis, largest in bases:  # the first whose program is within its bound
                program = BarrierProgram(n, field.numerators, initial, unsafe, domain,
                                         degree, mu, field.denominator, len(states),
                                         discrete, basis)
                if program.count <= largest:
                    break
                program = None
            if program is None:
                return None  # (the next degree's programs are larger still)
            x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
            if x is None or x[program.margin] <= min_margin:
                continue
            b = {m[:len(states)]: c for m, c in program.exact_b(x).items()}
            margin = float(x[program.margin])
            return SosFinding(P.to_expr(b, states), "B", 2 * degree, margin,
                              f"B < 0 on I, B > 0 on U, "
                              f"{'B(f(x)) - B(x)' if discrete else 'dB/dt'} <= -{mu:g} B "
                              f"on D with "
                              f"margin {margin:.3g}" + (" (the field's functions bounded "
                                                       "by their facts)" if facts else ""),
                              time.monotonic() - started)
    return None


def _bases(field, states: int, degree: int) -> list:
    """(B's monomials or None for all of the degree, the program's bound on variables):
    all, then, above degree 1 where only some states enter the field's nonlinear terms,
    the energy-shaped ones (whose programs are a fraction of the size, with a larger
    bound)."""
    if field.facts:
        return [(None, ATOMS_MAX_VARIABLES)]
    if degree == 1:
        return [(None, MAX_VARIABLES)]
    smaller = _nonlinear_part_basis(field.numerators, states, degree)
    shaped = max(map(sum, smaller)) > 2 and len(smaller) < len(P.monomials(states, 0, 2 * degree))
    # the full program first: where it is within its bound the shaped one adds nothing
    return [(None, HIGHER_DEGREE_MAX_VARIABLES)] + \
        ([(smaller, ENERGY_MAX_VARIABLES)] if shaped else [])


class BarrierProgram(Program):
    """The identities above; I and U given as pieces (constraint lists), B < 0 on each
    of I's, B > 0 on each of U's."""

    def __init__(self, n: int, field, initial_pieces, unsafe_pieces, domain, degree: int,
                 mu: float, denominator: P.Polynomial | None = None,
                 states: int | None = None, discrete: bool = False, basis=None):
        super().__init__(n, searches=True)
        # B is over the first `states` variables (the rest stand for function values)
        basis = basis or P.monomials(states or n, 0, 2 * degree)
        self.basis = [widened(m, n) for m in basis]
        self.coefficients = self.unknown_polynomial(self.basis, 1.0)  # -1 <= b <= 1
        self.margin = self.scalar()
        self.at_most.append(({self.margin: 1.0}, 1.0))
        b_terms = [{m: Fraction(1)} for m in self.basis]
        for piece in initial_pieces:
            self._condition([(v, P.scale(t, -1)) for v, t in zip(self.coefficients, b_terms)],
                            piece)
        for piece in unsafe_pieces:
            self._condition(list(zip(self.coefficients, b_terms)), piece)
        # multiplied through by the field's denominator Q > 0 (1 for a polynomial field):
        # -grad B . N - mu B Q - e >= 0 gives dB/dt <= -mu B - e / Q (for a map, with
        # B(f(x)) - B(x) in place of grad B . N)
        Q = denominator or P.constant(1, n)
        flow = [(v, P.add(P.scale(P.change(t, field, discrete), -1),
                          P.scale(P.multiply(t, Q), -mu)))
                for v, t in zip(self.coefficients, b_terms)]
        self._condition(flow, domain)

    def _condition(self, terms, constraints) -> None:
        """sum of terms - e >= 0 on the piece."""
        self.require_nonnegative(terms, constraints, (self.margin, P.constant(1, self.n)))

    def exact_b(self, x) -> P.Polynomial:
        return rounded(x, self.basis, self.coefficients, DECIMALS)


def _nonlinear_part_basis(field, states: int, degree: int) -> list[P.Monomial]:
    """B's monomials of degree at most 2 in every state and up to 2 * degree in the
    states of the field's nonlinear terms only (sos.energy_shaped): its change along the
    field has a lower degree, and the flow condition's program is a quarter of the full
    one (probe72/av32, a 6-state chain of cubic springs: 10 333 variables and 53 s for
    the quartic B; 2 476 and 0.8 s for this one)."""
    nonlinear = nonlinear_states(field, states)
    return [m for m in P.monomials(states, 0, 2 * degree) if energy_shaped(m, nonlinear)]
