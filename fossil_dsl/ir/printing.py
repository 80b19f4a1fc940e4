"""Readable text for expressions and formulas, in the .fsl expression syntax."""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L

_SUM, _PRODUCT, _UNARY, _POWER, _ATOM = range(5)


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


def to_text(expr: E.Expr) -> str:
    return _text(expr)[0]


def _text(expr: E.Expr) -> tuple[str, int]:
    if isinstance(expr, E.Num):
        text = number_text(expr.value)
        return text, (_ATOM if expr.value >= 0 and "/" not in text else _UNARY)
    if isinstance(expr, E.Var):
        return expr.name, _ATOM
    if isinstance(expr, E.Pi):
        return "pi", _ATOM
    if isinstance(expr, E.Apply):
        return f"{expr.func}({to_text(expr.arg)})", _ATOM
    if isinstance(expr, E.Neg):
        return "-" + _wrap(expr.operand, _UNARY), _UNARY
    if isinstance(expr, E.Pow):
        return f"{_wrap(expr.base, _ATOM)}^{_wrap(expr.exponent, _ATOM)}", _POWER
    if isinstance(expr, E.Div):
        return f"{_wrap(expr.numerator, _PRODUCT)}/{_wrap(expr.denominator, _POWER)}", _PRODUCT
    if isinstance(expr, E.Mul):
        return "*".join(_wrap(f, _PRODUCT) for f in expr.factors), _PRODUCT
    if isinstance(expr, E.Add):
        return _sum_text(expr.terms), _SUM
    raise TypeError(f"not an expression: {expr!r}")


def _sum_text(terms) -> str:
    parts = [_wrap(terms[0], _SUM)]
    for term in terms[1:]:
        if isinstance(term, E.Neg):
            parts.append(" - " + _wrap(term.operand, _PRODUCT))
        elif isinstance(term, E.Num) and term.value < 0:
            parts.append(" - " + number_text(-term.value))
        elif isinstance(term, E.Mul) and isinstance(term.factors[0], E.Num) \
                and term.factors[0].value < 0:
            parts.append(" - " + _wrap(E.mul(E.Num(-term.factors[0].value),
                                             *term.factors[1:]), _PRODUCT))
        else:
            parts.append(" + " + _wrap(term, _PRODUCT))
    return "".join(parts)


def _wrap(expr: E.Expr, level: int) -> str:
    text, own = _text(expr)
    return text if own >= level else f"({text})"


def formula_text(formula: L.Formula) -> str:
    if isinstance(formula, L.Compare):
        return f"{to_text(formula.left)} {formula.relation} {to_text(formula.right)}"
    if isinstance(formula, L.And):
        return " and ".join(_formula_wrapped(a) for a in formula.args)
    if isinstance(formula, L.Or):
        return " or ".join(_formula_wrapped(a) for a in formula.args)
    if isinstance(formula, L.Not):
        return "not " + _formula_wrapped(formula.arg)
    if isinstance(formula, L.BoolConst):
        return "true" if formula.value else "false"
    raise TypeError(f"not a formula: {formula!r}")


def _formula_wrapped(formula: L.Formula) -> str:
    text = formula_text(formula)
    return f"({text})" if isinstance(formula, (L.And, L.Or)) else text
