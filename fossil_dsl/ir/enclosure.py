"""Sound enclosures of closed expressions (no variables), by codac's outward-rounded
interval arithmetic. Used to compare constants such as pi/2 or sqrt(2) exactly enough
to decide a sign, and to bound them for solvers without those functions.
"""
from __future__ import annotations

import math
from fractions import Fraction

import codac

from fossil_dsl.ir import expr as E

_FUNCTIONS = {"sin": codac.sin, "cos": codac.cos, "tan": codac.tan, "exp": codac.exp,
              "log": codac.log, "sqrt": codac.sqrt, "tanh": codac.tanh,
              "atan": codac.atan, "abs": codac.abs}


def rational_interval(value: Fraction) -> codac.Interval:
    """The smallest double interval containing an exact rational."""
    near = float(value) if abs(value) < Fraction(10) ** 300 else math.copysign(math.inf, value)
    low = near if Fraction(near) <= value else math.nextafter(near, -math.inf)
    high = near if Fraction(near) >= value else math.nextafter(near, math.inf)
    if math.isinf(near):
        low, high = (-math.inf, -1e300) if value < 0 else (1e300, math.inf)
    return codac.Interval(low, high)


def enclose(expr: E.Expr) -> codac.Interval:
    """An interval containing the exact value of a variable-free expression."""
    if isinstance(expr, E.Num):
        return rational_interval(expr.value)
    if isinstance(expr, E.Pi):
        return codac.Interval.pi()
    if isinstance(expr, E.Neg):
        return -enclose(expr.operand)
    if isinstance(expr, E.Add):
        return _fold(expr.terms, lambda a, b: a + b)
    if isinstance(expr, E.Mul):
        return _fold(expr.factors, lambda a, b: a * b)
    if isinstance(expr, E.Div):
        return enclose(expr.numerator) / enclose(expr.denominator)
    if isinstance(expr, E.Pow):
        return _power(enclose(expr.base), expr.exponent)
    if isinstance(expr, E.Apply):
        return _FUNCTIONS[expr.func](enclose(expr.arg))
    raise ValueError(f"cannot enclose {expr!r}: it has variables")


def _fold(items, combine):
    result = enclose(items[0])
    for item in items[1:]:
        result = combine(result, enclose(item))
    return result


def _power(base: codac.Interval, exponent: E.Expr) -> codac.Interval:
    if isinstance(exponent, E.Num) and exponent.value.denominator == 1:
        return codac.pow(base, int(exponent.value))
    return codac.exp(enclose(exponent) * codac.log(base))


def sign(expr: E.Expr) -> int | None:
    """-1, 0 or 1 when certain; None when the enclosure straddles zero."""
    if isinstance(expr, E.Num):
        return (expr.value > 0) - (expr.value < 0)
    if E.free_vars(expr):
        return None
    interval = enclose(expr)
    if interval.is_empty():
        return None
    if interval.lb() > 0:
        return 1
    if interval.ub() < 0:
        return -1
    return None


def bounds(expr: E.Expr) -> tuple[Fraction, Fraction] | None:
    """Exact rational bounds of a closed expression, or None if unbounded."""
    interval = enclose(expr)
    if interval.is_empty() or math.isinf(interval.lb()) or math.isinf(interval.ub()):
        return None
    return Fraction(interval.lb()), Fraction(interval.ub())
