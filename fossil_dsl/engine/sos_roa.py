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
on Ω = {V <= β}) but keeps the program linear in V. Where D holds states that do not
converge (probe64/am03: the reversed Van der Pol's limit cycle lies in D) no V falls on
all of D; the decrease is then asked as

    -dV/dt - e|x|^2 - λ|x|^2 (1 - V) >= 0  on D

for a fixed λ > 0 (still linear in V), which lets V grow where V > 1, outside Ω. λ is
tried at a few multiples of 2α / r^2, α the linear closed loop's decay rate and r the
radius of I's bounding box: near 0, V is about |x|^2 / r^2 and falls at 2α times that.
Where the closed loop's exact form has function variables and no V is found with their
facts, or it has no exact form (sqrt, log), the programs are solved again for a
polynomial stand-in (surrogate.py) that keeps the linearisation and fits the terms of
degree 2 and more (probe64/am05: exp(T / (1 + 0.05 T)), whose facts leave the decrease
infeasible). Nothing here is trusted: V and the controller are rounded and proved like
any candidate, with the true field.
"""
from __future__ import annotations

import itertools
import time
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.linear import jacobians, operating_point
from fossil_dsl.engine.polynomial_field import PolynomialField, exact_field, padded, widened
from fossil_dsl.engine.quadratic_shapes import lqr_controllers
from fossil_dsl.engine.sos import (Inexact, faces, interval_products, rounded, set_constraints,
                                   set_pieces, squared_norm)
from fossil_dsl.engine.reach_program import BOUND, DECIMALS
from fossil_dsl.engine.sos_reach import MIN_MARGIN, ReachFinding
from fossil_dsl.engine.surrogate import polynomial_field
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis
from fossil_dsl.solvers.sdp import Program
from fossil_dsl.solvers.sos_refutation import ATOMS_MAX_VARIABLES, MAX_VARIABLES

HALF_DEGREES = (1, 2)  # V of degree 2, then 4
# with the multiplier λ|x|^2: V of degree 2, 4, 6 (am03: degree 6, margin 0.02), each
# with λ at these multiples of 2α / r^2 (am03: 0.2 and 0.3 solve, 0.1 and 0.5 do not)
MULTIPLIED_HALF_DEGREES = (1, 2, 3)
MULTIPLIER_FACTORS = (1.0, 0.5, 2.0)
# a stand-in's degrees (surrogate.py): a map's V(p(x)) multiplies them
STAND_IN_DEGREES, MAP_STAND_IN_DEGREES = (3, 5), (3,)
CONTROLLERS = 2  # LQR gains tried, at most (u02: the first one's quartic has margin 0.1)
LEVEL = Fraction(1)


def applies(plan: Plan) -> bool:
    spec = plan.spec
    return (plan.certificate.form == "region of attraction" and default_synthesis(plan)
            and not plan.options.largest_region and spec.domain.bounding_box() is not None)


def search(plan: Plan, deadline: float) -> ReachFinding | None:
    """The first V found, over the controllers tried, the fields (exact, then a
    stand-in) and V's degrees."""
    started = time.monotonic()
    sets = _sets(plan)
    operating = operating_point(plan.spec) if plan.spec.inputs else np.zeros(0)
    if sets is None or operating is None:
        return None
    discrete = plan.spec.time is TimeDomain.DISCRETE
    controllers = lqr_controllers(plan, operating, np.random.default_rng(plan.options.seed))
    for controller, gain in itertools.islice(controllers, CONTROLLERS):
        linear = _closed_jacobian(plan, gain, operating)
        for field, stand_in in _fields(plan, controller, linear, discrete):
            found = _first_v(plan, field, sets, linear, discrete, deadline)
            if found is not None:
                V, half, margin = found
                return ReachFinding({"V": V}, controller, gain, operating, 2 * half, margin,
                                    time.monotonic() - started, {"beta": LEVEL},
                                    stand_in=stand_in)
    return None


def _first_v(plan: Plan, field, sets, linear, discrete: bool, deadline: float):
    """(V, its half-degree, margin) of the first program solved with a margin, or None."""
    too_large = None  # the smallest half-degree whose program is too large
    for half, weight in _shapes(plan, linear, discrete):
        if time.monotonic() > deadline:
            return None
        if too_large is not None and half >= too_large:
            continue
        program = _RegionProgram(field, len(plan.states), *sets, half, discrete, weight)
        if program.count > (ATOMS_MAX_VARIABLES if field.facts else MAX_VARIABLES):
            too_large = half
            continue
        x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
        if x is not None and x[program.margin] > MIN_MARGIN:
            return P.to_expr(program.exact_v(x), plan.states), half, float(x[program.margin])
    return None


def _closed_jacobian(plan: Plan, gain, operating) -> np.ndarray | None:
    """The closed loop's Jacobian at the origin (A + B K), or None where it has none."""
    found = jacobians(plan.spec, operating if plan.spec.inputs else None)
    if found is None:
        return None
    A, B = found
    return A if gain is None else A + B @ np.asarray(gain, dtype=float)


def _fields(plan: Plan, controller, linear, discrete: bool):
    """(the closed loop in polynomial form, 0) where it has one; then, where that has
    function variables or is None, (a stand-in keeping the linear part, its degree)."""
    closed = [traversal.substitute(f, controller) for f in plan.spec.dynamics]
    field = _closed_loop(plan, closed, discrete)
    if field is not None:
        yield field, 0
        if not field.facts:
            return
    if linear is None:
        return
    fitted = polynomial_field(closed, plan.states, plan.spec.domain,
                              MAP_STAND_IN_DEGREES if discrete else STAND_IN_DEGREES,
                              plan.options.seed, linear)
    if fitted is not None:
        n = len(plan.states)
        yield PolynomialField(n, fitted, P.constant(1, n), []), \
            max(P.degree(p) for p in fitted)


def _shapes(plan: Plan, linear, discrete: bool):
    """(half-degree, λ) in the order tried: V falling on all of D first, then with the
    multiplier λ|x|^2 where the linear closed loop decays and I is bounded."""
    shapes = [(half, 0.0) for half in HALF_DEGREES]
    scale = _multiplier_scale(plan, linear, discrete)
    if scale:
        shapes += [(half, factor * scale) for half in MULTIPLIED_HALF_DEGREES
                   for factor in MULTIPLIER_FACTORS]
    return shapes


def _multiplier_scale(plan: Plan, linear, discrete: bool) -> float | None:
    """2α / r^2 (for a map, (1 - ρ^2) / r^2, ρ the spectral radius) for the closed loop's
    Jacobian `linear`, or None."""
    box = plan.spec.property.role("initial").bounding_box()
    if linear is None or box is None:
        return None
    eigenvalues = np.linalg.eigvals(linear)
    decay = 1 - np.abs(eigenvalues).max() ** 2 if discrete else -2 * eigenvalues.real.max()
    radius = sum(max(float(lo) ** 2, float(hi) ** 2) for lo, hi in zip(*box))
    return float(decay / radius) if decay > 0 and radius > 0 else None


def _closed_loop(plan: Plan, closed, discrete: bool) -> PolynomialField | None:
    """The closed loop's polynomial form; for a map, one over the denominator 1 only
    (V(f(x)) of a quotient is not polynomial)."""
    field = exact_field(plan, closed)
    if field is None or (discrete and P.degree(field.denominator) > 0):
        return None
    return field


def _sets(plan: Plan):
    """(D's constraints, each member of I's with its boxes' products), or None where D
    or a member of I is not a conjunction of polynomial comparisons."""
    try:
        return (set_constraints(plan.spec.domain, plan.states, exact=True),
                [interval_products(piece) for piece in set_pieces(
                    plan.spec.property.role("initial"), plan.states, exact=True)])
    except Inexact:
        return None


class _RegionProgram(Program):
    def __init__(self, field: PolynomialField, states: int, domain, initial, half: int,
                 discrete: bool, weight: float = 0.0):
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
        for piece in initial:
            self.require_nonnegative(minus_v, padded(piece, n), (self.margin, one), one)
        for face in faces(domain):
            self.require_nonnegative(v, padded(face, n), (self.margin, one), P.scale(one, -1))
        # over N = f Q with Q > 0: -grad V . N >= e|x|^2 gives dV/dt <= -e|x|^2 / Q
        # and with λ: -grad V . N - λ|x|^2 (1 - V) >= e|x|^2
        multiplier = P.scale(norm, Fraction(weight).limit_denominator(10 ** 6))
        decrease = [(c, P.add(P.scale(P.change(t, field.numerators, discrete), -1),
                              P.multiply(multiplier, t))) for c, t in v]
        self.require_nonnegative(decrease, inside + field.facts, (self.margin, norm),
                                 P.scale(multiplier, -1) if weight else None)

    def exact_v(self, x) -> P.Polynomial:
        return rounded(x, self.basis, self.coefficients, DECIMALS)
