"""A sum-of-squares attempt for a region of attraction (`from I: stable`), with inputs
closed by a linear controller fixed beforehand to an LQR gain of the linearisation,
rounded as the verifier will see it: where no quadratic V fits, a quartic one often
does. The closed loop is polynomial, or N / Q with Q > 0 on D and, for an ODE with sin,
tanh, exp, ..., a variable per application bounded by its facts (polynomial_field.py):
the decrease is then asked as -grad V . N >= e|x|^2 for every value the facts allow.

Why: a sublevel set of a quadratic V that holds I and lies in D is an ellipsoid the
closed loop keeps; for a chain of integrators none fits between a ball and a box of a few
times its size (probe56/u02, five integrators: the linear matrix inequalities of
ellipsoid_seed.py are infeasible at every decay rate), while trajectories from I stay
well inside D. A quartic V's sublevel sets follow the flow more closely.

With β = 1, V (monomials of degree 2 to 2h, coefficients in [-100, 100]) and the largest
e with

     V - e|x|^2     >= 0  on D
     1 - V - e      >= 0  on I
     V - 1 - e      >= 0  on each face of D
    -dV/dt - e|x|^2 >= 0  on D     (V(x) - V(f(x)) for a map)

each a Positivstellensatz identity. Decrease on all of D is more than the rule asks (only
on Ω = {V <= β}) but keeps the program linear in V. Nothing here is trusted: V and the
controller are rounded and proved like any candidate.
"""
from __future__ import annotations

import itertools
import time
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.linear import operating_point
from fossil_dsl.engine.polynomial_field import PolynomialField, exact_field, padded, widened
from fossil_dsl.engine.quadratic_shapes import lqr_controllers
from fossil_dsl.engine.sos import (Inexact, faces, interval_products, rounded, set_constraints,
                                   squared_norm)
from fossil_dsl.engine.sos_reach import BOUND, DECIMALS, MIN_MARGIN, ReachFinding
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis
from fossil_dsl.solvers.sdp import Program
from fossil_dsl.solvers.sos_refutation import ATOMS_MAX_VARIABLES, MAX_VARIABLES

HALF_DEGREES = (1, 2)  # V of degree 2, then 4
CONTROLLERS = 2  # LQR gains tried, at most (u02: the first one's quartic has margin 0.1)
LEVEL = Fraction(1)


def applies(plan: Plan) -> bool:
    spec = plan.spec
    return (plan.certificate.form == "region of attraction" and default_synthesis(plan)
            and not plan.options.largest_region and spec.domain.bounding_box() is not None)


def search(plan: Plan, deadline: float) -> ReachFinding | None:
    """The first V found, over the controllers tried and V's degrees."""
    started, states = time.monotonic(), plan.states
    sets = _sets(plan)
    operating = operating_point(plan.spec) if plan.spec.inputs else np.zeros(0)
    if sets is None or operating is None:
        return None
    discrete = plan.spec.time is TimeDomain.DISCRETE
    controllers = lqr_controllers(plan, operating, np.random.default_rng(plan.options.seed))
    for controller, gain in itertools.islice(controllers, CONTROLLERS):
        field = _closed_loop(plan, controller, discrete)
        if field is None:
            return None
        for half in HALF_DEGREES:
            if time.monotonic() > deadline:
                return None
            program = _RegionProgram(field, len(states), *sets, half, discrete)
            if program.count > (ATOMS_MAX_VARIABLES if field.facts else MAX_VARIABLES):
                break
            x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
            if x is not None and x[program.margin] > MIN_MARGIN:
                return ReachFinding({"V": P.to_expr(program.exact_v(x), states)}, controller,
                                    gain, operating, 2 * half, float(x[program.margin]),
                                    time.monotonic() - started, {"beta": LEVEL})
    return None


def _closed_loop(plan: Plan, controller, discrete: bool) -> PolynomialField | None:
    """The closed loop's polynomial form; for a map, one over the denominator 1 only
    (V(f(x)) of a quotient is not polynomial)."""
    field = exact_field(plan, [traversal.substitute(f, controller) for f in plan.spec.dynamics])
    if field is None or (discrete and P.degree(field.denominator) > 0):
        return None
    return field


def _sets(plan: Plan):
    """(D's constraints, I's with its boxes' products), or None where either is not a
    conjunction of polynomial comparisons."""
    try:
        return (set_constraints(plan.spec.domain, plan.states, exact=True),
                interval_products(set_constraints(plan.spec.property.role("initial"),
                                                  plan.states, exact=True)))
    except Inexact:
        return None


class _RegionProgram(Program):
    def __init__(self, field: PolynomialField, states: int, domain, initial, half: int,
                 discrete: bool):
        n = field.variables
        super().__init__(n, searches=True)
        # V is over the states; the rest of the variables stand for function values
        self.basis = [widened(m, n) for m in P.monomials(states, 2, 2 * half)]
        self.coefficients = self.unknown_polynomial(self.basis, BOUND)
        self.margin = self.scalar()
        self.at_most.append(({self.margin: 1.0}, 1.0))
        terms = [{m: Fraction(1)} for m in self.basis]
        v = list(zip(self.coefficients, terms))
        minus_v = [(c, P.scale(t, -1)) for c, t in v]
        norm = padded([squared_norm(states)], n)[0]
        one = P.constant(1, n)
        inside = padded(interval_products(domain), n)
        self.require_nonnegative(v, inside, (self.margin, norm))
        self.require_nonnegative(minus_v, padded(initial, n), (self.margin, one), one)
        for face in faces(domain):
            self.require_nonnegative(v, padded(face, n), (self.margin, one), P.scale(one, -1))
        # over N = f Q with Q > 0: -grad V . N >= e|x|^2 gives dV/dt <= -e|x|^2 / Q
        decrease = [(c, P.scale(P.change(t, field.numerators, discrete), -1)) for c, t in v]
        self.require_nonnegative(decrease, inside + field.facts, (self.margin, norm))

    def exact_v(self, x) -> P.Polynomial:
        return rounded(x, self.basis, self.coefficients, DECIMALS)
