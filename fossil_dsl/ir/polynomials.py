"""Exact sparse polynomials over the rationals: {exponent vector: coefficient}, built from
neutral expressions. Used where a polynomial identity must hold exactly (the kernel's
sum-of-squares check) and to set up sum-of-squares programs."""
from __future__ import annotations

from fractions import Fraction
from typing import Mapping, Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal

Monomial = tuple[int, ...]
Polynomial = dict[Monomial, Fraction]


class NotPolynomial(ValueError):
    pass


def polynomial(expr: E.Expr, states: Sequence[str]) -> Polynomial:
    """`expr` as a polynomial in `states` (raises NotPolynomial if it is not one)."""
    n = len(states)
    if isinstance(expr, E.Num):
        return constant(expr.value, n)
    if isinstance(expr, E.Var):
        if expr.name not in states:
            raise NotPolynomial(f"`{expr.name}` is not a state")
        return {tuple(int(s == expr.name) for s in states): Fraction(1)}
    if isinstance(expr, E.Add):
        return add(*(polynomial(t, states) for t in expr.terms))
    if isinstance(expr, E.Mul):
        result = constant(1, n)
        for factor in expr.factors:
            result = multiply(result, polynomial(factor, states))
        return result
    if isinstance(expr, E.Neg):
        return scale(polynomial(expr.operand, states), -1)
    if isinstance(expr, E.Div) and isinstance(expr.denominator, E.Num) \
            and expr.denominator.value != 0:
        return scale(polynomial(expr.numerator, states), 1 / expr.denominator.value)
    if isinstance(expr, E.Pow) and isinstance(expr.exponent, E.Num) \
            and expr.exponent.value.denominator == 1 and expr.exponent.value >= 0:
        return power(polynomial(expr.base, states), int(expr.exponent.value), n)
    raise NotPolynomial(f"`{expr}` is not a polynomial in the states")


def evidently_positive(p: Mapping[Monomial, Fraction]) -> bool:
    """p = c + sum of a_m m(x) with c > 0, every a_m > 0 and every m a product of even
    powers: then p(x) >= c > 0 for every x."""
    if not p:
        return False
    zero = (0,) * len(next(iter(p)))
    return p.get(zero, 0) > 0 and all(c > 0 and all(k % 2 == 0 for k in m)
                                      for m, c in p.items())


def constant(value, n: int) -> Polynomial:
    value = Fraction(value)
    return {(0,) * n: value} if value else {}


def add(*polynomials: Mapping[Monomial, Fraction]) -> Polynomial:
    result: Polynomial = {}
    for p in polynomials:
        accumulate(result, p)
    return result


def accumulate(total: Polynomial, p: Mapping[Monomial, Fraction]) -> None:
    """total += p, in place: a sum built term by term with `add` copies the whole sum at
    each term (a degree-8 Gram matrix's polynomial in 4 states: 4 900 copies of up to
    495 terms, 40 s of d18's run)."""
    for monomial, coefficient in p.items():
        value = total.get(monomial, Fraction(0)) + coefficient
        if value:
            total[monomial] = value
        else:
            total.pop(monomial, None)


def scale(p: Mapping[Monomial, Fraction], factor) -> Polynomial:
    factor = Fraction(factor)
    return {m: c * factor for m, c in p.items()} if factor else {}


def multiply(p: Mapping[Monomial, Fraction], q: Mapping[Monomial, Fraction]) -> Polynomial:
    result: Polynomial = {}
    for m1, c1 in p.items():
        for m2, c2 in q.items():
            monomial = tuple(a + b for a, b in zip(m1, m2))
            total = result.get(monomial, Fraction(0)) + c1 * c2
            if total:
                result[monomial] = total
            else:
                result.pop(monomial, None)
    return result


def power(p: Polynomial, exponent: int, n: int) -> Polynomial:
    result = constant(1, n)
    for _ in range(exponent):
        result = multiply(result, p)
    return result


def degree(p: Mapping[Monomial, Fraction]) -> int:
    return max((sum(m) for m in p), default=0)


def low_degree(p: Mapping[Monomial, Fraction]) -> int:
    """The smallest total degree of a term (0 for the zero polynomial)."""
    return min((sum(m) for m in p), default=0)


def monomials(n: int, low: int, high: int) -> list[Monomial]:
    """Every exponent vector of n variables with total degree in [low, high], by degree."""
    found: list[Monomial] = []
    for total in range(low, high + 1):
        found += _of_degree(n, total)
    return found


