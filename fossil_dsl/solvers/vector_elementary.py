"""The elementary functions on interval arrays, from Taylor series with remainders.

The C library's sin, exp, ... are accurate in practice but promise nothing, so none is
used: each function's value at a float is enclosed by a Taylor polynomial evaluated in
outward-rounded interval arithmetic (vector_intervals.py) plus a bound on the series'
tail, after an exact or enclosed reduction of the argument:
- sin, cos: x - k 2pi with 2pi enclosed, |reduced| <= 3.2, 17 terms (tail < 1e-17);
- exp: x / 2^10, 21 terms (tail < 1e-22), squared ten times;
- atan: halved twice by atan x = 2 atan(x / (1 + sqrt(1 + x^2))) to |z| <= 0.415,
  22 terms of the alternating series (tail < 1e-18);
- log: x = m 2^e exactly (frexp), m in [1/sqrt 2, sqrt 2), log m = 2 atanh((m-1)/(m+1)),
  14 terms (tail < 1e-21);
- tanh = 1 - 2/(exp(2x) + 1), tan = sin/cos.
A function's range on an interval then follows from its endpoints where it is monotone,
and for sin and cos from where the interval may hold an extremum (tested with a slack
far above the rounding errors: an extremum counted that is not there only loosens).
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from fossil_dsl.solvers import vector_intervals as V

PI = V.widened_constant("3.141592653589793238462643383279502884197")
TWO_PI = V.outward(2 * PI[0], 2 * PI[1])
HALF_PI = V.outward(PI[0] / 2, PI[1] / 2)
LN2 = V.widened_constant("0.6931471805599453094172321214581765680755")
REDUCIBLE = 1e6  # sin and cos beyond: [-1, 1]
EXP_TOP, EXP_BOTTOM = 709.0, -745.0  # exp overflows above, is below the least double under
TANH_CLIP = 300.0  # tanh beyond is within 1e-260 of +-1
ATAN_CLIP = 1e100

SIN_TERMS, EXP_TERMS, ATAN_TERMS, LOG_TERMS = 17, 21, 22, 14
# the reduced arguments' bounds: pi (+ rounding); 709/1024 and 745/1024; tan(pi/8);
# (sqrt 2 - 1)/(sqrt 2 + 1)
SIN_BOUND, EXP_BOUND, ATAN_BOUND, LOG_BOUND = (Fraction(16, 5), Fraction(73, 100),
                                               Fraction(83, 200), Fraction(43, 250))


def _coefficients(values):
    return [V.constant(Fraction(v)) for v in values]


# sin: x * sum (-1)^k (x^2)^k / (2k+1)!; cos: sum (-1)^k (x^2)^k / (2k)!
_SIN = _coefficients(Fraction((-1) ** k, math.factorial(2 * k + 1)) for k in range(SIN_TERMS))
_COS = _coefficients(Fraction((-1) ** k, math.factorial(2 * k)) for k in range(SIN_TERMS))
_EXP = _coefficients(Fraction(1, math.factorial(k)) for k in range(EXP_TERMS))
_ATAN = _coefficients(Fraction((-1) ** k, 2 * k + 1) for k in range(ATAN_TERMS))
_ATANH = _coefficients(Fraction(1, 2 * k + 1) for k in range(LOG_TERMS))


def _tail(bound: Fraction, power: int, divisor: int) -> float:
    """An upper bound (a double) of bound^power / divisor: the series' tail for every
    reduced argument within `bound`, computed once and exactly."""
    return V.constant(bound ** power / divisor)[1]


def _within(x, bound: Fraction, value):
    """value where the reduced argument x lies within `bound` (as the tail assumes; the
    reductions guarantee it, this checks it), NaN (refuting nothing) elsewhere."""
    return V.whole_where(V.magnitude(x) > float(bound), value)


def _point(x):
    x = np.asarray(x, dtype=float)
    return x, x


def _reduced(x):
    """x - k 2pi with k = round(x / 2pi): within pi of 0 (plus rounding)."""
    turns = np.round(np.clip(x, -REDUCIBLE, REDUCIBLE) / (2 * math.pi))
    return V.sub(_point(x), V.mul(_point(turns), TWO_PI))


def trigonometric_at(x, sine: bool):
    """An enclosure of sin x (or cos x) at the floats x (|x| <= REDUCIBLE, else [-1, 1])."""
    reduced = _reduced(x)
    squared = V.square(reduced)
    if sine:
        value = V.mul(reduced, V.polynomial(squared, _SIN))
        tail = _tail(SIN_BOUND, 2 * SIN_TERMS + 1, math.factorial(2 * SIN_TERMS + 1))
    else:
        value = V.polynomial(squared, _COS)
        tail = _tail(SIN_BOUND, 2 * SIN_TERMS, math.factorial(2 * SIN_TERMS))
    value = _within(reduced, SIN_BOUND, V.with_error(value, tail))
    unit = (-np.ones_like(x), np.ones_like(x))
    return _clamped(_where(np.abs(x) > REDUCIBLE, unit, value))


def _where(mask, a, b):
    return np.where(mask, a[0], b[0]), np.where(mask, a[1], b[1])


def _clamped(a, low=-1.0, high=1.0):
    return np.clip(a[0], low, high), np.clip(a[1], low, high)


def _may_hold(a, offset: float, period: float):
    """Whether [low, high] may hold offset + k period for an integer k (a slack of 1e-9
    relative counts every near miss as a hit)."""
    low, high = a
    slack = 1e-9 * (1 + np.abs(low) + np.abs(high))
    with np.errstate(invalid="ignore"):
        k = np.floor((high + slack - offset) / period)
        return (offset + k * period >= low - slack) | ~np.isfinite(k)


def _trigonometric(a, sine: bool):
    low_values = trigonometric_at(a[0], sine)
    high_values = trigonometric_at(a[1], sine)
    result = V.hull(low_values, high_values)
    top, bottom = (math.pi / 2, -math.pi / 2) if sine else (0.0, math.pi)
    wide = (a[1] - a[0] >= 6.3) | ~np.isfinite(a[0]) | ~np.isfinite(a[1])
    high = np.where(wide | _may_hold(a, top, 2 * math.pi), 1.0, result[1])
    low = np.where(wide | _may_hold(a, bottom, 2 * math.pi), -1.0, result[0])
    return low, high


def sin(a):
    return _trigonometric(a, sine=True)


def cos(a):
    return _trigonometric(a, sine=False)


def tan(a):
    """Monotone between poles; the whole line where the interval may hold one."""
    values = [V.div(trigonometric_at(end, True), trigonometric_at(end, False)) for end in a]
    pole = _may_hold(a, math.pi / 2, math.pi) | (a[1] - a[0] >= 3.1)
    return V.whole_where(pole, (values[0][0], values[1][1]))


def exp_at(x):
    x = np.asarray(x, dtype=float)
    small = V.mul(_point(np.clip(x, EXP_BOTTOM, EXP_TOP)), V.constant(Fraction(1, 1024)))
    tail = 2.1 * _tail(EXP_BOUND, EXP_TERMS, math.factorial(EXP_TERMS))  # e^0.73 < 2.1
    value = _within(small, EXP_BOUND, V.with_error(V.polynomial(small, _EXP), tail))
    for _ in range(10):
        value = V.square(value)
    low = np.where(x < EXP_BOTTOM, 0.0, np.maximum(value[0], 0.0))
    high = np.where(x < EXP_BOTTOM, 5e-324, value[1])
    # above EXP_TOP, exp(EXP_TOP)'s lower bound still holds (exp grows), and exp(x) may
    # be up to the largest double (exp(709.5) = 1.35e308): no larger lower bound is safe
    return low, np.where(x > EXP_TOP, np.inf, high)


def exp(a):
    return exp_at(a[0])[0], exp_at(a[1])[1]


def _tanh_at(x):
    clipped = np.clip(np.asarray(x, dtype=float), -TANH_CLIP, TANH_CLIP)
    grown = exp_at(2 * clipped)  # exact doubling
    return V.sub((1.0, 1.0), V.div((2.0, 2.0), V.add(grown, (1.0, 1.0))))


def tanh(a):
    low = np.where(a[0] < -TANH_CLIP, -1.0, _tanh_at(a[0])[0])
    high = np.where(a[1] > TANH_CLIP, 1.0, _tanh_at(a[1])[1])
    return np.maximum(low, -1.0), np.minimum(high, 1.0)


def _halved(x):
    """tan(atan(x)/2) = x / (1 + sqrt(1 + x^2))."""
    return V.div(x, V.add((1.0, 1.0), V.sqrt(V.add((1.0, 1.0), V.square(x)))))


def _atan_at(x):
    x = np.asarray(x, dtype=float)
    clipped = np.clip(x, -ATAN_CLIP, ATAN_CLIP)
    z = _halved(_halved(_point(clipped)))
    series = _within(z, ATAN_BOUND, V.with_error(
        V.mul(z, V.polynomial(V.square(z), _ATAN)),
        _tail(ATAN_BOUND, 2 * ATAN_TERMS + 1, 2 * ATAN_TERMS + 1)))
    value = V.mul(series, (4.0, 4.0))
    beyond = V.outward(HALF_PI[0] - 1e-99, HALF_PI[1])
    value = _where(x > ATAN_CLIP, beyond, value)
    return _where(x < -ATAN_CLIP, V.neg(beyond), value)


def atan(a):
    return _atan_at(a[0])[0], _atan_at(a[1])[1]


def _log_at(x):
    """log x for floats x > 0."""
    x = np.minimum(np.asarray(x, dtype=float), np.finfo(float).max)
    mantissa, exponent = np.frexp(x)
    low_half = mantissa < math.sqrt(0.5)
    mantissa = np.where(low_half, 2 * mantissa, mantissa)
    exponent = np.where(low_half, exponent - 1, exponent).astype(float)
    m = _point(mantissa)
    s = V.div(V.sub(m, (1.0, 1.0)), V.add(m, (1.0, 1.0)))
    series = V.mul(V.mul(s, V.polynomial(V.square(s), _ATANH)), (2.0, 2.0))
    tail = 2.1 * _tail(LOG_BOUND, 2 * LOG_TERMS + 1, 2 * LOG_TERMS + 1)  # 1/(1 - s^2) < 1.05
    series = _within(s, LOG_BOUND, V.with_error(series, tail))
    return V.add(series, V.mul(_point(exponent), LN2))


def log(a):
    undefined = ~(a[0] > 0)
    safe_low = np.where(undefined, 1.0, a[0])
    high = np.where(np.isinf(a[1]), np.inf, _log_at(np.where(undefined, 1.0, a[1]))[1])
    return V.whole_where(undefined, (_log_at(safe_low)[0], high))


def sqrt(a):
    return V.sqrt(a)


def absolute(a):
    return V.absolute(a)


FUNCTIONS = {"sin": sin, "cos": cos, "tan": tan, "exp": exp, "log": log, "sqrt": sqrt,
             "tanh": tanh, "atan": atan, "abs": absolute}
