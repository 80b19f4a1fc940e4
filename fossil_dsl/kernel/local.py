"""A function is negative near the origin, from its Taylor expansion there.

The lemma (docs/certificates.md, "The ball round the origin"): let g be three times
differentiable on the ball |x| <= ρ, with g(0) = 0, ∇g(0) = 0, x^T H x / 2 <= -μ |x|^2
for the Hessian H of g at 0, and each third partial derivative d_ijk g bounded by M_ijk
in absolute value on the ball. Taylor's theorem with the Lagrange remainder gives, for
|x| <= ρ, g(x) <= -μ|x|^2 + (1/6) sum_ijk M_ijk |x_i x_j x_k| over the n^3 ordered
triples, and by Cauchy-Schwarz (sum_ijk (x_i x_j x_k)^2 = |x|^6) the sum is at most
sqrt(S) |x|^3 with S = sum_ijk M_ijk^2: g < 0 for 0 < |x| when 36 μ^2 > S ρ^2 (with one
bound M for all, S = n^3 M^2).

Each hypothesis is an obligation like any other (exported, re-checked); the kernel only
chooses μ and the bounds, from the Hessian's eigenvalues and from the third derivatives
(their enclosures on the ball's box and their values at a few points), and a poor choice
can only leave the lemma unproved.
"""
from __future__ import annotations

import functools
import itertools
import math
from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import traversal
from fossil_dsl.ir.calculus import derivative
from fossil_dsl.ir.enclosure import enclose
from fossil_dsl.kernel.obligations import Facts, Obligation

MU_SHARE = Fraction(9, 10)  # of the Hessian's margin, as μ
M_FACTOR = 4  # the bound M over the largest third derivative seen at the probe points
ROOM = 4  # at most this factor over the chosen bounds where the radius allows
MAX_STATES = 6  # 56 third derivatives; beyond, the lemma is not tried


def negative_near_origin(facts: Facts, name: str, g: E.Expr, words: str) -> bool:
    """Add the lemma's obligations for g < 0 on 0 < |x| <= r (r: the claim's excluded
    ball); False (and nothing added) where the lemma cannot apply."""
    states, rho = facts.states, facts.r
    if not 0 < len(states) <= MAX_STATES or rho <= 0:
        return False
    try:
        at_zero = _at_origin(g, states)
        if any(isinstance(v, E.Num) and v.value for v in at_zero):
            return False  # not flat at the origin: the lemma cannot hold
        hessian = _hessian_at_origin(g, states)
        if hessian is None:
            return False
        mu = _margin(hessian)
        thirds = _third_derivatives(g, tuple(states))
        bounds = _bounds(thirds, states, rho, mu)
    except (E.ExprError, ValueError, ZeroDivisionError, OverflowError):
        return False
    if mu is None or bounds is None:
        return False
    _obligations(facts, name, words, at_zero, hessian, mu, thirds, bounds)
    return True


def _at_origin(g: E.Expr, states) -> list[E.Expr]:
    """g and its gradient at 0."""
    origin = {s: E.ZERO for s in states}
    return [traversal.substitute(e, origin) for e in (g, *(derivative(g, s) for s in states))]


def _hessian_at_origin(g: E.Expr, states) -> list[list[E.Expr]] | None:
    """H's entries: numbers, or closed terms with a finite enclosure (cos(pi/3) where
    the field has sin(x + pi/3): the obligation on H states them exactly, and only a
    procedure that encloses them soundly can prove it)."""
    origin = {s: E.ZERO for s in states}
    rows = []
    for a in states:
        first = derivative(g, a)
        row = [traversal.substitute(derivative(first, b), origin) for b in states]
        for entry in row:
            low, high = enclose(entry)  # raises on a state left in it
            if not (math.isfinite(low) and math.isfinite(high) and low <= high):
                return None
        rows.append(row)
    return rows


def _margin(hessian) -> Fraction | None:
    """μ > 0 with H/2 + μ I negative definite (numerically; the obligation decides)."""
    import numpy as np
    middle = [[sum(enclose(entry)) / 2 for entry in row] for row in hessian]
    largest = float(np.linalg.eigvalsh(np.array(middle, dtype=float) / 2).max())
    if not largest < 0:
        return None
    return Fraction(-largest * float(MU_SHARE)).limit_denominator(10 ** 6) or None


@functools.lru_cache(maxsize=8)  # the engine tries one g at several radii
def _third_derivatives(g: E.Expr, states) -> dict[tuple[int, ...], E.Expr]:
    found = {}
    for i, j, k in itertools.combinations_with_replacement(range(len(states)), 3):
        found[(i, j, k)] = derivative(derivative(derivative(g, states[i]), states[j]),
                                      states[k])
    return found


