"""Rationals from Arb's balls on a grid, rounded the safe way: the constants of the facts
about sin, cos, tanh, ... (atom_facts.py, taylor_facts.py)."""
from __future__ import annotations

from fractions import Fraction
from math import ceil, floor

GRID = 10 ** 9  # constants are rounded to this many parts of one


def arb(value: Fraction):
    """The exact rational as an Arb ball."""
    import flint
    return flint.arb(value.numerator) / value.denominator


def lower(ball) -> Fraction:
    """A grid rational at most every value the ball holds."""
    return _on_grid(ball.lower().mid(), floor)


def upper(ball) -> Fraction:
    """A grid rational at least every value the ball holds."""
    return _on_grid(ball.upper().mid(), ceil)


def nearest(ball) -> Fraction:
    """A grid rational near the ball's middle (no direction promised)."""
    return _on_grid(ball.mid(), round)


def _on_grid(point, rounding) -> Fraction:
    mantissa, exponent = point.man_exp()
    return Fraction(rounding(Fraction(int(mantissa)) * Fraction(2) ** int(exponent) * GRID),
                    GRID)
