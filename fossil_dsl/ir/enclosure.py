"""Sound enclosures of closed expressions (no variables), by codac's outward-rounded
interval arithmetic. Used to compare constants such as pi/2 or sqrt(2) exactly enough
to decide a sign, and to bound them for solvers without those functions.

codac (IBEX) rounds outwards only while the processor rounds upwards: importing it
switches the whole process to upward rounding, and its + - * / give point intervals
that miss the true value if anything switches back. So codac is imported lazily, and
every computation with it runs under `upward_rounding()`, which sets the mode codac
chose and restores the caller's afterwards (the rest of the process keeps rounding to
nearest, as Python, numpy and torch expect).
"""
from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import functools
import math
import sys
from fractions import Fraction

from fossil_dsl.ir import expr as E


@functools.cache
def _libm():
    path = ctypes.util.find_library("m")
    if path is None:
        raise RuntimeError("cannot find the C maths library to control rounding modes")
    return ctypes.CDLL(path)


@functools.cache
def _codac():
    """The codac module, and the rounding mode it needs (read when it is imported)."""
    if "codac" in sys.modules:
        # its import set the mode and nobody read it: upward_rounding() could not set it
        # again, and codac's intervals would silently stop enclosing
        raise RuntimeError("codac was imported before fossil_dsl.ir.enclosure read the "
                           "rounding mode it needs: import it with import_codac()")
    libm = _libm()
    previous = libm.fegetround()
    import codac
    mode = libm.fegetround()
    libm.fesetround(previous)
    return codac, mode


def import_codac() -> None:
    """Import codac, keeping the process's rounding mode (importing codac directly
    leaves the whole process rounding upwards: Python's floats then overflow to an
    error where they should round to the largest double)."""
    _codac()


@contextlib.contextmanager
def upward_rounding():
    codac, mode = _codac()
    libm = _libm()
    previous = libm.fegetround()
    libm.fesetround(mode)
    try:
        yield codac
    finally:
        libm.fesetround(previous)


def rational_bounds(value: Fraction) -> tuple[float, float]:
    """The nearest doubles below and above an exact rational (compared exactly)."""
    if abs(value) >= Fraction(10) ** 300:
        return (-math.inf, -1e300) if value < 0 else (1e300, math.inf)
    near = float(value)
    low = near if Fraction(near) <= value else math.nextafter(near, -math.inf)
    high = near if Fraction(near) >= value else math.nextafter(near, math.inf)
    return low, high


def rational_interval(value: Fraction):
    """The smallest double interval containing an exact rational (call under
    upward_rounding)."""
    return _codac()[0].Interval(*rational_bounds(value))


def enclose(expr: E.Expr, box=None) -> tuple[float, float]:
    """(low, high) floats containing the exact value of a variable-free expression, or
    every value of the expression on `box` (variable -> (low, high) rationals: natural
    interval evaluation); low > high means the value is undefined (e.g. log of a
    negative number)."""
    if isinstance(expr, E.Num):  # no interval arithmetic needed (nor codac's import)
        return rational_bounds(expr.value)
    with upward_rounding() as codac:
        env = {E.Var(name): codac.Interval(rational_bounds(low)[0], rational_bounds(high)[1])
               for name, (low, high) in (box or {}).items()}
        interval = _enclose(expr, env)
        if interval.is_empty():
            return (math.inf, -math.inf)
        return (interval.lb(), interval.ub())


def _enclose(expr: E.Expr, env):
    """`env`: the variables' intervals, and the intervals of the nodes seen (a
    derivative's tree shares its subtrees)."""
    if expr in env:
        return env[expr]
    env[expr] = value = _enclosed_node(expr, env)
    return value


def _enclosed_node(expr: E.Expr, env):
    codac = _codac()[0]
    if isinstance(expr, E.Num):
        return rational_interval(expr.value)
    if isinstance(expr, E.Pi):
        return codac.Interval.pi()
    if isinstance(expr, E.Neg):
        return -_enclose(expr.operand, env)
    if isinstance(expr, E.Add):
        return _fold(expr.terms, lambda a, b: a + b, env)
    if isinstance(expr, E.Mul):
        return _fold(expr.factors, lambda a, b: a * b, env)
    if isinstance(expr, E.Div):
        return _enclose(expr.numerator, env) / _enclose(expr.denominator, env)
    if isinstance(expr, E.Pow):
        return _power(_enclose(expr.base, env), expr.exponent, env)
    if isinstance(expr, E.Apply):
        return function(expr.func, _enclose(expr.arg, env))
    raise ValueError(f"cannot enclose {expr!r}: it has variables")


def function(name: str, argument, rigorous: bool = True):
    """codac's `name` applied to an interval or an analytic expression, outward-rounded.
    codac's own tanh is not (it misses the true value by an ulp at about 2% of points),
    so tanh is built from exp, whose enclosures are: 1 - 2 / (exp(2z) + 1).
    tests/test_soundness.py compares every function with mpmath at 100 digits.
    `rigorous=False` keeps codac's own tanh, for searches whose answers are leads: the
    composite's derivative (4 e / (e + 1)^2, e = exp(2z) twice) is so loose on wide
    boxes that the centred forms lose their grip, and a search takes three times longer."""
    codac = _codac()[0]
    if name == "tanh" and rigorous:
        return 1 - 2 / (codac.exp(2 * argument) + 1)
    return getattr(codac, name)(argument)


def _fold(items, combine, env):
    result = _enclose(items[0], env)
    for item in items[1:]:
        result = combine(result, _enclose(item, env))
    return result


def _power(base, exponent: E.Expr, env):
    codac = _codac()[0]
    if isinstance(exponent, E.Num) and exponent.value.denominator == 1:
        return codac.pow(base, int(exponent.value))
    return codac.exp(_enclose(exponent, env) * codac.log(base))


def sign(expr: E.Expr) -> int | None:
    """-1, 0 or 1 when certain; None when the enclosure straddles zero."""
    if isinstance(expr, E.Num):
        return (expr.value > 0) - (expr.value < 0)
    if E.free_vars(expr):
        return None
    low, high = enclose(expr)
    if low > high:
        return None
    if low > 0:
        return 1
    if high < 0:
        return -1
    return None


def bounds(expr: E.Expr) -> tuple[Fraction, Fraction] | None:
    """Exact rational bounds of a closed expression, or None if unbounded."""
    low, high = enclose(expr)
    if low > high or math.isinf(low) or math.isinf(high):
        return None
    return Fraction(low), Fraction(high)
