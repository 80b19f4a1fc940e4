"""Facts about sin, cos and tanh on a narrow range away from 0: a Taylor polynomial with
its remainder.

For lo <= a <= hi with c the (rational) middle and h = max(hi - c, c - lo), Taylor's
theorem with Lagrange's remainder gives
    f(a) = f(c) + f'(c) (a - c) + f''(c) (a - c)^2 / 2 + f'''(ξ) (a - c)^3 / 6,
with |f'''| <= M: 1 for sin and cos, 2 for tanh (its third derivative is
(1 - T^2)(6 T^2 - 2) with T = tanh, between -2 and 2/3). With rationals q0, q1, q2 near
f(c), f'(c) and f''(c) / 2 (each one's error bounded from Arb's enclosures), t = f(a)
lies within
    ε = |f(c) - q0| + |f'(c) - q1| h + |f''(c)/2 - q2| h^2 + M h^3 / 6
of the quadratic T(a) = q0 + q1 (a - c) + q2 (a - c)^2, rounded up: T - ε <= t <= T + ε,
two facts linear in t.

Why: the sector facts (sin a between a and k a) are exact at a = 0 but loose away from
it: on [0.4, 0.5] they leave sin a a band of 0.02, where this one leaves 3.5e-4. A
planar quadrotor's decrease condition (probe65/ao10, 6 states, sin and cos of the pitch
th) has no refutation with the sector facts on slabs of th near 0.44, and one on every
slab of width 0.1 with these (solvers/slab_split.py); a tanh network's reach program
(probe77/ba11) has a V only with these, on cells of the domain (polynomial_field.py). A
range with 0 inside keeps the sector facts: they vanish with a, as conditions near the
origin need.
"""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.arb_rounding import GRID, arb, nearest, upper

NARROW = Fraction(1, 2)  # the widest range these facts are given for
THIRD_DERIVATIVE = {"sin": 1, "cos": 1, "tanh": 2}  # M: |f'''| <= M everywhere


def narrow(reach) -> bool:
    """A range these facts are for: at most NARROW wide, without 0 in its interior."""
    return reach is not None and reach[1] - reach[0] <= NARROW \
        and not reach[0] < 0 < reach[1]


def taylor_facts(func: str, a: E.Expr, t: E.Expr, reach) -> list[L.Formula]:
    """T(a) - ε <= t <= T(a) + ε for t = func(a), func in THIRD_DERIVATIVE,
    lo <= a <= hi."""
    lo, hi = reach
    middle = Fraction(round((lo + hi) / 2 * GRID), GRID)
    half = max(hi - middle, middle - lo)
    balls = _coefficients(func, arb(middle))
    coefficients = [nearest(ball) for ball in balls]
    errors = [upper(abs(ball - arb(q))) for ball, q in zip(balls, coefficients)]
    error = errors[0] + errors[1] * half + errors[2] * half * half \
        + upper(THIRD_DERIVATIVE[func] * arb(half) ** 3 / 6)
    shift = E.add(a, E.Num(-middle))
    taylor = E.add(E.Num(coefficients[0]), E.mul(E.Num(coefficients[1]), shift),
                   E.mul(E.Num(coefficients[2]), E.power(shift, E.Num(Fraction(2)))))
    return [L.Compare("<=", t, E.add(taylor, E.Num(error))),
            L.Compare("<=", E.add(taylor, E.Num(-error)), t)]


def _coefficients(func: str, middle):
    """Arb balls holding f(c), f'(c) and f''(c) / 2."""
    if func == "tanh":
        value = middle.tanh()
        slope = 1 - value * value
        return value, slope, -value * slope
    sine, cosine = middle.sin(), middle.cos()
    if func == "sin":
        return sine, cosine, -sine / 2
    return cosine, -sine, -cosine / 2
