"""Coordinates in which a query's main function has unit curvature, for taylor_boxes.py.

With H the Hessian of the query's largest smooth side at the origin (or the hull's
centre), H = U diag(l) U^T, the substitution x = T z with T = U diag(|l|^(-1/2)) (its
entries rounded to rationals) gives an equivalent query in z: a point z satisfies it
exactly when x = T z satisfies the original (T is invertible, checked exactly). In z the
side's second-order part is a sum of +-z_i^2, so the Taylor form's off-diagonal terms,
which interval arithmetic bounds by |H_ij| w_i w_j whatever the signs, nearly vanish, and
boxes can be wide.

Why: the acrobot's LQR decrease (probe67/aq18) has curvatures from 0.55 to 161 at the
origin; in the states the search needed boxes 0.15 of their distance from the origin
wide (65 000 per doubling of the radius, 962 000 boxes in 20 s in all), in z boxes as
wide as their distance near the origin (259 000 boxes in 15 s; docs/benchmarks.md,
session 68).
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import rational_bounds

DIGITS = 10 ** 6  # T's entries: multiples of 1e-6 of its largest
WORTH = 3.0  # below this ratio of the curvatures the states are used as they are
FLOOR = 1e-6  # of the largest curvature: smaller ones are raised to it


def transform(hessian: np.ndarray) -> list[list[Fraction]] | None:
    """T (rationals, invertible) with T^T H T about diag(+-1), or None where H's
    curvatures are within WORTH of each other (or not finite)."""
    if not np.all(np.isfinite(hessian)):
        return None
    values, vectors = np.linalg.eigh((hessian + hessian.T) / 2)
    sizes = np.abs(values)
    if sizes.max() <= 0 or sizes.max() / max(sizes.min(), 1e-300) < WORTH:
        return None
    sizes = np.maximum(sizes, FLOOR * sizes.max())
    numeric = vectors / np.sqrt(sizes)
    unit = np.abs(numeric).max()
    T = [[Fraction(round(v / unit * DIGITS)) * Fraction(unit).limit_denominator(DIGITS)
          / DIGITS for v in row] for row in numeric]
    return T if _inverse(T) is not None else None


def substituted(formula: L.Formula, names, T, hull):
    """(the query in z, z's names, z's hull) for x = T z, from x's hull."""
    z_names = tuple(_fresh(names, i) for i in range(len(names)))
    z = [E.Var(n) for n in z_names]
    mapping = {name: E.add(*[E.mul(E.Num(T[i][j]), z[j]) for j in range(len(names))
                             if T[i][j]]) for i, name in enumerate(names)}
    inverse = _inverse(T)
    z_hull = []
    for row in inverse:
        low = sum(min(c * Fraction(lo), c * Fraction(hi)) for c, (lo, hi) in zip(row, hull))
        high = sum(max(c * Fraction(lo), c * Fraction(hi)) for c, (lo, hi) in zip(row, hull))
        z_hull.append((rational_bounds(low)[0], rational_bounds(high)[1]))
    return L.substitute(formula, mapping), z_names, z_hull


def back(T, z_point) -> list[Fraction]:
    """x = T z, exactly."""
    return [sum(T[i][j] * z_point[j] for j in range(len(z_point))) for i in range(len(T))]


def _fresh(names, index: int) -> str:
    name = f"z{index}"
    while name in names:
        name += "_"
    return name


def _inverse(T) -> list[list[Fraction]] | None:
    """T^-1 in exact rationals (FLINT), or None if T is singular."""
    import flint
    n = len(T)
    matrix = flint.fmpq_mat(n, n, [flint.fmpq(v.numerator, v.denominator)
                                   for row in T for v in row])
    try:
        inverse = matrix.inv()
    except ZeroDivisionError:
        return None
    return [[Fraction(int(inverse[i, j].p), int(inverse[i, j].q)) for j in range(n)]
            for i in range(n)]