def _of_degree(n: int, total: int) -> list[Monomial]:
    if n == 1:
        return [(total,)]
    return [(first,) + rest for first in range(total, -1, -1)
            for rest in _of_degree(n - 1, total - first)]


def times(m1: Monomial, m2: Monomial) -> Monomial:
    return tuple(a + b for a, b in zip(m1, m2))


def derivative(p: Mapping[Monomial, Fraction], index: int) -> Polynomial:
    result: Polynomial = {}
    for monomial, coefficient in p.items():
        if monomial[index]:
            lowered = monomial[:index] + (monomial[index] - 1,) + monomial[index + 1:]
            result[lowered] = coefficient * monomial[index]
    return result


def lie_derivative(p: Mapping[Monomial, Fraction], field: Sequence[Polynomial]) -> Polynomial:
    """The derivative of p along x' = field(x)."""
    return add(*(multiply(derivative(p, i), f) for i, f in enumerate(field)))


def to_expr(p: Mapping[Monomial, Fraction], states: Sequence[str]) -> E.Expr:
    terms = []
    # by degree, then x0 before x1 (x0^2 + x0*x1 + x1^2)
    for monomial, coefficient in sorted(p.items(), key=lambda item: (-sum(item[0]),
                                                                     [-k for k in item[0]])):
        factors = [E.power(E.Var(s), E.Num(Fraction(k))) if k > 1 else E.Var(s)
                   for s, k in zip(states, monomial) if k]
        terms.append(E.mul(E.Num(coefficient), *factors))
    return E.add(*terms) if terms else E.ZERO


def compose(p: Mapping[Monomial, Fraction], field: Sequence[Polynomial]) -> Polynomial:
    """p(field(x)): the polynomial after one step of x+ = field(x). The components may
    have more variables than there are states (the variables for function values of
    polynomial_field.py); p is then over the states' first ones only."""
    n = next((len(m) for component in field for m in component), len(field))
    images = _images_of(field)
    result: Polynomial = {}
    for monomial, coefficient in p.items():
        accumulate(result, scale(_image(monomial, field, images, n), coefficient))
    return result


# the images of monomials under the last few maps composed with: a program asks for
# B(f(x)) of every basis monomial, for several rates and controllers; without them one
# 4-state barrier program of degree 4 cost 2 s of exact products (probe64/am04)
_IMAGES: dict[tuple, dict[Monomial, Polynomial]] = {}
_IMAGES_KEPT = 8


def _images_of(field: Sequence[Polynomial]) -> dict[Monomial, Polynomial]:
    key = tuple(tuple(sorted(component.items())) for component in field)
    if key not in _IMAGES:
        if len(_IMAGES) >= _IMAGES_KEPT:
            _IMAGES.clear()
        _IMAGES[key] = {}
    return _IMAGES[key]


def _image(monomial: Monomial, field: Sequence[Polynomial], images: dict, n: int) -> Polynomial:
    """The monomial of field(x): x^m(field(x)), from the image of m less one factor."""
    if monomial not in images:
        index = next((i for i, k in enumerate(monomial) if k), None)
        if index is None:
            images[monomial] = constant(1, n)
        else:
            lower = monomial[:index] + (monomial[index] - 1,) + monomial[index + 1:]
            images[monomial] = multiply(_image(lower, field, images, n), field[index])
    return images[monomial]


def change(p: Mapping[Monomial, Fraction], field: Sequence[Polynomial],
           discrete: bool) -> Polynomial:
    """dp/dt along x' = field(x), or p(field(x)) - p(x) for x+ = field(x)."""
    if discrete:
        return add(compose(p, field), scale(p, -1))
    return lie_derivative(p, field)


COMPACT_DEGREE = 2  # expanded only up to this degree (see `compact`)


def compact(expr: E.Expr, states: Sequence[str]) -> E.Expr:
    """`expr` written as a sum of monomials where it is a polynomial of degree at most
    COMPACT_DEGREE with fewer nodes that way (the same function, exactly). A quadratic
    learned as a sum of squared linear forms is checked faster expanded: the interval
    procedure refuted a 4-state swing system's decrease in 0.5 of the boxes, at twice
    the boxes per second (probe46/a03). Higher degrees are left as they are: expanding
    a product of squares loses the structure that keeps intervals tight."""
    if traversal.degree(expr) > COMPACT_DEGREE:
        return expr
    try:
        expanded = to_expr(polynomial(expr, states), states)
    except (NotPolynomial, ZeroDivisionError):
        return expr
    return expanded if traversal.tree_size(expanded) < traversal.tree_size(expr) else expr
