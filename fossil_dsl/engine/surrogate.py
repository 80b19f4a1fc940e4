"""A polynomial stand-in for a vector field with elementary functions (exp, sin, tanh,
...), for the sum-of-squares programs only: each component that is not a polynomial is
replaced by its least-squares fit over samples of the domain, of the smallest degree of
those asked for whose largest sampled error is within TOLERANCE of the component's size.

The programs then ask their conditions of the stand-in, with their margin as the only
room for its error, so a function found with it may fail for the true field. Nothing
here is trusted: the functions are rounded and proved with the true field like any
candidate.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.sampling import sample
from fossil_dsl.engine.trajectories import column
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P

SAMPLES = 4000
# the largest sampled error allowed, relative to 1 + the component's largest sampled
# magnitude: a Morse force -2 (1 - e^-x) e^-x on [-1, 3] needs degree 7 for it
TOLERANCE = 0.01
MAX_TERMS = 120  # monomials of a fit, at most (degree 7 in 3 states)
DIGITS = 8  # kept of each coefficient


def polynomial_field(field, states, domain, degrees, seed: int = 0, linear=None):
    """The field with each non-polynomial component fitted, of the first of `degrees`
    within the tolerance, or None where some component has none (or the domain has no
    samples). With `linear` (the field's Jacobian at the origin, an equilibrium) a fit
    keeps that linear part and no constant, and only its terms of degree 2 and more are
    fitted: a stability program needs the stand-in to vanish at 0 as the field does (a
    least-squares fit's constant of 1e-4 leaves no V decreasing there: probe64/am05)."""
    exact = [_exactly(f, states) for f in field]
    if all(p is not None for p in exact):
        return exact
    points = np.asarray(sample(domain, states, SAMPLES, np.random.default_rng(seed),
                               domain.bounding_box()), dtype=float)
    if len(points) < SAMPLES // 2:
        return None
    rows = [None] * len(field) if linear is None else np.asarray(linear, dtype=float)
    fitted = [p if p is not None else _fitted(f, states, points, degrees, row)
              for f, p, row in zip(field, exact, rows)]
    return None if any(p is None for p in fitted) else fitted


def _fitted(f, states, points: np.ndarray, degrees, row=None) -> P.Polynomial | None:
    """f's fit in the states it uses, or None (no fit, or f not finite at a sample);
    with the row of its Jacobian at 0, that linear part and a fit of the rest."""
    with np.errstate(all="ignore"):
        values = column(evaluate(f, state_env(states, points)), len(points))
    used = [k for k, s in enumerate(states) if s in E.free_vars(f)]
    if not used or not np.all(np.isfinite(values)):
        return None
    if row is None:
        return _fit(points[:, used], values, used, len(states), degrees)
    n = len(states)
    part = {tuple(int(i == k) for i in range(n)): c for k in range(n)
            if (c := _rounded(row[k]))}
    rest = _fit(points[:, used], values - points @ row, used, n, degrees, lowest=2)
    return None if rest is None else P.add(part, rest)


def _rounded(value: float) -> Fraction:
    return Fraction(round(float(value), DIGITS)).limit_denominator(10 ** DIGITS)


def _exactly(f, states) -> P.Polynomial | None:
    try:
        return P.polynomial(f, states)
    except P.NotPolynomial:
        return None


def _fit(points: np.ndarray, values: np.ndarray, used: list[int], n: int,
         degrees, lowest: int = 0) -> P.Polynomial | None:
    """The least-squares polynomial of the smallest degree within the tolerance, in the
    states `used` (the columns of `points`) out of n, of terms of degree `lowest` up."""
    allowed = TOLERANCE * (1.0 + float(np.abs(values).max()))
    for degree in degrees:
        basis = P.monomials(len(used), lowest, degree)
        if len(basis) > MAX_TERMS:
            return None
        matrix = np.prod(points[:, None, :] ** np.asarray(basis)[None, :, :], axis=2)
        scales = np.abs(matrix).max(axis=0)
        scales[scales == 0] = 1.0
        solution = np.linalg.lstsq(matrix / scales, values, rcond=None)[0] / scales
        rounded = [_rounded(c) for c in solution]
        error = np.abs(matrix @ np.asarray(rounded, dtype=float) - values).max()
        if error <= allowed:
            return {_spread(m, used, n): c for m, c in zip(basis, rounded) if c}
    return None


def _spread(monomial, used: list[int], n: int) -> P.Monomial:
    """The exponents of the used states placed among all n."""
    exponents = [0] * n
    for k, power in zip(used, monomial):
        exponents[k] = power
    return tuple(exponents)
