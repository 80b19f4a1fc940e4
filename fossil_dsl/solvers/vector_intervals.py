"""Interval arithmetic on numpy arrays of boxes, rounded outwards.

An interval array is a pair (low, high) of float arrays (or scalars, broadcast). Every
operation computes its bounds in round-to-nearest and then moves each one ulp outwards
(`outward`): IEEE 754 rounds +, -, *, / and sqrt correctly, so the exact result lies
within an ulp of the computed one, and one ulp out encloses it whatever the
rounding mode. A NaN (inf - inf, 0 * inf) stands for the whole line. Where a value may be
undefined (a division by an interval holding 0, sqrt or log of an interval reaching
below 0, tan across a pole) the result is the whole line too: a box with such a point is
never refuted by what follows from it.

Why: codac's contractors evaluate one box per Python call (about 5 000 boxes a second
on a 4-state decrease condition); these evaluate thousands of boxes per numpy call.
The elementary functions are in vector_elementary.py (Taylor series with remainders
built from these operations, not the C library's functions).
"""
from __future__ import annotations

import functools
from fractions import Fraction

import numpy as np

from fossil_dsl.ir.enclosure import rational_bounds

INF = np.inf
ULP = 2.0 ** -52
TINY = 5e-324  # the least positive double


def outward(low, high):
    """Each bound moved out by |bound| 2^-52 + 2^-1074: at least one ulp (for a bound in
    [2^e, 2^(e+1)) the step is >= 2^(e-52), a double, so rounding cannot shrink it), which
    a correctly rounded result is within, in either rounding mode. Four times faster
    than np.nextafter. A NaN bound stays NaN: it passes through every later operation,
    and a comparison it reaches refutes nothing, as the whole line would."""
    return low - (np.abs(low) * ULP + TINY), high + (np.abs(high) * ULP + TINY)


def whole_where(mask, pair):
    """The whole line where `mask` holds, `pair` elsewhere."""
    return np.where(mask, -INF, pair[0]), np.where(mask, INF, pair[1])


@functools.lru_cache(maxsize=4096)
def constant(value: Fraction):
    """The tightest float interval holding an exact rational."""
    low, high = rational_bounds(value)
    return np.float64(low), np.float64(high)


def widened_constant(decimal: str):
    """A float interval for a constant given by a decimal text correct to 40 digits: the
    rational's bounds moved one more ulp out cover the 1e-40 the text may be off by."""
    return outward(*constant(Fraction(decimal)))


def add(a, b):
    return outward(a[0] + b[0], a[1] + b[1])


def neg(a):
    return -a[1], -a[0]


def sub(a, b):
    return add(a, neg(b))


def mul(a, b):
    products = (a[0] * b[0], a[0] * b[1], a[1] * b[0], a[1] * b[1])
    low = np.minimum(np.minimum(products[0], products[1]), np.minimum(products[2], products[3]))
    high = np.maximum(np.maximum(products[0], products[1]),
                      np.maximum(products[2], products[3]))
    # np.minimum passes a NaN (0 * inf) on: the result refutes nothing
    return outward(low, high)


def square(a):
    """a^2 with its lower bound 0 where a holds 0 (tighter than a * a)."""
    low_sq, high_sq = a[0] * a[0], a[1] * a[1]
    holds_zero = (a[0] <= 0) & (a[1] >= 0)
    low = np.where(holds_zero, 0.0, np.minimum(low_sq, high_sq))
    low, high = outward(low, np.maximum(low_sq, high_sq))
    return np.maximum(low, 0.0), high


def reciprocal(a):
    holds_zero = (a[0] <= 0) & (a[1] >= 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return whole_where(holds_zero, outward(1.0 / a[1], 1.0 / a[0]))


def div(a, b):
    return mul(a, reciprocal(b))


def power(a, n: int):
    """a^n for an integer n, by squaring."""
    if n < 0:
        return reciprocal(power(a, -n))
    if n == 0:
        return np.ones_like(a[0]), np.ones_like(a[1])
    if n % 2 == 0:
        return square(power(a, n // 2))
    return a if n == 1 else mul(a, power(a, n - 1))


def absolute(a):
    magnitude = np.maximum(np.abs(a[0]), np.abs(a[1]))
    holds_zero = (a[0] <= 0) & (a[1] >= 0)
    return np.where(holds_zero, 0.0, np.minimum(np.abs(a[0]), np.abs(a[1]))), magnitude


def sqrt(a):
    with np.errstate(invalid="ignore"):
        root = outward(np.sqrt(np.maximum(a[0], 0.0)), np.sqrt(np.maximum(a[1], 0.0)))
    return whole_where(a[0] < 0, (np.maximum(root[0], 0.0), root[1]))


def hull(a, b):
    return np.minimum(a[0], b[0]), np.maximum(a[1], b[1])


def magnitude(a):
    """The largest |value| in each interval."""
    return np.maximum(np.abs(a[0]), np.abs(a[1]))


def polynomial(x, coefficients):
    """sum_k coefficients[k] x^k by Horner's rule, every step outward-rounded."""
    result = coefficients[-1]
    for coefficient in reversed(coefficients[:-1]):
        result = add(mul(result, x), coefficient)
    return result


def with_error(a, error):
    """a widened by [-error, error] (error >= 0)."""
    return outward(a[0] - error, a[1] + error)
