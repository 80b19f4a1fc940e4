"""Comparisons with divisions as polynomial comparisons: multiply through denominators
whose sign is proved.

A comparison l ~ r whose sides divide by non-constant expressions is rewritten as
N ~ 0 (or N ~' 0 with ~ reversed), where l - r = N / (D_1 ... D_k) as expressions, each
D_k a denominator (or a denominator's numerator), and the sign of every divisor at any
depth (`guards`, the D_k among them) proved on the box the query's own conjuncts give
its variables (Arb's ball arithmetic on at most SIGN_PIECES pieces of the box: the
count, not a clock, so a check redoes the same proof). Every point of the query lies in
the box, where no divisor is 0, so there l - r and N / prod D_k are the same number and
the rewritten comparison holds exactly where the old one does. Function applications
are kept whole (a division inside sin(x/y) stays there). Comparisons whose divisors'
signs are not proved stay as they are.

Why: the equations of a mechanical system with its mass matrix inverted (a cart-pole,
a two-link arm) divide by 4/3 - m cos(q)^2 / M; a Lyapunov condition over them is a
polynomial in the states, sin q and cos q only after multiplying through.
"""
from __future__ import annotations

from collections import Counter

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.arb_box import starting_box

SIGN_PIECES = 64  # pieces of the box, at most, in a proof of a denominator's sign
MAX_NODES = 20_000  # a comparison whose cleared form is larger is left as it was
FLIPPED = {"<=": ">=", "<": ">", ">=": "<=", ">": "<"}


def has_division(query: L.Formula) -> bool:
    return any(_divides(side) for c in L.comparisons(query) for side in (c.left, c.right))


def cleared(query: L.Formula) -> L.Formula:
    """The query with each comparison over proved denominators multiplied through (see
    the module's text); the query itself where there is nothing to clear."""
    if not has_division(query):
        return query
    signs = _Signs(query)
    return L.map_comparisons(query, lambda c: _cleared_comparison(c, signs))


def fraction(expr: E.Expr) -> tuple[E.Expr, tuple[E.Expr, ...]]:
    """(N, (D_1, ..., D_k)) with expr = N / (D_1 ... D_k) wherever none of its `guards`
    is 0; function applications and non-integer powers are kept whole."""
    if isinstance(expr, E.Neg):
        numerator, factors = fraction(expr.operand)
        return E.neg(numerator), factors
    if isinstance(expr, E.Add):
        return _sum([fraction(term) for term in expr.terms])
    if isinstance(expr, E.Mul):
        parts = [fraction(factor) for factor in expr.factors]
        return E.mul(*(n for n, _ in parts)), tuple(d for _, ds in parts for d in ds)
    if isinstance(expr, E.Div):
        return _quotient(fraction(expr.numerator), fraction(expr.denominator),
                         expr.denominator)
    if isinstance(expr, E.Pow) and _integer(expr.exponent) is not None:
        numerator, factors = fraction(expr.base)
        n = _integer(expr.exponent)
        if n >= 0:
            return E.power(numerator, E.Num(n)), factors * n
        return E.power(E.mul(*factors), E.Num(-n)), (numerator,) * -n
    return expr, ()


def guards(expr: E.Expr):
    """Every expression `fraction` may divide by, at any depth: the numerator of each
    divisor (and of each base raised to a negative power) outside function
    applications. Where none is 0, every division in expr is by a non-zero number, and
    fraction's identity holds; `fraction`'s factors are among them."""
    for node in _outside_applications(expr):
        if isinstance(node, E.Div):  # (a number's sign is read off at once)
            yield fraction(node.denominator)[0]
        elif isinstance(node, E.Pow) and (_integer(node.exponent) or 0) < 0:
            yield fraction(node.base)[0]


def _outside_applications(expr: E.Expr):
    yield expr
    if not isinstance(expr, E.Apply):
        for child in E.children(expr):
            yield from _outside_applications(child)


