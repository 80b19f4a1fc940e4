"""Rewriting and measuring expression trees."""
from __future__ import annotations

from typing import Iterable, Mapping

from fossil_dsl.ir.expr import (Add, Apply, Div, Expr, Mul, Neg, Num, Pi, Pow, Var, add,
                                apply, children, div, free_vars, mul, neg, power, walk)
from fossil_dsl.ir.functions import FUNCTIONS


def substitute(expr: Expr, mapping: Mapping[str, Expr]) -> Expr:
    """Replace variables by expressions, folding constants on the way up."""
    if isinstance(expr, Var):
        return mapping.get(expr.name, expr)
    if isinstance(expr, (Num, Pi)):
        return expr
    return rebuild(expr, tuple(substitute(child, mapping) for child in children(expr)))


def rebuild(expr: Expr, new_children: tuple[Expr, ...]) -> Expr:
    """The same node over new children, through the folding constructors."""
    if isinstance(expr, Add):
        return add(*new_children)
    if isinstance(expr, Mul):
        return mul(*new_children)
    if isinstance(expr, Div):
        return div(*new_children)
    if isinstance(expr, Pow):
        return power(*new_children)
    if isinstance(expr, Neg):
        return neg(new_children[0])
    if isinstance(expr, Apply):
        return apply(expr.func, new_children[0])
    return expr


def degree(expr: Expr) -> int:
    """An upper bound on the polynomial degree (a function of a state counts as 1)."""
    if not free_vars(expr):
        return 0
    if isinstance(expr, Var):
        return 1
    if isinstance(expr, Add):
        return max(map(degree, expr.terms))
    if isinstance(expr, Mul):
        return sum(map(degree, expr.factors))
    if isinstance(expr, Div):
        return degree(expr.numerator) + degree(expr.denominator)
    if isinstance(expr, Neg):
        return degree(expr.operand)
    if isinstance(expr, Pow) and isinstance(expr.exponent, Num):
        return degree(expr.base) * abs(int(expr.exponent.value))
    if isinstance(expr, Apply) and FUNCTIONS[expr.func].piecewise_linear:
        return degree(expr.arg)  # solvers encode abs(p) with p itself
    return 1


def is_polynomial(expr: Expr) -> bool:
    """+, -, * and non-negative integer powers only, over rational constants."""
    for node in walk(expr):
        if isinstance(node, (Apply, Pi, Div)):
            return False
        if isinstance(node, Pow) and not _natural_exponent(node.exponent):
            return False
    return True


def is_affine(expr: Expr) -> bool:
    """A polynomial of degree at most 1."""
    return is_polynomial(expr) and degree(expr) <= 1


def is_arithmetic(expr: Expr) -> bool:
    """Decidable by nonlinear real arithmetic: polynomials, division, integer powers, abs."""
    for node in walk(expr):
        if isinstance(node, Pi):
            return False
        if isinstance(node, Apply) and not FUNCTIONS[node.func].piecewise_linear:
            return False
        if isinstance(node, Pow) and not (isinstance(node.exponent, Num)
                                          and node.exponent.value.denominator == 1):
            return False
    return True


def _natural_exponent(exponent: Expr) -> bool:
    return isinstance(exponent, Num) and exponent.value.denominator == 1 \
        and exponent.value >= 0


def distinct_nodes(expr: Expr):
    """Every distinct subexpression once (a shared one is not visited again)."""
    seen, stack = set(), [expr]
    while stack:
        node = stack.pop()
        if node not in seen:
            seen.add(node)
            yield node
            stack.extend(children(node))


def has_function(expr: Expr) -> bool:
    return any(isinstance(node, Apply) for node in distinct_nodes(expr))


def children_first(roots: Iterable[Expr]) -> list[Expr]:
    """The distinct subexpressions of the roots, each after its children."""
    order, seen = [], set()
    for root in roots:
        stack = [(root, False)]
        while stack:
            node, expanded = stack.pop()
            if expanded:
                order.append(node)
            elif node not in seen:
                seen.add(node)
                stack.append((node, True))
                stack.extend((child, False) for child in children(node))
    return order


def tree_size(expr: Expr) -> int:
    """How many nodes the expression has written out as a tree (a subexpression counts
    once per occurrence): what an evaluator without shared results works through."""
    sizes: dict[Expr, int] = {}
    for node in children_first([expr]):
        sizes[node] = 1 + sum(sizes[child] for child in children(node))
    return sizes[expr]
