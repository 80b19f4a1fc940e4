"""A rational vector field over one denominator, f = N / Q (N and Q polynomials, sympy's
`together` and `lcm`), for the sum-of-squares programs: where Q > 0 on D, dV/dt <= -g
is grad V . N <= -g Q, which is still linear in V. Q's sign is only sampled here: the
programs' functions are proved like any candidate, and the kernel proves that every
division is defined on D.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.trajectories import column
from fossil_dsl.ir import polynomials as P

SIGN_SAMPLES = 2000  # points of D's box where Q's sign is looked at


def over_one_denominator(field, states, box, seed: int = 0):
    """(N, Q) with f = N / Q and Q > 0 at every sampled point of D's bounding box
    (the signs are flipped where Q < 0 there), or None where f is not rational or Q
    changes sign."""
    import sympy
    from fossil_dsl.ir.symbolic import SympyConversionError, to_sympy
    symbols = {s: sympy.Symbol(s, real=True) for s in states}
    generators = [symbols[s] for s in states]
    try:
        parts = [sympy.fraction(sympy.together(to_sympy(f, symbols))) for f in field]
        denominator = sympy.lcm([d for _, d in parts])
        numerators = [sympy.cancel(n * denominator / d) for n, d in parts]
        polynomials = [_polynomial(e, generators) for e in numerators + [denominator]]
    except (SympyConversionError, sympy.PolynomialError, ValueError):
        return None
    *numerators, denominator = polynomials
    sign = _sign(P.to_expr(denominator, states), states, box, seed)
    if sign == 0:
        return None
    return [P.scale(n, sign) for n in numerators], P.scale(denominator, sign)


def _polynomial(expression, generators) -> P.Polynomial:
    import sympy
    poly = sympy.Poly(expression, *generators, domain="QQ")  # PolynomialError if not one
    return {monomial: Fraction(int(c.p), int(c.q)) for monomial, c in poly.terms()
            if c != 0}


def _sign(denominator, states, box, seed: int) -> int:
    """1 or -1 where Q has that sign at every sampled point, else 0."""
    if box is None:
        return 0
    low, high = np.asarray(box[0], dtype=float), np.asarray(box[1], dtype=float)
    points = low + (high - low) * np.random.default_rng(seed).random((SIGN_SAMPLES, len(low)))
    values = column(evaluate(denominator, state_env(states, points)), SIGN_SAMPLES)
    return 1 if values.min() > 0 else -1 if values.max() < 0 else 0
