"""An expression's interval array on a batch of boxes (vector_intervals.py), node by node,
each node once per batch (a derivative's tree shares its subtrees with its function)."""
from __future__ import annotations

from fossil_dsl.ir import expr as E
from fossil_dsl.solvers import vector_elementary as F
from fossil_dsl.solvers import vector_intervals as V
from fossil_dsl.solvers.api import UnsupportedTheory


def enclose(expr: E.Expr, env, memo: dict):
    """The interval array of expr on the boxes `env` (variable -> interval array);
    `memo` holds the nodes already enclosed (derivatives share subtrees)."""
    found = memo.get(expr)
    if found is None:
        found = memo[expr] = _node(expr, env, memo)
    return found


def _node(expr: E.Expr, env, memo):
    if isinstance(expr, E.Num):
        return V.constant(expr.value)
    if isinstance(expr, E.Var):
        return env[expr.name]
    if isinstance(expr, E.Pi):
        return F.PI
    if isinstance(expr, E.Neg):
        return V.neg(enclose(expr.operand, env, memo))
    if isinstance(expr, E.Add):
        return _fold(expr.terms, V.add, env, memo)
    if isinstance(expr, E.Mul):
        return _fold(expr.factors, V.mul, env, memo)
    if isinstance(expr, E.Div):
        return V.div(enclose(expr.numerator, env, memo), enclose(expr.denominator, env, memo))
    if isinstance(expr, E.Pow):
        exponent = expr.exponent
        if not (isinstance(exponent, E.Num) and exponent.value.denominator == 1):
            raise UnsupportedTheory("a power with a non-integer exponent")
        return V.power(enclose(expr.base, env, memo), int(exponent.value))
    if isinstance(expr, E.Apply) and expr.func in F.FUNCTIONS:
        return F.FUNCTIONS[expr.func](enclose(expr.arg, env, memo))
    raise UnsupportedTheory(f"cannot enclose {type(expr).__name__}")


def _fold(items, combine, env, memo):
    result = enclose(items[0], env, memo)
    for item in items[1:]:
        result = combine(result, enclose(item, env, memo))
    return result
