"""Exact conversion between the tool's expressions and sympy's, both ways.

To sympy: for users of a result (a certificate as a sympy expression). From sympy: for
specs built in Python, where the dynamics come as sympy expressions. Numbers stay exact
both ways: a sympy Float becomes the decimal it prints as, never a binary fraction.
Nothing is ever parsed from a string or evaluated.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Collection

import sympy

from fossil_dsl.ir import expr as E

_TO_SYMPY = {"sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan, "exp": sympy.exp,
             "log": sympy.log, "sqrt": sympy.sqrt, "tanh": sympy.tanh, "atan": sympy.atan,
             "abs": sympy.Abs}
_FROM_SYMPY = {sympy.sin: "sin", sympy.cos: "cos", sympy.tan: "tan", sympy.exp: "exp",
               sympy.log: "log", sympy.tanh: "tanh", sympy.atan: "atan", sympy.Abs: "abs"}


class SympyConversionError(ValueError):
    pass


def to_sympy(expr: E.Expr, symbols: dict[str, sympy.Symbol] | None = None) -> sympy.Expr:
    """The sympy expression of `expr`, with real symbols named after the variables."""
    symbols = {} if symbols is None else symbols
    if isinstance(expr, E.Num):
        return sympy.Rational(expr.value.numerator, expr.value.denominator)
    if isinstance(expr, E.Var):
        return symbols.setdefault(expr.name, sympy.Symbol(expr.name, real=True))
    if isinstance(expr, E.Pi):
        return sympy.pi
    if isinstance(expr, E.Add):
        return sympy.Add(*(to_sympy(t, symbols) for t in expr.terms))
    if isinstance(expr, E.Mul):
        return sympy.Mul(*(to_sympy(f, symbols) for f in expr.factors))
    if isinstance(expr, E.Div):
        return to_sympy(expr.numerator, symbols) / to_sympy(expr.denominator, symbols)
    if isinstance(expr, E.Neg):
        return -to_sympy(expr.operand, symbols)
    if isinstance(expr, E.Pow):
        return sympy.Pow(to_sympy(expr.base, symbols), to_sympy(expr.exponent, symbols))
    if isinstance(expr, E.Apply):
        return _TO_SYMPY[expr.func](to_sympy(expr.arg, symbols))
    raise SympyConversionError(f"no sympy form for {expr!r}")


def from_sympy(value, names: Collection[str]) -> E.Expr:
    """The tool's expression of a sympy expression (or a Python number) whose symbols
    are among `names`."""
    if isinstance(value, (int, Fraction)):
        return E.Num(Fraction(value))
    if isinstance(value, float):
        return E.Num(Fraction(repr(value)))
    if not isinstance(value, sympy.Basic):  # a string is never parsed
        raise SympyConversionError(f"expected a sympy expression or a number, not "
                                   f"{type(value).__name__}")
    return _from(value, frozenset(names))


def _from(node: sympy.Basic, names: frozenset[str]) -> E.Expr:
    if node.is_Rational:
        return E.Num(Fraction(int(node.p), int(node.q)))
    if node.is_Float:
        return E.Num(Fraction(str(node)))
    if node is sympy.pi:
        return E.Pi()
    if node.is_Symbol:
        if node.name not in names:
            raise SympyConversionError(
                f"unknown symbol `{node.name}` (known: {', '.join(sorted(names))})")
        return E.Var(node.name)
    args = [_from(a, names) for a in node.args]
    if node.is_Add:
        return E.add(*args)
    if node.is_Mul:
        return E.mul(*args)
    if node.is_Pow:
        if node.exp == sympy.Rational(1, 2):
            return E.apply("sqrt", args[0])
        return E.power(args[0], args[1])
    if node.func in _FROM_SYMPY:
        return E.apply(_FROM_SYMPY[node.func], args[0])
    raise SympyConversionError(f"`{node.func.__name__}` is not a function of the language "
                               f"(allowed: {', '.join(sorted(E.FUNCTIONS))})")
