"""The closed loop as numbers, for pictures and estimates (nothing here proves
anything): its field, or its map, on a batch of points; a step of RK4; and which points
lie in a certified region {x in D : V(x) <= β}."""
from __future__ import annotations

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.engine.trajectories import Field, column, numeric_field, rk4_step
from fossil_dsl.ir import traversal

__all__ = ["Field", "closed_loop", "column", "in_region", "rk4_step"]


def closed_loop(result) -> Field:
    """The dynamics with the proved controller substituted, on points of shape [N, n]."""
    field = [traversal.substitute(f, dict(result.controller)) for f in result.plan.spec.dynamics]
    return numeric_field(field, result.plan.states)


def in_region(result, points: np.ndarray) -> np.ndarray:
    """Where the points lie in D with V <= β (the region `region: largest` proved)."""
    states = result.plan.states
    env = state_env(states, points)
    values = column(evaluate(result.formulas["V"], env), len(points))
    domain = holds(result.plan.spec.domain.contains_formula(states), env, len(points))
    return np.asarray(domain, dtype=bool) & (values <= float(result.levels["beta"]))
