"""Rounding a semidefinite program's floating-point Gram matrices to exact ones.

Rational entries (MULTIPLIER_DECIMALS decimals) that are checked positive semidefinite
exactly, and the projection that makes s0's Gram matrix satisfy a refutation's identity
exactly (sos_refutation.py; each entry feeds one monomial, so each monomial's residual is
spread evenly over its entries).
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from fossil_dsl.ir import polynomials as P
from fossil_dsl.solvers.positivstellensatz import SumOfSquares, positive_semidefinite

MULTIPLIER_DECIMALS = 12  # kept of a refutation's multipliers


def decimal(value: float, decimals: int) -> Fraction:
    return Fraction(round(float(value) * 10 ** decimals), 10 ** decimals) \
        if math.isfinite(value) else Fraction(0)


def psd_square(basis, G: np.ndarray) -> SumOfSquares | None:
    """G rounded to rationals; nudged up the diagonal if rounding left it indefinite."""
    for nudge in (0.0, 1e-10, 1e-8):
        gram = rational_matrix(G + nudge * np.eye(len(basis)))
        if positive_semidefinite(gram):
            return SumOfSquares(tuple(basis), gram)
    return None


def rational_matrix(G: np.ndarray) -> tuple[tuple[Fraction, ...], ...]:
    size = len(G)
    rows = [[decimal((G[i, j] + G[j, i]) / 2, MULTIPLIER_DECIMALS) for j in range(size)]
            for i in range(size)]
    return tuple(tuple(row) for row in rows)


def projected(basis, G: np.ndarray, target: P.Polynomial) -> SumOfSquares | None:
    """The rational Gram matrix nearest to G (Frobenius) with m^T G m = target exactly,
    if it is positive semidefinite: each entry (a, b) feeds one monomial m_a m_b, so the
    projection spreads each monomial's residual evenly over its entries."""
    gram = [list(row) for row in rational_matrix(G)]
    classes: dict[P.Monomial, list[tuple[int, int]]] = {}
    for a, ma in enumerate(basis):
        for b, mb in enumerate(basis):
            classes.setdefault(P.times(ma, mb), []).append((a, b))
    if any(monomial not in classes for monomial in target):
        return None
    for monomial, pairs in classes.items():
        residual = target.get(monomial, Fraction(0)) - sum(gram[a][b] for a, b in pairs)
        if residual:
            share = residual / len(pairs)
            for a, b in pairs:
                gram[a][b] += share
    rational = tuple(tuple(row) for row in gram)
    return SumOfSquares(tuple(basis), rational) if positive_semidefinite(rational) else None
