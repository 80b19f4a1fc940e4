"""Where an expression is undefined: division by zero, a negative power of zero, sqrt or
a fractional power of a negative number, log of a non-positive number, tan where the
cosine vanishes.

`undefined_where` gives one formula that holds exactly at the points where some partial
operation fails; an obligation proves it unsatisfiable on the region where the
expressions are evaluated. Operations whose argument is positive by its structure alone
(1 + exp(z), a sum of squares plus a positive number, ...) give no formula: they cannot
fail.
"""
from __future__ import annotations

from typing import Iterable

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L

ZERO = E.ZERO


def undefined_where(expressions: Iterable[E.Expr]) -> L.Formula | None:
    """A formula satisfied exactly where one of the expressions is undefined (None if
    none can be)."""
    failures: dict[L.Formula, None] = {}
    seen: set[E.Expr] = set()
    for expression in expressions:
        for node in E.walk(expression):
            if node in seen:
                continue
            seen.add(node)
            failure = _failure(node)
            if failure is not None:
                failures[failure] = None
    return L.disjunction(*failures) if failures else None


def _failure(node: E.Expr) -> L.Formula | None:
    if isinstance(node, E.Div):
        return _zero(node.denominator)
    if isinstance(node, E.Pow):
        return _power_failure(node)
    if isinstance(node, E.Apply):
        if node.func == "sqrt":
            return None if sign_of(node.arg) >= 0 else L.Compare("<", node.arg, ZERO)
        if node.func == "log":
            return None if sign_of(node.arg) > 0 else L.Compare("<=", node.arg, ZERO)
        if node.func == "tan":
            return _zero(E.apply("cos", node.arg))
    return None


def _power_failure(node: E.Pow) -> L.Formula | None:
    exponent = node.exponent
    if isinstance(exponent, E.Num) and exponent.value.denominator == 1:
        return _zero(node.base) if exponent.value < 0 else None
    if isinstance(exponent, E.Num) and exponent.value > 0:  # x^(p/q): x >= 0
        return None if sign_of(node.base) >= 0 else L.Compare("<", node.base, ZERO)
    return None if sign_of(node.base) > 0 else L.Compare("<=", node.base, ZERO)


def _zero(value: E.Expr) -> L.Formula | None:
    if sign_of(value) > 0 or sign_of(E.neg(value)) > 0:
        return None
    return L.conjunction(L.Compare("<=", value, ZERO), L.Compare(">=", value, ZERO))


def sign_of(expr: E.Expr) -> int:
    """1 if expr > 0 wherever it is defined, by structure alone; 0 if expr >= 0 so;
    -1 if nothing is known. Never wrong, often modest."""
    if isinstance(expr, E.Num):
        return 1 if expr.value > 0 else 0 if expr.value == 0 else -1
    if isinstance(expr, E.Pi):
        return 1
    if isinstance(expr, E.Apply):
        return {"exp": 1, "abs": 0, "sqrt": 0}.get(expr.func, -1)
    if isinstance(expr, E.Pow):
        return _power_sign(expr)
    if isinstance(expr, E.Add):
        signs = [sign_of(t) for t in expr.terms]
        return -1 if min(signs) < 0 else max(signs)
    if isinstance(expr, (E.Mul, E.Div)):
        factors = expr.factors if isinstance(expr, E.Mul) else (expr.numerator, expr.denominator)
        signs = [sign_of(f) for f in factors]
        return -1 if min(signs) < 0 else min(signs)
    return -1


def _power_sign(expr: E.Pow) -> int:
    exponent = expr.exponent
    base = sign_of(expr.base)
    if isinstance(exponent, E.Num) and exponent.value.denominator == 1 \
            and exponent.value % 2 == 0:
        return max(base, 0)  # an even power: >= 0, and > 0 where the base is
    return base
