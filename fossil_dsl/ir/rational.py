"""Rational expressions as a polynomial over a product of polynomial factors, for the
polynomial form of a comparison with divisions (a sum-of-squares refutation needs one).

`quotient(expr)` is N / (f1^e1 ... fk^ek), equal to expr and with every factor nonzero
wherever expr is defined (the kernel proves separately that every division is defined
where a condition is evaluated: kernel/definedness.py). A factor with an even exponent
is then positive there, and so is one positive by its form (1 + (1 + y)^2, see
`sign_by_form`) or evidently positive once expanded; multiplying N by the others, each
once, gives a polynomial with expr's sign (`numerator`). Sums take the largest exponent
of each factor (a least common denominator), so (a/d)^2 + (b/d)(c/e) + (c/e)^2 stays
over d^2 e^2: positive, of low degree.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir.polynomials import (NotPolynomial, Polynomial, add, constant,
                                       evidently_positive, multiply, polynomial, power, scale)


@dataclass(frozen=True)
class Factor:
    polynomial: Polynomial
    exponent: int
    positive: bool  # > 0 wherever the expression is defined


@dataclass(frozen=True)
class Quotient:
    top: Polynomial
    factors: dict  # a factor's polynomial, as a sorted tuple of items -> Factor

    def positive(self) -> bool:
        """Is the divisor > 0 wherever the expression is defined?"""
        return all(f.exponent % 2 == 0 or f.positive for f in self.factors.values())

    def divisor(self, n: int) -> Polynomial:
        result = constant(1, n)
        for f in self.factors.values():
            result = multiply(result, power(f.polynomial, f.exponent, n))
        return result


def numerator(expr: E.Expr, states: Sequence[str]) -> Polynomial:
    """A polynomial with expr's sign (0 included) at every point where expr is defined:
    N times each factor of the divisor that has an odd exponent and no known sign."""
    try:
        return polynomial(expr, states)
    except NotPolynomial:
        q = quotient(expr, states)
    result = q.top
    for f in q.factors.values():
        if f.exponent % 2 and not f.positive:
            result = multiply(result, f.polynomial)
    return result


def over_positive(expr: E.Expr, states: Sequence[str]) -> tuple[Polynomial, Polynomial]:
    """(N, D) with expr = N / D and D > 0 wherever expr is defined; raises NotPolynomial
    where a divisor's sign is not known."""
    q = quotient(expr, states)
    if not q.positive():
        raise NotPolynomial("a divisor whose sign is not known")
    return q.top, q.divisor(len(states))


def quotient(expr: E.Expr, states: Sequence[str]) -> Quotient:
    """expr as N over a product of factors; NotPolynomial for a division by 0 or an
    expression that is not rational."""
    n = len(states)
    if isinstance(expr, E.Add):
        result = quotient(expr.terms[0], states)
        for term in expr.terms[1:]:
            result = _sum(result, quotient(term, states), n)
        return result
    if isinstance(expr, E.Mul):
        result = Quotient(constant(1, n), {})
        for factor in expr.factors:
            result = _product(result, quotient(factor, states))
        return result
    if isinstance(expr, E.Neg):
        inner = quotient(expr.operand, states)
        return Quotient(scale(inner.top, -1), inner.factors)
    if isinstance(expr, E.Div):
        divisor = _reciprocal(quotient(expr.denominator, states), n,
                              sign_by_form(expr.denominator) == POSITIVE)
        return _product(quotient(expr.numerator, states), divisor)
    if isinstance(expr, E.Pow) and isinstance(expr.exponent, E.Num) \
            and expr.exponent.value.denominator == 1:
        k = int(expr.exponent.value)
        base = quotient(expr.base, states)
        if k < 0:
            base = _reciprocal(base, n, sign_by_form(expr.base) == POSITIVE)
        return Quotient(power(base.top, abs(k), n),
                        {key: Factor(f.polynomial, f.exponent * abs(k), f.positive)
                         for key, f in base.factors.items()})
    return Quotient(polynomial(expr, states), {})


def _sum(a: Quotient, b: Quotient, n: int) -> Quotient:
    factors = {}
    for key in a.factors.keys() | b.factors.keys():
        fa, fb = a.factors.get(key), b.factors.get(key)
        largest = max(f.exponent for f in (fa, fb) if f is not None)
        factors[key] = Factor((fa or fb).polynomial, largest,
                              any(f.positive for f in (fa, fb) if f is not None))
    return Quotient(add(_raised(a, factors, n), _raised(b, factors, n)), factors)


def _raised(q: Quotient, factors: dict, n: int) -> Polynomial:
    """q's numerator over the common divisor `factors`."""
    top = q.top
    for key, f in factors.items():
        missing = f.exponent - (q.factors[key].exponent if key in q.factors else 0)
        if missing:
            top = multiply(top, power(f.polynomial, missing, n))
    return top


def _product(a: Quotient, b: Quotient) -> Quotient:
    factors = dict(a.factors)
    for key, f in b.factors.items():
        old = factors.get(key)
        factors[key] = f if old is None else \
            Factor(f.polynomial, old.exponent + f.exponent, old.positive or f.positive)
    return Quotient(multiply(a.top, b.top), factors)


def _reciprocal(q: Quotient, n: int, by_form: bool) -> Quotient:
    """1 / q: the divisor's factors move up, q's numerator becomes a factor. It is
    positive where q is positive by its form over a positive divisor (q = N / D > 0 and
    D > 0, so N > 0), or where it is evidently positive."""
    if not q.top:
        raise NotPolynomial("a division by 0")
    if len(q.top) == 1 and all(k == 0 for k in next(iter(q.top))):  # a number c != 0
        return Quotient(scale(q.divisor(n), 1 / next(iter(q.top.values()))), {})
    positive = (by_form and q.positive()) or evidently_positive(q.top)
    key = tuple(sorted(q.top.items()))
    return Quotient(q.divisor(n), {key: Factor(q.top, 1, positive)})


UNKNOWN, NONNEGATIVE, POSITIVE = 0, 1, 2


def sign_by_form(expr: E.Expr) -> int:
    """What an expression's form alone shows of its sign at every point: POSITIVE for
    1 + (1 + y)^2 (a positive number plus even powers), NONNEGATIVE for (x - y)^2,
    UNKNOWN otherwise (the expanded y^2 + 2 y + 2 is not `evidently_positive`)."""
    if isinstance(expr, E.Num):
        return POSITIVE if expr.value > 0 else NONNEGATIVE if expr.value == 0 else UNKNOWN
    if isinstance(expr, E.Pow) and isinstance(expr.exponent, E.Num) \
            and expr.exponent.value.denominator == 1:
        base, even = sign_by_form(expr.base), expr.exponent.value % 2 == 0
        if expr.exponent.value < 0:  # 1 / b^k: defined only where b != 0
            return POSITIVE if base == POSITIVE else UNKNOWN
        return max(base, NONNEGATIVE) if even else base
    if isinstance(expr, E.Add):
        signs = [sign_by_form(t) for t in expr.terms]
        return UNKNOWN if UNKNOWN in signs else max(signs)
    if isinstance(expr, (E.Mul, E.Div)):
        signs = [sign_by_form(f) for f in E.children(expr)]
        return min(signs)
    return UNKNOWN
