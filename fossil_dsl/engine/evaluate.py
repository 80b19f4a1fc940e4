"""Numeric evaluation of neutral expressions and formulas on torch batches (learning and
sampling only; nothing here proves anything)."""
from __future__ import annotations

import math
from typing import Mapping

import torch

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L

_FUNCTIONS = {"sin": torch.sin, "cos": torch.cos, "tan": torch.tan, "exp": torch.exp,
              "log": torch.log, "sqrt": torch.sqrt, "tanh": torch.tanh, "atan": torch.atan,
              "abs": torch.abs}


def evaluate(expr: E.Expr, env: Mapping[str, torch.Tensor]):
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
        value = evaluate(expr.arg, env)
        value = value if isinstance(value, torch.Tensor) else \
            torch.tensor(value, dtype=torch.float64)
        return _FUNCTIONS[expr.func](value)
    raise TypeError(f"cannot evaluate {expr!r}")


def holds(formula: L.Formula, env: Mapping[str, torch.Tensor], batch: int,
          slack: float = 0.0) -> torch.Tensor:
    """A boolean mask: where the formula holds, comparisons loosened by `slack`."""
    if isinstance(formula, L.Compare):
        left, right = evaluate(formula.left, env), evaluate(formula.right, env)
        difference = torch.as_tensor(left - right).expand(batch)
        if formula.relation in ("<=", "<"):
            return difference <= slack if formula.relation == "<=" else difference < slack
        return difference >= -slack if formula.relation == ">=" else difference > -slack
    if isinstance(formula, L.And):
        return torch.stack([holds(a, env, batch, slack) for a in formula.args]).all(0)
    if isinstance(formula, L.Or):
        return torch.stack([holds(a, env, batch, slack) for a in formula.args]).any(0)
    if isinstance(formula, L.Not):
        return ~holds(formula.arg, env, batch, -slack)
    if isinstance(formula, L.BoolConst):
        return torch.full((batch,), formula.value)
    raise TypeError(f"not a formula: {formula!r}")


def state_env(states, points: torch.Tensor) -> dict[str, torch.Tensor]:
    return {name: points[:, i] for i, name in enumerate(states)}