def _sum(parts) -> tuple[E.Expr, tuple[E.Expr, ...]]:
    """Over the least common multiple of the terms' denominators (as multisets), so
    terms over the same denominator (every equation of an inverted mass matrix) share
    it instead of multiplying it in again."""
    numerators, common = over_common(parts)
    return E.add(*numerators), common


def over_common(parts) -> tuple[list[E.Expr], tuple[E.Expr, ...]]:
    """The numerators of (N_i, factors_i) fractions over their least common denominator,
    and its factors."""
    common = Counter()
    for _, factors in parts:
        common |= Counter(factors)
    numerators = [E.mul(numerator, *(common - Counter(factors)).elements())
                  for numerator, factors in parts]
    return numerators, tuple(common.elements())


def common_denominator(terms, region: L.Formula) -> tuple[list[E.Expr], E.Expr] | None:
    """(N_1, ..., N_k, D) with term_i = N_i / D and D > 0 proved on the box of the
    region's conjuncts; None where a factor's sign is not proved there."""
    numerators, factors = over_common([fraction(term) for term in terms])
    signs = _Signs(region)
    sign = signs.product(factors)
    if sign == 0 or any(signs.of(g) == 0 for term in terms for g in guards(term)):
        return None
    if sign < 0:
        return [E.neg(n) for n in numerators], E.neg(E.mul(*factors))
    return numerators, E.mul(*factors)


def _quotient(top, bottom, denominator: E.Expr):
    (n1, d1), (n2, d2) = top, bottom
    if not E.free_vars(denominator) and isinstance(n2, E.Num) and not d2:
        return E.mul(n1, E.Num(1 / n2.value)), d1
    return E.mul(n1, *d2), d1 + (n2,)


def _integer(exponent: E.Expr) -> int | None:
    if isinstance(exponent, E.Num) and exponent.value.denominator == 1:
        return exponent.value.numerator
    return None


def _divides(expr: E.Expr) -> bool:
    """A division outside function applications, by something with a variable in it."""
    if isinstance(expr, E.Div):
        return bool(E.free_vars(expr.denominator)) or _divides(expr.numerator)
    if isinstance(expr, E.Pow) and (_integer(expr.exponent) or 0) < 0:
        return bool(E.free_vars(expr.base))
    if isinstance(expr, E.Apply):
        return False
    return any(_divides(child) for child in E.children(expr))


def _cleared_comparison(comparison: L.Compare, signs: "_Signs") -> L.Compare:
    if not (_divides(comparison.left) or _divides(comparison.right)):
        return comparison
    difference = E.add(comparison.left, E.neg(comparison.right))
    numerator, factors = fraction(difference)
    sign = signs.product(factors)
    if sign == 0 or any(signs.of(g) == 0 for g in guards(difference)) \
            or sum(1 for _ in E.walk(numerator)) > MAX_NODES:
        return comparison
    relation = comparison.relation if sign > 0 else FLIPPED[comparison.relation]
    return L.Compare(relation, numerator, E.ZERO)


class _Signs:
    """The sign of expressions on the query's box: 1, -1, or 0 where not proved."""

    def __init__(self, query: L.Formula):
        self.names = sorted(L.free_vars(query))
        self.box = starting_box(query, self.names)
        self.found: dict[E.Expr, int] = {}

    def product(self, factors) -> int:
        sign = 1
        for factor in factors:
            sign *= self.of(factor)
        return sign

    def of(self, expr: E.Expr) -> int:
        if expr not in self.found:
            self.found[expr] = self._proved(expr)
        return self.found[expr]

    def _proved(self, expr: E.Expr) -> int:
        if isinstance(expr, E.Num):
            return (expr.value > 0) - (expr.value < 0)
        names, box = (self.names, self.box) if E.free_vars(expr) else ([], [])
        if box is None or any(lo > hi for lo, hi in box) \
                or not E.free_vars(expr) <= set(names):
            return 0
        from fossil_dsl.solvers.arb_backend import refuted_on
        for sign, relation in ((1, "<="), (-1, ">=")):
            if refuted_on(L.Compare(relation, expr, E.ZERO), names, box, SIGN_PIECES):
                return sign
        return 0
