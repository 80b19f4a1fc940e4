"""Exact symbolic derivatives of neutral expressions (for Lie derivatives of certificates)."""
from __future__ import annotations

from typing import Mapping, Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import atoms, traversal

TWO = E.Num(2)


def derivative(expr: E.Expr, var: str, memo: dict | None = None) -> E.Expr:
    """d expr / d var. Shared subtrees are differentiated once."""
    return directional(expr, {var: E.ONE}, memo)


def directional(expr: E.Expr, direction: Mapping[str, E.Expr],
                memo: dict | None = None) -> E.Expr:
    """The derivative of expr along `direction` (variable -> its rate; the others
    fixed), the chain rule applied once per distinct subexpression."""
    memo = {} if memo is None else memo
    if expr in memo:
        return memo[expr]
    result = _derivative(expr, direction, memo)
    memo[expr] = result
    return result


def _derivative(expr: E.Expr, direction: Mapping[str, E.Expr], memo: dict) -> E.Expr:
    d = lambda e: directional(e, direction, memo)  # noqa: E731
    if isinstance(expr, E.Var):
        return direction.get(expr.name, E.ZERO)
    if isinstance(expr, (E.Num, E.Pi)):
        return E.ZERO
    if isinstance(expr, E.Add):
        return E.add(*(d(t) for t in expr.terms))
    if isinstance(expr, E.Neg):
        return E.neg(d(expr.operand))
    if isinstance(expr, E.Mul):
        return _product_rule(expr.factors, d)
    if isinstance(expr, E.Div):
        num, den = expr.numerator, expr.denominator
        return E.div(E.add(E.mul(d(num), den), E.neg(E.mul(num, d(den)))), E.power(den, TWO))
    if isinstance(expr, E.Pow):
        return _power_rule(expr, d)
    if isinstance(expr, E.Apply):
        return E.mul(_outer_derivative(expr.func, expr.arg), d(expr.arg))
    raise TypeError(f"cannot differentiate {expr!r}")


def _product_rule(factors, d) -> E.Expr:
    terms = []
    for i, factor in enumerate(factors):
        df = d(factor)
        if df != E.ZERO:
            terms.append(E.mul(*factors[:i], df, *factors[i + 1:]))
    return E.add(*terms) if terms else E.ZERO


def _power_rule(expr: E.Pow, d) -> E.Expr:
    base, exponent = expr.base, expr.exponent
    if not E.free_vars(exponent):
        return E.mul(exponent, E.power(base, E.add(exponent, E.Num(-1))), d(base))
    # a^b = exp(b log a)
    return E.mul(expr, E.add(E.mul(d(exponent), E.apply("log", base)),
                             E.div(E.mul(exponent, d(base)), base)))


def _outer_derivative(func: str, arg: E.Expr) -> E.Expr:
    rules = {
        "sin": lambda: E.apply("cos", arg),
        "cos": lambda: E.neg(E.apply("sin", arg)),
        "tan": lambda: E.add(E.ONE, E.power(E.apply("tan", arg), TWO)),
        "exp": lambda: E.apply("exp", arg),
        "log": lambda: E.div(E.ONE, arg),
        "sqrt": lambda: E.div(E.ONE, E.mul(TWO, E.apply("sqrt", arg))),
        "tanh": lambda: E.add(E.ONE, E.neg(E.power(E.apply("tanh", arg), TWO))),
        "atan": lambda: E.div(E.ONE, E.add(E.ONE, E.power(arg, TWO))),
        # |x|' = x/|x| away from 0; certificates use abs only through relu
        "abs": lambda: E.div(arg, E.apply("abs", arg)),
    }
    return rules[func]()


def gradient(expr: E.Expr, variables: Sequence[str]) -> tuple[E.Expr, ...]:
    return tuple(derivative(expr, v, {}) for v in variables)  # one memo per variable


def lie_derivative(expr: E.Expr, variables: Sequence[str],
                   field: Sequence[E.Expr]) -> E.Expr:
    """∇expr · field: the derivative of expr along the flow of x' = field.

    Two equal forms: the sum of partial derivatives times the field, which copies expr's
    subexpressions once per variable, and the derivative along the field, which copies
    the field once per place a variable occurs. Where expr has functions (a network's
    activations), the one that is smaller written out as a tree is taken: the interval
    procedure evaluates trees (f1_barr3's flow query: 10 911 -> 8 866 nodes, its proof
    12 -> 9 s; row05, whose field holds a controller network, keeps the sum). Polynomial
    expr keep the sum, which their solvers normalise anyway."""
    by_variable = E.add(*(E.mul(g, f) for g, f in zip(gradient(expr, variables), field)))
    if not traversal.has_function(expr):
        return by_variable
    along = directional(expr, dict(zip(variables, field)))
    return along if traversal.tree_size(along) < traversal.tree_size(by_variable) \
        else by_variable


def change(expr: E.Expr, variables: Sequence[str], field: Sequence[E.Expr],
           discrete: bool) -> E.Expr:
    """How expr changes along the dynamics: its Lie derivative for x' = field, or
    expr(field(x)) - expr(x) for x+ = field(x). Where that has functions (sin, tanh, ...)
    and expr is a polynomial, it is expanded over its atoms if that is small: V's large
    terms then cancel exactly (V = x'Px and a step x + h g(x) leave 2h x'P g + h^2 g'P g),
    where an enclosure of the difference of the two large values would have to be narrow
    to see the small one (d21: 4 states with sin, not proved in 300 s before, certified
    in 48 s). Polynomial differences are left as they are: Z3, CVC5 and the
    sum-of-squares search expand them themselves (expanded, d14's search took another
    path, 56 -> 104 s), and so are those of networks with functions, which expanding
    only enlarges (row17's sigmoid barrier: 17 534 -> 21 654 nodes, its invariance proof
    5 -> 24 s)."""
    if not discrete:
        return lie_derivative(expr, variables, field)
    difference = E.add(compose(expr, variables, field), E.neg(expr))
    if traversal.has_function(expr) or not traversal.has_function(difference):
        return difference
    expansion = atoms.expanded(difference, variables)
    return difference if expansion is None else expansion


def compose(expr: E.Expr, variables: Sequence[str], images: Sequence[E.Expr]) -> E.Expr:
    """expr with each variable replaced by its image: V(f(x))."""
    mapping: Mapping[str, E.Expr] = dict(zip(variables, images))
    return traversal.substitute(expr, mapping)
