"""Exact rationals: rounding floats to decimals, and their text (an integer, a finite
decimal, or p/q)."""
from __future__ import annotations

from fractions import Fraction


def number_text(value: Fraction) -> str:
    """Exact: an integer, a finite decimal, or p/q."""
    if value.denominator == 1:
        return str(value.numerator)
    den = value.denominator
    twos = fives = 0
    while den % 2 == 0:
        den //= 2
        twos += 1
    while den % 5 == 0:
        den //= 5
        fives += 1
    if den != 1:
        return f"{value.numerator}/{value.denominator}"
    digits = max(twos, fives)
    scaled = abs(value) * 10 ** digits
    whole, frac = divmod(int(scaled), 10 ** digits)
    sign = "-" if value < 0 else ""
    return f"{sign}{whole}.{frac:0{digits}d}"


def rational(value: float, digits: int) -> Fraction:
    """`value` rounded to `digits` decimals, exactly."""
    return Fraction(round(value * 10 ** digits), 10 ** digits)
