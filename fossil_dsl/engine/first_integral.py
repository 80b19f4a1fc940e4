"""Conserved quantities as barriers, for safety.

The combinations H of a few functions (the monomials of degree 1..d, sin and cos of each
argument of a sin or cos in the field, log of each state positive on D, and log |x + c|
where x + c divides x's own equation and keeps one sign on D) with dH/dt = 0 along
x' = f(x) (H(f(x)) = H(x) for a map) form a linear space: written over the states and
the field's atoms as indeterminates (ir/atoms.py), the conditions are linear equations
in H's coefficients with rational entries, so the space is found exactly (python-flint's
integer null space); a combination whose change is 0 over independent indeterminates is
0 for every value they take. An undamped pendulum's energy y^2 - 2 cos(x) is one.

B = sum_k a_k H_k + c is then chosen by a linear program on samples (B <= -e on I,
B >= e on U within D, largest e); a and c are rounded, and B stays exactly conserved
whatever the rounding. In continuous time no B can
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

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.sampling import sample
from fossil_dsl.engine.trajectories import column
from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.ir.atoms import AtomTable
from fossil_dsl.ir.sets import Intersection
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis

DEGREES = (2, 4)  # of the monomials among the candidates, in the order tried
MAX_BASIS = 130  # candidates, at most (4 states, degree 4: 69 monomials)
SAMPLES = 400  # of I and of U within D
DECIMALS = 6  # kept of a and c
MIN_MARGIN = 1e-6
MAX_POWER = 4  # of a state, in a conserved function made defined at its 0 (see _defined_on_zero)


@dataclass(frozen=True)
class ConservedFinding:
    formula: E.Expr  # B, exact
    controller: dict  # input -> exact constant (empty without inputs)
    operating: np.ndarray
    gain: np.ndarray  # 0: no feedback
    count: int  # conserved functions found (a basis of the space)
    degree: int
    margin: float
    seconds: float

    def describe(self) -> str:
        held = " with the inputs held at the operating point" if self.controller else ""
        return (f"a conserved quantity{held}: B in the span of {self.count} first "
                f"integrals (monomials of degree <= {self.degree}, sin, cos, log; exact null "
                f"space), margin {self.margin:.3g} on the samples, {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    """Safety, the default templates, and at most the default (linear) controller."""
    return plan.certificate.form == "safety" and default_synthesis(plan)


def search(plan: Plan, deadline: float, extra=None) -> ConservedFinding | None:
    """B from the conserved functions of the lowest degree that separate the samples of
    I and U (with `extra`: (points of I, points of U) found by the solvers), or None."""
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
    field = [traversal.substitute(f, held) for f in spec.dynamics]
    box = spec.domain.bounding_box()
    positive = [s for s, low in zip(states, box[0]) if low > 0] if box else []
    touching = [s for s, low in zip(states, box[0]) if low == 0] if box else []
    discrete = spec.time is TimeDomain.DISCRETE
    shifted = _invariant_logs(field, states, box) if box and not discrete else {}
    samples = None
    for degree, at_zero in _passes(touching):
        candidates = _candidates(field, states, degree, positive + at_zero) + list(shifted)
        if time.monotonic() > deadline or len(candidates) > MAX_BASIS:
            return None
        weights = _null_space(candidates, field, states, discrete, shifted)
        basis = [_defined_on_zero(w, candidates, at_zero) for w in weights]
        basis = [h for h in basis if h is not None]
        if not basis:
            continue
        samples = samples or _samples(plan, extra)
        found = _separating(basis, states, *samples)
        if found is not None:
            b, margin = found
            return ConservedFinding(b, held, operating, np.zeros((len(held), len(states))),
                                    len(basis), degree, margin, time.monotonic() - started)
    return None


def _candidates(field, states, degree: int, positive=()) -> list[E.Expr]:
    """The monomials of degree 1..degree, sin and cos of each argument of a sin or cos
    in the field, and the log of each state that is positive throughout the domain (a
    Lotka-Volterra system conserves x - log(x) + y - log(y))."""
    monomials = [E.mul(*(E.power(E.Var(s), E.Num(k)) for s, k in zip(states, m) if k))
                 for m in P.monomials(len(states), 1, degree)]
    arguments = dict.fromkeys(node.arg for f in field for node in E.walk(f)
                              if isinstance(node, E.Apply) and node.func in ("sin", "cos"))
    return monomials + [E.apply(func, a) for a in arguments for func in ("sin", "cos")] + \
        [E.apply("log", E.Var(s)) for s in positive]


def _invariant_logs(field, states, box) -> dict[E.Expr, E.Expr]:
    """log |x + c| for each factor x + c (c != 0) of x's own polynomial equation x' = f that
    keeps one sign on D's box, with its change f / (x + c), a polynomial: x = -c is then
    invariant (x + c is a Darboux polynomial), and the log of such factors is how the
    shifted Lotka-Volterra system conserves u - log(1 + u) + v - log(1 + v)."""
    import sympy
    from sympy.polys.polyerrors import BasePolynomialError
    from fossil_dsl.ir.symbolic import from_sympy, to_sympy
    symbols = {s: sympy.Symbol(s) for s in states}
    logs = {}
    for state, f, low, high in zip(states, field, *box):
        x, equation = symbols[state], to_sympy(f, symbols)
        try:
            factors = sympy.factor_list(equation, x)[1]
        except BasePolynomialError:  # not a polynomial in x
            continue
        for factor, _ in factors:
            c = _shift(factor, x)
            if c is not None and c != 0 and (low + c > 0 or high + c < 0):
                sign = 1 if low + c > 0 else -1
                log = E.apply("log", E.mul(E.Num(sign), E.add(E.Var(state), E.Num(c))))
                quotient = sympy.cancel(equation / (x + sympy.Rational(c)))
                logs[log] = from_sympy(quotient, states)
    return logs


def _shift(factor, x) -> Fraction | None:
    """c where the factor is a (x + c) with a and c rational numbers, else None."""
    import sympy
    if factor.free_symbols != {x}:
        return None
    poly = sympy.Poly(factor, x)
    if poly.degree() != 1 or not all(k.is_Rational for k in poly.all_coeffs()):
        return None
    a, b = poly.all_coeffs()
    c = sympy.Rational(b / a)
    return Fraction(int(c.p), int(c.q))


def _passes(touching: list[str]):
    """(degree, states whose log is a candidate although D reaches their 0): those logs
    only after every degree without them, so that a conserved polynomial is preferred."""
    return [(d, []) for d in DEGREES] + ([(d, touching) for d in DEGREES] if touching else [])


def _defined_on_zero(weights: list[Fraction], candidates, at_zero: list[str]):
    """The combination of the candidates, or where it holds b log(x) of a state x that D
    lets be 0: exp(l H) = x^(l b) exp(l (H - b log x)) with l b a positive integer for each
    such log (the SIR system conserves s + i - 0.5 log(s), so s exp(-2 (s + i)): defined at
    s = 0 and conserved as well). None where no small power l b does."""
    logs = {c.arg.name: w for w, c in zip(weights, candidates) if w and _is_log(c)}
    if not any(x in logs for x in at_zero):
        return _combination(weights, candidates)
    scale = _power_scale(list(logs.values()))
    if scale is None:
        return None
    rest = _combination([0 if _is_log(c) else w * scale
                         for w, c in zip(weights, candidates)], candidates)
    powers = [E.power(E.Var(x), E.Num(b * scale)) for x, b in logs.items()]
    return E.mul(*powers, E.apply("exp", rest))


def _is_log(candidate: E.Expr) -> bool:
    """The log of a state itself (not log |x + c|, whose argument keeps away from 0)."""
    return isinstance(candidate, E.Apply) and candidate.func == "log" and \
        isinstance(candidate.arg, E.Var)


def _power_scale(coefficients: list[Fraction]) -> Fraction | None:
    """l with l b a positive integer of at most MAX_POWER for each b, or None."""
    if len({b > 0 for b in coefficients}) != 1:
        return None
    numerators = [abs(b.numerator) for b in coefficients]
    denominators = [b.denominator for b in coefficients]
    common = Fraction(int(np.gcd.reduce(numerators)), int(np.lcm.reduce(denominators)))
    scale = (1 if coefficients[0] > 0 else -1) / common
    return scale if all(b * scale <= MAX_POWER for b in coefficients) else None


def _combination(weights: list[Fraction], candidates) -> E.Expr:
    return E.add(*(E.mul(E.Num(w), c) for w, c in zip(weights, candidates) if w))


def conserved(candidates, field, states, discrete: bool) -> list[E.Expr]:
    """A basis (exact, each scaled to largest weight 1) of the combinations of the
    candidates whose change along the system is identically 0 over the atoms."""
    return [_combination(w, candidates)
            for w in _null_space(candidates, field, states, discrete)]


def _null_space(candidates, field, states, discrete: bool,
                known=None) -> list[list[Fraction]]:
    """The weights of conserved combinations of the candidates (a basis, each scaled to
    largest weight 1); `known`: candidate -> its change, where that is simpler than
    calculus.change's (log |x + c|: a polynomial)."""
    import flint
    known = known or {}
    changes = [known[c] if c in known else calculus.change(c, states, field, discrete)
               for c in candidates]
    try:
        polynomials = AtomTable(states).polynomials(changes)
    except P.NotPolynomial:  # (a power with a symbolic exponent inside an atom's argument)
        return []
    rows = sorted({m for p in polynomials for m in p})
    if not rows:  # every candidate is conserved (f = 0, or the identity map)
        return [[Fraction(int(j == k)) for j in range(len(candidates))]
                for k in range(len(candidates))]
    table = [_integer_row([p.get(m, Fraction(0)) for p in polynomials]) for m in rows]
    space, count = flint.fmpz_mat(len(rows), len(candidates), sum(table, [])).nullspace()
    found = []
    for k in range(count):
        weights = [Fraction(int(space[j, k])) for j in range(len(candidates))]
        top = max(abs(w) for w in weights)
        found.append([w / top for w in weights])
    return found


def _integer_row(row: list[Fraction]) -> list[int]:
    scale = int(np.lcm.reduce([v.denominator for v in row])) if row else 1
    return [int(v * scale) for v in row]


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


def _separating(basis, states, inside: np.ndarray, outside: np.ndarray):
    """(B exact, margin): sum a_k H_k + c <= -e on `inside`, >= e on `outside`, with
    |a_k| <= 1 and the largest e <= 1 (a linear program); None where e is not positive."""
    from scipy.optimize import linprog
    values_in = np.column_stack([_values(h, states, inside) for h in basis])
    values_out = np.column_stack([_values(h, states, outside) for h in basis])
    k = len(basis)
    # variables a_1..a_k, c, e; minimise -e
    upper = np.vstack([np.hstack([values_in, np.ones((len(inside), 2))]),
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
    b = E.add(*(E.mul(E.Num(_decimal(w)), h) for h, w in zip(basis, a)), E.Num(_decimal(c)))
    return b, float(solution.x[-1])


def _values(h: E.Expr, states, points: np.ndarray) -> np.ndarray:
    return column(evaluate(h, state_env(states, points)), len(points))


def _decimal(value: float) -> Fraction:
    return Fraction(str(round(float(value), DECIMALS)))
