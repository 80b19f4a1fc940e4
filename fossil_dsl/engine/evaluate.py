"""Numeric evaluation of neutral expressions and formulas on batches of points: torch
tensors when learning, numpy arrays in verifier-only runs (which import no torch).
Nothing here proves anything."""
from __future__ import annotations

import math
import sys
from functools import reduce
from typing import Mapping

import numpy as np

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L

_NUMPY_NAMES = {"atan": "arctan"}  # where numpy's name differs from the language's


def _library(value, env: Mapping):
    """torch or numpy: the library of `value`, or, where it is a plain number, of the
    batch in `env`."""
    if isinstance(value, float):
        value = next(iter(env.values()), value)
    torch = sys.modules.get("torch")  # loaded only by runs that learn
    return torch if torch is not None and isinstance(value, torch.Tensor) else np


def evaluate(expr: E.Expr, env: Mapping):
    if isinstance(expr, E.Num):
        return float(expr.value)
    if isinstance(expr, E.Var):
        return env[expr.name]
    if isinstance(expr, E.Pi):
        return math.pi
    if isinstance(expr, E.Add):
        return sum((evaluate(t, env) for t in expr.terms[1:]), evaluate(expr.terms[0], env))
    if isinstance(expr, E.Mul):
        result = evaluate(expr.factors[0], env)
        for factor in expr.factors[1:]:
            result = result * evaluate(factor, env)
        return result
    if isinstance(expr, E.Neg):
        return -evaluate(expr.operand, env)
    if isinstance(expr, E.Div):
        return evaluate(expr.numerator, env) / evaluate(expr.denominator, env)
    if isinstance(expr, E.Pow):
        return evaluate(expr.base, env) ** evaluate(expr.exponent, env)
    if isinstance(expr, E.Apply):
        return _apply(expr.func, evaluate(expr.arg, env), env)
    raise TypeError(f"cannot evaluate {expr!r}")


def _apply(func: str, value, env: Mapping):
    xp = _library(value, env)
    if xp is np:
        return getattr(np, _NUMPY_NAMES.get(func, func))(np.asarray(value, dtype=np.float64))
    value = value if isinstance(value, xp.Tensor) else xp.tensor(value, dtype=xp.float64)
    return getattr(xp, func)(value)


def holds(formula: L.Formula, env: Mapping, batch: int, slack: float = 0.0):
    """A boolean mask: where the formula holds, comparisons loosened by `slack`."""
    if isinstance(formula, L.Compare):
        difference = _full(evaluate(formula.left, env) - evaluate(formula.right, env), env,
                           batch)
        if formula.relation in ("<=", "<"):
            return difference <= slack if formula.relation == "<=" else difference < slack
        return difference >= -slack if formula.relation == ">=" else difference > -slack
    if isinstance(formula, L.And):
        return reduce(lambda a, b: a & b, (holds(a, env, batch, slack) for a in formula.args))
    if isinstance(formula, L.Or):
        return reduce(lambda a, b: a | b, (holds(a, env, batch, slack) for a in formula.args))
    if isinstance(formula, L.Not):
        return ~holds(formula.arg, env, batch, -slack)
    if isinstance(formula, L.BoolConst):
        return _full(0.0, env, batch) == 0.0 if formula.value else _full(0.0, env, batch) != 0.0
    raise TypeError(f"not a formula: {formula!r}")


def _full(value, env: Mapping, batch: int):
    """`value` (a number or an array of the batch) as an array of the batch."""
    xp = _library(value, env)
    if xp is np:
        return np.broadcast_to(np.asarray(value, dtype=np.float64), (batch,))
    return xp.as_tensor(value, dtype=xp.float64).expand(batch)


def state_env(states, points) -> dict:
    return {name: points[:, i] for i, name in enumerate(states)}
