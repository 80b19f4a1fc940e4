"""The closed loop as numbers, for pictures and estimates (nothing here proves
anything): its field, or its map, on a batch of points; a step of RK4; and which points
lie in a certified region {x in D : V(x) <= β}."""
from __future__ import annotations

from typing import Callable

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.ir import traversal

Field = Callable[[np.ndarray], np.ndarray]


def closed_loop(result) -> Field:
    """The dynamics with the proved controller substituted, on points of shape [N, n]."""
    field = [traversal.substitute(f, dict(result.controller)) for f in result.plan.spec.dynamics]
    states = result.plan.states

    def at(points: np.ndarray) -> np.ndarray:
        env = state_env(states, points)
        with np.errstate(all="ignore"):  # paths that blow up are cut or counted as such
            return np.stack([column(evaluate(f, env), len(points)) for f in field], 1)
    return at


def rk4_step(field: Field, points: np.ndarray, dt: float) -> np.ndarray:
    with np.errstate(all="ignore"):
        k1 = field(points)
        k2 = field(points + dt / 2 * k1)
        k3 = field(points + dt / 2 * k2)
        k4 = field(points + dt * k3)
        return points + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def in_region(result, points: np.ndarray) -> np.ndarray:
    """Where the points lie in D with V <= β (the region `region: largest` proved)."""
    states = result.plan.states
    env = state_env(states, points)
    values = column(evaluate(result.formulas["V"], env), len(points))
    domain = holds(result.plan.spec.domain.contains_formula(states), env, len(points))
    return np.asarray(domain, dtype=bool) & (values <= float(result.levels["beta"]))


def column(value, count: int) -> np.ndarray:
    """A formula's value on `count` points (a constant formula gives a number)."""
    return np.broadcast_to(np.asarray(value, dtype=np.float64), (count,)).copy()
