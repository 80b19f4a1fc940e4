"""Sum-of-squares programming for polynomial systems: a convex first attempt at a Lyapunov
function (and, in sos_barrier.py, a barrier).

Lyapunov function. For x' = f(x) with f polynomial, find V(x) = z^T P z + e|x|^2 (z:
the monomials of degree 1..d, P >= 0, trace P = 1) and the largest t with

    -dV/dt - t|x|^2 = m^T Q m + sum_i s_i g_i,   Q >= 0, s_i sums of squares,

where g_i >= 0 are the polynomial constraints describing the domain D (S-procedure). If
t > 0, V > 0 and dV/dt < 0 on D away from the origin. For a map x+ = f(x), V(f(x)) - V(x)
takes the place of dV/dt. V is rounded to rationals: a candidate, proved (or not) like
any other.

Refutations of the kernel's obligations for the V found are searched for by
solvers/sos_refutation.py. The programs are built and solved in sdp.py.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from fractions import Fraction


from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.sets import Complement, Named, Union
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.solvers.positivstellensatz import comparisons, conjuncts
from fossil_dsl.solvers.sdp import Program
from fossil_dsl.solvers.gram_rounding import decimal
from fossil_dsl.solvers.refutation_plan import opposite_pairs
from fossil_dsl.solvers.sos_refutation import MAX_VARIABLES
from fossil_dsl.plan.compile import Plan
from fossil_dsl.plan.certificates.roa import ROA_FORMS

FORMS = ("stability",) + ROA_FORMS  # whose conditions a Lyapunov V meets on D
DEGREES = (1, 2)  # V of degree 2, then 4 (z of degree up to d)
V_FLOOR = Fraction(1, 1000)  # e in V = z^T P z + e|x|^2: V >= e|x|^2
DECIMALS = 6  # kept of P's entries (trace P = 1: entries are at most 1)
MIN_MARGIN = 1e-7  # t below this is numerical noise, not a decrease
# the decrease asked for: t|x|^2, else t|x|^4 (where the linearisation is only marginally
# stable, as for x' = -x^3 + y, y' = -x - y^3)
MARGIN_POWERS = (1, 2)
# a program of at most this many variables is solved as it is (probe46/e03, 4 states:
# the energy-shaped V's program first cost 1.4 s, and the full one found V after it)
SMALL = 4000


@dataclass(frozen=True)
class SosFinding:
    formula: E.Expr  # exact (rounded)
    function: str  # "V" or "B"
    degree: int
    margin: float  # of the program
    condition: str  # what the program asked for, with its margin, in words
    seconds: float

    def describe(self) -> str:
        return (f"sum-of-squares programming (Clarabel): {self.function} of degree "
                f"{self.degree}, {self.condition}, {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    """A polynomial autonomous system, a Lyapunov-type property (or safety, where an ODE
    may be rational or have elementary functions and a map must be polynomial:
    sos_barrier.py), and no template or candidate chosen by the user."""
    spec = plan.spec
    form = plan.certificate.form in FORMS or plan.certificate.form == "safety"
    return (form and plan.controller is None and not spec.inputs
            and spec.torch_dynamics is None and spec.synthesis.certificate is None
            and spec.synthesis.candidate is None and not plan.options.learn_only
            and (field_of(plan) is not None or plan.certificate.form == "safety"))


def lyapunov(plan: Plan, deadline: float) -> SosFinding | None:
    """The first V (by degree) whose program is feasible with a positive margin, or None."""
    started = time.monotonic()
    field = field_of(plan)
    plain = set_constraints(plan.spec.domain, plan.states)
    # with a box's products only where the plain constraints give nothing at that degree:
    # the programs grow; but before a V of higher degree, whose programs grow far more
    # (d18, a 4-state map: a quadratic V in 0.06 s with them, else a quartic in 30 s
    # whose decrease took 100 s to refute)
    variants = (plain,) if interval_products(plain) == plain else \
        (plain, interval_products(plain))
    too_large = set()  # the variants whose full programs grew beyond MAX_VARIABLES
    for degree, variant, power in ((d, v, m) for d in DEGREES for v in range(len(variants))
                                   for m in MARGIN_POWERS):
        if time.monotonic() > deadline:
            return None
        for program in _programs(plan, field, variants[variant], degree, power,
                                 full=variant not in too_large):
            if program.count > MAX_VARIABLES:
                if program.nonlinear is None:
                    too_large.add(variant)
                continue
            x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
            if x is not None and x[program.margin] > MIN_MARGIN:
                return _finding(plan, program, x, degree, power, deadline, started)
    return None


def _programs(plan: Plan, field, constraints, degree: int, power: int, full: bool = True):
    """The programs for V of the degree: the full one where it is small; else, above
    degree 1 where only some states enter the field's nonlinear terms, first the
    energy-shaped V's (a fraction of the size: probe74/ax36, 6 states, 1 009 variables
    and 0.9 s where the full program's 8 401 were too costly to start), then the full
    one. (The shaped V is a full one too: where the full program is infeasible, so is
    the shaped one.)"""
    n, discrete = len(plan.states), plan.spec.time is TimeDomain.DISCRETE
    whole = _LyapunovProgram(n, field, constraints, degree, power, discrete) if full else None
    nonlinear = nonlinear_states(field, n)
    if degree > 1 and 0 < len(nonlinear) < n and (whole is None or whole.count > SMALL):
        yield _LyapunovProgram(n, field, constraints, degree, power, discrete, nonlinear)
    if whole is not None:
        yield whole


def _finding(plan: Plan, program: "_LyapunovProgram", x, degree: int, power: int,
             deadline: float, started: float) -> SosFinding:
    if plan.certificate.form in ROA_FORMS:
        rounder = _roundest(program, float(x[program.margin]), deadline)
        x = rounder if rounder is not None else x
    formula = P.to_expr(program.exact_v(x), plan.states)
    margin = float(x[program.margin])
    change = "V(f(x)) - V(x)" if program.discrete else "dV/dt"
    return SosFinding(formula, "V", 2 * degree, margin,
                      f"{change} <= -{margin:.3g} |x|^{2 * power} on D",
                      time.monotonic() - started)


def _roundest(program: "_LyapunovProgram", margin: float, deadline: float):
    """The V whose quadratic part is roundest (largest smallest eigenvalue, trace 1),
    keeping a quarter of the best margin: a region of attraction needs a sublevel set
    that holds the initial set and fits in D, which a V flat along some axis spoils."""
    program.at_most.append(({program.margin: -1.0}, -margin / 4))
    roundness = program.roundness()
    return program.solve({roundness: -1.0}, deadline - time.monotonic())


def field_of(plan: Plan) -> list[P.Polynomial] | None:
    try:
        return [P.polynomial(f, plan.states) for f in plan.spec.dynamics]
    except P.NotPolynomial:
        return None


class Inexact(ValueError):
    """A set whose membership is not a conjunction of polynomial comparisons (a union, a
    complement), where a program needs the set itself."""


def set_constraints(region, states, exact: bool = False) -> list[P.Polynomial]:
    """g with g >= 0 on the set (closures of strict comparisons), from its membership
    formula where that is a conjunction of polynomial comparisons. Other conjuncts raise
    Inexact where `exact`, else are left out (a program then asks for its condition on a
    larger set, which is stronger; but not where the set is one to stay out of, or one
    to reach)."""
    found = []
    for atom in conjuncts(region.contains_formula(states)):
        try:
            found += [h for h, _ in comparisons(atom, states)]
        except ValueError as exc:  # not a comparison, or not polynomial
            if exact:
                raise Inexact(str(exc)) from exc
    return found


def set_pieces(region, states, exact: bool = False) -> list[list[P.Polynomial]]:
    """The constraints of each member of a union (of unions), as set_constraints gives
    them: a condition asked on a union is asked on each member (probe70/at23: I two
    boxes, one each side of the origin)."""
    if isinstance(region, Named):
        return set_pieces(region.value, states, exact)
    if isinstance(region, Union):
        return set_pieces(region.left, states, exact) + set_pieces(region.right, states, exact)
    if isinstance(region, Complement):
        outside = _outside_pieces(region, states, exact)
        if outside is not None:
            return outside
    return [set_constraints(region, states, exact)]


def _outside_pieces(region, states, exact: bool) -> list[list[P.Polynomial]] | None:
    """D minus A, for A = {every g >= 0}: one piece per g, D with -g >= 0 (the closure; a
    condition asked on it is asked on a little more). Without them the complement of a
    box was D itself, and no B is positive on all of D (probe72/av37: U outside a box)."""
    try:
        inside = set_constraints(region.operand, states, exact=True)
    except Inexact:
        return None
    return [piece + [P.scale(g, -1)] for g in inside
            for piece in set_pieces(region.domain, states, exact)] or None


def interval_products(constraints: list[P.Polynomial]) -> list[P.Polynomial]:
    """The constraints, and the product of each pair of opposite linear bounds (l <= x_i
    and x_i <= u give (x_i - l)(u - x_i) >= 0): without them a box's multipliers of low
    degree cannot see that it is bounded: the reach program for lit17's sets, and the
    Lyapunov program for a 4-state cubic map (whose V(f(x)) - V(x) has terms -x_i^6 that
    only (1 - x_i^2) times a quartic can match), are infeasible."""
    return constraints + [P.multiply(constraints[i], constraints[k])
                          for i, k in opposite_pairs(constraints)]


def rounded(x, basis: list[P.Monomial], coefficients: list[int],
            decimals: int) -> P.Polynomial:
    """The polynomial a program found (its coefficients' values in x), each coefficient
    rounded to `decimals` decimals."""
    return P.add(*({m: decimal(x[c], decimals)} for m, c in zip(basis, coefficients)))


def faces(domain: list[P.Polynomial]) -> list[list[P.Polynomial]]:
    """Each face {g = 0} of the domain {every g >= 0}, within the domain."""
    return [[g, P.scale(g, -1)] + interval_products(domain[:k] + domain[k + 1:])
            for k, g in enumerate(domain)]


class _LyapunovProgram(Program):
    """V = z^T P z + e|x|^2; with `nonlinear` (states), V's terms above degree 2 only in
    those states, an energy's shape (energy_shaped)."""

    def __init__(self, n: int, field: list[P.Polynomial], constraints: list[P.Polynomial],
                 degree: int, power: int, discrete: bool, nonlinear: set | None = None):
        super().__init__(n, searches=True)
        self.discrete, self.nonlinear = discrete, nonlinear
        change = lambda p: P.change(p, field, discrete)  # dV/dt or V(f(x)) - V(x)
        kept = (lambda m: True) if nonlinear is None else \
            (lambda m: energy_shaped(m, nonlinear))
        self.z = [m for m in P.monomials(n, 1, degree) if kept(m)]
        self.states_block = self.z[:n]  # the linear monomials come first
        norm = squared_norm(n)
        # -dV, part by part; an entry whose product V may not hold is 0
        self.v_entries = self.gram(self.z, lambda p: P.scale(change(p), -1)
                                   if kept(next(iter(p))) else {})
        self.equalities += [({v: 1.0}, 0.0) for v, i, j in self.v_entries
                            if not kept(P.times(self.z[i], self.z[j]))]
        self.add_constant(P.scale(change(P.scale(norm, V_FLOOR)), -1))
        self.margin = self.scalar()
        self.add_term(self.margin, P.scale(P.power(norm, power, n), -1))
        top = max(2 * power, max(P.degree(change({P.times(a, b): Fraction(1)}))
                                 for a in self.z for b in self.z if kept(P.times(a, b))))
        self.minus_certificate((top + 1) // 2, constraints, low=1)
        self.equalities.append(({v: 1.0 for v, i, j in self.v_entries if i == j}, 1.0))

    def roundness(self) -> int:
        """mu with (P's block of linear monomials) - mu I >= 0, for an objective."""
        mu = self.scalar()
        linear = len(self.states_block)
        shifted = self.gram(self.states_block, lambda p: {})
        by_place = {(i, j): v for v, i, j in self.v_entries if j < linear}
        for variable, i, j in shifted:
            self.equalities.append(({by_place[i, j]: 1.0, variable: -1.0,
                                     **({mu: -1.0} if i == j else {})}, 0.0))
        return mu

    def exact_v(self, x) -> P.Polynomial:
        """z^T P z + e|x|^2 with P's entries rounded to DECIMALS decimals."""
        terms = [P.scale(squared_norm(self.n), V_FLOOR)]
        for variable, i, j in self.v_entries:
            weight = decimal(x[variable], DECIMALS) * (1 if i == j else 2)
            terms.append({P.times(self.z[i], self.z[j]): weight})
        return P.add(*terms)


def nonlinear_states(field, n: int) -> set[int]:
    """The states (of the first n variables) in the field's terms of degree 2 or more."""
    return {i for p in field for m in p if sum(m[:n]) >= 2 for i, e in enumerate(m[:n]) if e}


def energy_shaped(monomial: P.Monomial, nonlinear: set[int]) -> bool:
    """Of degree at most 2, or in the `nonlinear` states alone: the terms of an energy,
    quartic in the positions that cubic springs act on, quadratic in the speeds. Its
    change along the field keeps a lower degree, so its programs are far smaller
    (probe72/av32's quartic barrier: 2 476 variables against 10 333; probe48/c05's
    quartic V in 8 states: 2 557 against 30 361)."""
    return sum(monomial) <= 2 or all(e == 0 or i in nonlinear for i, e in enumerate(monomial))


def squared_norm(n: int) -> P.Polynomial:
    return {tuple(int(k == i) * 2 for k in range(n)): Fraction(1) for i in range(n)}


