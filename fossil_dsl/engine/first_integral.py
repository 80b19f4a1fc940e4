"""Conserved quantities as barriers, for safety of a polynomial system.

The polynomials H of degree at most d (no constant term) with dH/dt = 0 along x' = f(x)
(H(f(x)) = H(x) for a map) form a linear space: the conditions are linear equations in
H's coefficients, with the rational coefficients of f, so the space is found exactly
(python-flint's integer null space). B = sum_k a_k H_k + c is then chosen by a linear
program on samples (B <= -e on I, B >= e on U within D, largest e); a and c are rounded,
and B stays exactly conserved whatever the rounding. In continuous time no B can
strictly decrease on its zero level set where the flow conserves volume (an undamped
oscillator), so such a B is proved by the kernel's variant rule "B never increases in
D" (kernel/safety_rules.py); a map's rule is met as it is.

With inputs, the controller holds them at the operating point (u = u*, no feedback): a
drift-free system (a unicycle) then conserves every function.

Nothing here is trusted: B is proved like any candidate.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.sampling import sample
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.ir.sets import Intersection
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis

DEGREES = (2, 4)  # of the conserved polynomials, in the order tried
MAX_BASIS = 130  # monomials in H, at most (4 states, degree 4: 69)
SAMPLES = 400  # of I and of U within D
DECIMALS = 6  # kept of a and c
MIN_MARGIN = 1e-6


@dataclass(frozen=True)
class ConservedFinding:
    formula: E.Expr  # B, exact
    controller: dict  # input -> exact constant (empty without inputs)
    operating: np.ndarray
    gain: np.ndarray  # 0: no feedback
    count: int  # conserved polynomials found (a basis of the space)
    degree: int
    margin: float
    seconds: float

    def describe(self) -> str:
        held = " with the inputs held at the operating point" if self.controller else ""
        return (f"a conserved quantity{held}: B in the span of {self.count} polynomial "
                f"first integrals of degree <= {self.degree} (exact null space), margin "
                f"{self.margin:.3g} on the samples, {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    """Safety, the default templates, and at most the default (linear) controller."""
    return plan.certificate.form == "safety" and default_synthesis(plan)


def search(plan: Plan, deadline: float, extra=None) -> ConservedFinding | None:
    """B from the conserved polynomials of the lowest degree that separate the samples
    of I and U (with `extra`: (points of I, points of U) found by the solvers), or None."""
    started = time.monotonic()
    spec, states = plan.spec, plan.states
    operating = np.zeros(0)
    if spec.inputs:
        from fossil_dsl.engine.linear import operating_point  # imports torch
        operating = operating_point(spec)
    if operating is None:
        return None
    held = {u: E.Num(Fraction(str(round(float(v), plan.options.digits))))
            for u, v in zip(spec.inputs, operating)}
    try:
        field = [P.polynomial(traversal.substitute(f, held), states) for f in spec.dynamics]
    except P.NotPolynomial:
        return None
    samples = None
    for degree in DEGREES:
        if time.monotonic() > deadline or len(P.monomials(len(states), 1, degree)) > MAX_BASIS:
            return None
        basis = conserved(field, len(states), degree, spec.time is TimeDomain.DISCRETE)
        if not basis:
            continue
        samples = samples or _samples(plan, extra)
        found = _separating(basis, *samples)
        if found is not None:
            b, margin = found
            return ConservedFinding(P.to_expr(b, states), held, operating,
                                    np.zeros((len(held), len(states))), len(basis), degree,
                                    margin, time.monotonic() - started)
    return None


def conserved(field, n: int, degree: int, discrete: bool) -> list[P.Polynomial]:
    """A basis of the polynomials H of degree 1..degree with H's change 0, each scaled
    to largest coefficient 1 (exact)."""
    import flint
    basis = P.monomials(n, 1, degree)
    changes = [P.change({m: Fraction(1)}, field, discrete) for m in basis]
    rows = sorted({m for change in changes for m in change})
    if not rows:  # every monomial is conserved (f = 0, or the identity map)
        return [{m: Fraction(1)} for m in basis]
    table = [[changes[j].get(m, Fraction(0)) for j in range(len(basis))] for m in rows]
    integers = [_integer_row(row) for row in table]
    space, count = flint.fmpz_mat(len(rows), len(basis), sum(integers, [])).nullspace()
    found = []
    for k in range(count):
        vector = [Fraction(int(space[j, k])) for j in range(len(basis))]
        top = max(abs(v) for v in vector)
        found.append({m: v / top for m, v in zip(basis, vector) if v})
    return found


def _integer_row(row: list[Fraction]) -> list[int]:
    scale = np.lcm.reduce([v.denominator for v in row]) if row else 1
    return [int(v * int(scale)) for v in row]


def _samples(plan: Plan, extra):
    spec = plan.spec
    rng = np.random.default_rng(plan.options.seed)
    box = spec.domain.bounding_box()
    unsafe = Intersection(spec.property.role("unsafe"), spec.domain)
    inside = np.asarray(sample(spec.property.role("initial"), plan.states, SAMPLES, rng, box))
    outside = np.asarray(sample(unsafe, plan.states, SAMPLES, rng, box))
    if extra is not None:
        inside = np.vstack([inside, *extra[0]]) if len(extra[0]) else inside
        outside = np.vstack([outside, *extra[1]]) if len(extra[1]) else outside
    return inside.reshape(-1, len(plan.states)), outside.reshape(-1, len(plan.states))


def _separating(basis, inside: np.ndarray, outside: np.ndarray):
    """(B exact, margin): sum a_k H_k + c <= -e on `inside`, >= e on `outside`, with
    |a_k| <= 1 and the largest e <= 1 (a linear program); None where e is not positive."""
    from scipy.optimize import linprog
    values_in = np.column_stack([_values(h, inside) for h in basis])
    values_out = np.column_stack([_values(h, outside) for h in basis])
    k = len(basis)
    # variables a_1..a_k, c, e; minimise -e
    upper = np.vstack([np.hstack([values_in, np.ones((len(inside), 1)),
                                  np.ones((len(inside), 1))]),
                       np.hstack([-values_out, -np.ones((len(outside), 1)),
                                  np.ones((len(outside), 1))])])
    cost = np.zeros(k + 2)
    cost[-1] = -1.0
    bounds = [(-1.0, 1.0)] * k + [(None, None), (0.0, 1.0)]
    solution = linprog(cost, A_ub=upper, b_ub=np.zeros(len(upper)), bounds=bounds,
                       method="highs")
    if solution.status != 0 or solution.x[-1] <= MIN_MARGIN:
        return None
    a, c = solution.x[:k], solution.x[k]
    b = P.add(*(P.scale(h, _decimal(w)) for h, w in zip(basis, a)),
              P.constant(_decimal(c), len(inside[0])))
    return b, float(solution.x[-1])


def _values(h: P.Polynomial, points: np.ndarray) -> np.ndarray:
    total = np.zeros(len(points))
    for monomial, coefficient in h.items():
        total += float(coefficient) * np.prod(points ** np.asarray(monomial), axis=1)
    return total


def _decimal(value: float) -> Fraction:
    return Fraction(str(round(float(value), DECIMALS)))