def _bounds(thirds, states, rho: Fraction, mu: Fraction | None) -> dict | None:
    """M_ijk for which 36 μ^2 > S ρ^2 (see the module's text), or None: the lesser of the
    derivative's enclosure on the ball's box (with 5 % room) and one bound for all,
    M_FACTOR times the largest |third derivative| at the origin and at ±ρ/2 on each
    axis. The enclosures are the sharper where the derivatives differ (a CSTR's degree-4
    V: radius 1/400 against 1/1600), the single bound where an expression is so large
    that its enclosure is loose (an acrobot's decrease: 67 against 5 at radius 1/100)."""
    if mu is None:
        return None
    box = {s: (-rho, rho) for s in states}
    single = _short(M_FACTOR * _probed(thirds.values(), states, rho))
    bounds = {key: _lesser(_short(1.05 * max(map(abs, enclose(third, box)))), single)
              for key, third in thirds.items()}
    if None in bounds.values() or not 36 * mu ** 2 > rho ** 2 * _sum_of_squares(bounds):
        return None
    # the room the radius leaves, given to the bounds (up to ROOM times): a bound close
    # to the derivative's largest value makes its obligation slow to prove (probe58/ab01:
    # its kernel 5.8 -> 12.1 s with the enclosures' 5 % alone)
    room = min(ROOM, 0.9 * math.sqrt(float(36 * mu ** 2 / (rho ** 2 * _sum_of_squares(bounds)))))
    wider = {key: _short(float(b) * room) for key, b in bounds.items()}
    return wider if room > 1 and 36 * mu ** 2 > rho ** 2 * _sum_of_squares(wider) else bounds


def _probed(thirds, states, rho: Fraction) -> float:
    """The largest |third derivative| at the origin and at ±ρ/2 on each axis."""
    probes = [{s: E.ZERO for s in states}]
    for s, sign in itertools.product(states, (1, -1)):
        probes.append({t: E.Num(sign * rho / 2) if t == s else E.ZERO for t in states})
    largest = 0.0
    for third in thirds:
        for probe in probes:
            low, high = enclose(traversal.substitute(third, probe))
            largest = max(largest, abs(low), abs(high))
    return largest


def _lesser(a: Fraction | None, b: Fraction | None) -> Fraction | None:
    """The smaller bound, where either is known."""
    return b if a is None else a if b is None else min(a, b)


def _short(value: float) -> Fraction | None:
    """Above value, a multiple of 1/1000; None for inf or NaN."""
    return Fraction(math.ceil(value * 1000) + 1, 1000) if math.isfinite(value) else None


def _sum_of_squares(bounds: dict) -> Fraction:
    """S: the sum over the n^3 ordered triples (an unordered one counts 1, 3 or 6 times)."""
    return sum(_orderings(key) * b ** 2 for key, b in bounds.items())


def _orderings(key: tuple[int, ...]) -> int:
    return math.factorial(len(key)) // math.prod(
        math.factorial(key.count(i)) for i in set(key))


def _obligations(facts: Facts, name, words, at_zero, hessian, mu, thirds, bounds) -> None:
    states, rho, n = facts.states, facts.r, len(facts.states)
    prefix = f"local:{name}"
    facts.obligations.append(Obligation(
        f"{prefix}:flat", f"{words} and its gradient are 0 at the origin",
        L.disjunction(*(L.disjunction(L.Compare("<", v, E.ZERO), L.Compare(">", v, E.ZERO))
                        for v in at_zero))))
    x = [E.Var(s) for s in states]
    form = E.add(*(E.mul(E.Num(Fraction(1, 2)), hessian[i][j], x[i], x[j])
                   for i in range(n) for j in range(n)),
                 E.mul(E.Num(mu), facts.squared_norm()))
    # both sides are quadratic forms: on the shell 1/4 <= |x|^2 <= 1 is for every x, and
    # a bounded, strict question suits every procedure (the interval one included)
    norm = facts.squared_norm()
    shell = L.conjunction(L.Compare(">=", norm, E.Num(Fraction(1, 4))),
                          L.Compare("<=", norm, E.ONE))
    facts.obligations.append(Obligation(
        f"{prefix}:hessian", f"x^T H x / 2 <= -{mu} |x|^2 for the Hessian H of {words} at "
        "the origin (on 1/4 <= |x|^2 <= 1, hence everywhere)",
        L.conjunction(shell, L.Compare(">", form, E.ZERO))))
    ball = facts.ball(rho)
    for (i, j, k), third in thirds.items():
        bound = bounds[(i, j, k)]
        facts.never(f"{prefix}:third:{i}{j}{k}", f"|d^3 {words}/dx{i}dx{j}dx{k}| <= {bound} on "
                    f"the ball |x| <= {rho}", ball,
                    L.disjunction(L.Compare(">", third, E.Num(bound)),
                                  L.Compare("<", third, E.Num(-bound))),
                    # nearly constant on the tiny ball: bisection settles it at once,
                    # where Z3 stalled for its whole share (18 s) on a degree-6 V's
                    first="interval")
    total = _sum_of_squares(bounds)
    facts.obligations.append(Obligation(
        f"{prefix}:radius", f"36 μ^2 > S ρ^2 for μ = {mu}, S = {total} (the sum of the "
        f"third derivatives' squared bounds over the {n}^3 ordered triples), ρ = {rho}, "
        f"so {words} < 0 for 0 < |x| <= ρ",
        L.Compare("<=", E.Num(36 * mu ** 2), E.Num(total * rho ** 2))))
