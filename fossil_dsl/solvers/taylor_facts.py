"""Facts about sin and cos on a narrow range away from 0: a Taylor polynomial with its
remainder.

For lo <= a <= hi with c the (rational) middle and h = max(hi - c, c - lo), Taylor's
theorem with Lagrange's remainder gives, for f = sin or cos,
    f(a) = f(c) + f'(c) (a - c) + f''(c) (a - c)^2 / 2 + f'''(ξ) (a - c)^3 / 6,
and |f'''| <= 1. With rationals s ~ sin c and k ~ cos c in place of the true values
(their errors bounded from Arb's enclosures), t = f(a) lies within ε of the quadratic
T(a) = s + k (a - c) - s (a - c)^2 / 2 (sin) or k - s (a - c) - k (a - c)^2 / 2 (cos),
    ε = h^3 / 6 + |f(c) - its rational| (1 + h^2 / 2) + |f'(c) - its rational| h,
rounded up: T - ε <= t <= T + ε, two facts linear in t.

Why: the sector facts (sin a between a and k a) are exact at a = 0 but loose away from
it: on [0.4, 0.5] they leave sin a a band of 0.02, where this one leaves 3.5e-4. A
planar quadrotor's decrease condition (probe65/ao10, 6 states, sin and cos of the pitch
th) has no refutation with the sector facts on slabs of th near 0.44, and one on every
slab of width 0.1 with these (solvers/slab_split.py). A range with 0 inside keeps the
sector facts: they vanish with a, as conditions near the origin need.
"""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.arb_rounding import GRID, arb, nearest, upper

NARROW = Fraction(1, 2)  # the widest range these facts are given for


def narrow(reach) -> bool:
    """A range these facts are for: at most NARROW wide, without 0 in its interior."""
    return reach is not None and reach[1] - reach[0] <= NARROW \
        and not reach[0] < 0 < reach[1]


def taylor_facts(func: str, a: E.Expr, t: E.Expr, reach) -> list[L.Formula]:
    """T(a) - ε <= t <= T(a) + ε for t = func(a), func sin or cos, lo <= a <= hi."""
    lo, hi = reach
    middle = Fraction(round((lo + hi) / 2 * GRID), GRID)
    half = max(hi - middle, middle - lo)
    sine, cosine = arb(middle).sin(), arb(middle).cos()
    s, k = nearest(sine), nearest(cosine)
    # upper bounds of |true value - rational| (the balls hold the true values)
    sine_error, cosine_error = upper(abs(sine - arb(s))), upper(abs(cosine - arb(k)))
    if func == "sin":
        coefficients = (s, k, -s / 2)
        value_error, slope_error = sine_error, cosine_error
    else:
        coefficients = (k, -s, -k / 2)
        value_error, slope_error = cosine_error, sine_error
    error = value_error * (1 + half * half / 2) + slope_error * half \
        + upper(arb(half) ** 3 / 6)
    shift = E.add(a, E.Num(-middle))
    taylor = E.add(E.Num(coefficients[0]), E.mul(E.Num(coefficients[1]), shift),
                   E.mul(E.Num(coefficients[2]), E.power(shift, E.Num(Fraction(2)))))
    return [L.Compare("<=", t, E.add(taylor, E.Num(error))),
            L.Compare("<=", E.add(taylor, E.Num(-error)), t)]
