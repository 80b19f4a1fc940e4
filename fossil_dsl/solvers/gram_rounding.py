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


def settled(squares: list[SumOfSquares], factors: list[P.Polynomial], total: P.Polynomial,
            reach: set[P.Monomial]) -> tuple[list[SumOfSquares], P.Polynomial] | None:
    """The rounded multipliers `squares` (total = sum of squares[i] * factors[i] and
    more) with the residual on each monomial outside `reach` (those s0's Gram matrix
    cannot hold) moved onto a diagonal entry of one of them, and the new total; None
    where some residual cannot be moved.

    Why: multipliers whose terms cancel on such a monomial (a cart-pole's decrease with
    cos abstracted, probe53/n06: 813.4 - 164.6 - 648.8 on cos^3) leave the rounding's
    1e-12 there, which no projection onto s0 removes. A diagonal entry m_a^2 of
    multiplier i changes the monomials m_a^2 times factors[i]'s terms; only a raise
    (keeps the Gram matrix positive semidefinite) whose other changes stay in `reach`
    is taken."""
    squares = list(squares)
    for _ in range(len(total) + 1):
        stray = [m for m, c in total.items() if c and m not in reach]
        if not stray:
            return squares, total
        move = _raise_for(stray[0], total[stray[0]], squares, factors, reach)
        if move is None:
            return None
        index, entry, amount = move
        squares[index] = _raised(squares[index], entry, amount)
        square = squares[index].monomials[entry]
        total = P.add(total, P.scale(P.multiply({P.times(square, square): Fraction(1)},
                                                factors[index]), amount))
    return None


def _raise_for(monomial, residual, squares, factors, reach):
    """(multiplier, diagonal entry, amount > 0) that cancels `residual` on `monomial`."""
    for index, (square, factor) in enumerate(zip(squares, factors)):
        for entry, m in enumerate(square.monomials):
            diagonal = P.times(m, m)
            for term, coefficient in factor.items():
                if P.times(diagonal, term) != monomial:
                    continue
                amount = -residual / coefficient
                others = {P.times(diagonal, t) for t in factor if t != term}
                if amount > 0 and others <= reach:
                    return index, entry, amount
    return None


def _raised(square: SumOfSquares, entry: int, amount: Fraction) -> SumOfSquares:
    gram = [list(row) for row in square.gram]
    gram[entry][entry] += amount
    return SumOfSquares(square.monomials, tuple(tuple(row) for row in gram))
