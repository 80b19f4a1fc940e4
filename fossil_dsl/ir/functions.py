"""The functions of the language, and their exact values where those are rational.

Folding only ever applies to a rational argument (or a rational multiple of pi, for sin,
cos and tan), so this table needs no expression types: `expr.apply` asks it for the value
at a number.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Mapping


class DomainError(ValueError):
    """A function applied to a number outside its domain (log 0, sqrt of a negative)."""


@dataclass(frozen=True)
class Function:
    """A function the language allows; `exact` gives its value at a rational where that
    value is rational too, else None."""

    name: str
    exact: Callable[[Fraction], Fraction | None]
    piecewise_linear: bool = False  # abs: expressible in linear arithmetic with ite
    total: bool = True  # defined at every real number


def _at_zero(value: int) -> Callable[[Fraction], Fraction | None]:
    return lambda x: Fraction(value) if x == 0 else None


def _exact_log(x: Fraction) -> Fraction | None:
    if x <= 0:
        raise DomainError("log of a non-positive number")
    return Fraction(0) if x == 1 else None


def _exact_sqrt(x: Fraction) -> Fraction | None:
    if x < 0:
        raise DomainError("sqrt of a negative number")
    root_n, root_d = _isqrt_exact(x.numerator), _isqrt_exact(x.denominator)
    return Fraction(root_n, root_d) if root_n is not None and root_d is not None else None


def _isqrt_exact(n: int) -> int | None:
    root = math.isqrt(n)
    return root if root * root == n else None


FUNCTIONS: Mapping[str, Function] = {f.name: f for f in (
    Function("sin", _at_zero(0)),
    Function("cos", _at_zero(1)),
    Function("tan", _at_zero(0), total=False),
    Function("exp", _at_zero(1)),
    Function("log", _exact_log, total=False),
    Function("sqrt", _exact_sqrt, total=False),
    Function("tanh", _at_zero(0)),
    Function("atan", _at_zero(0)),
    Function("abs", abs, piecewise_linear=True),
)}


# sin(k pi / 6) for k = 0..11 where it is rational (Niven's theorem: sin of a rational
# multiple of pi is rational only at 0, +-1/2, +-1; tan only at 0, +-1), else None
_SINE_SIXTHS = (Fraction(0), Fraction(1, 2), None, Fraction(1), None, Fraction(1, 2),
                Fraction(0), Fraction(-1, 2), None, Fraction(-1), None, Fraction(-1, 2))

_TANGENT_QUARTERS = (Fraction(0), Fraction(1), None, Fraction(-1))


def exact_at_pi_multiple(func: str, c: Fraction) -> Fraction | None:
    """func(c pi) where it is rational (sin(pi/6) = 1/2: an operating angle of pi/6 then
    makes 1 - 2 sin(pi/6) exactly 0), else None."""
    if func == "tan":  # rational only at 0 and +-1 (k pi / 4; k pi / 2 is a pole)
        return _TANGENT_QUARTERS[int(4 * c) % 4] if (4 * c).denominator == 1 else None
    if func == "cos":
        return exact_at_pi_multiple("sin", c + Fraction(1, 2))
    if func != "sin" or (6 * c).denominator != 1:
        return None
    return _SINE_SIXTHS[int(6 * c) % 12]
