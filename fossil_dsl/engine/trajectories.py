"""Vector fields and maps as numbers, and a step of RK4: for simulated labels (engine) and
for pictures and estimates (outputs). Nothing here proves anything."""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.ir import expr as E

Field = Callable[[np.ndarray], np.ndarray]


def numeric_field(dynamics: Sequence[E.Expr], states: Sequence[str]) -> Field:
    """The right-hand sides on points of shape [N, n] (NaN or inf where undefined)."""
    def at(points: np.ndarray) -> np.ndarray:
        env = state_env(states, points)
        with np.errstate(all="ignore"):  # paths that blow up are cut or counted as such
            return np.stack([column(evaluate(f, env), len(points)) for f in dynamics], 1)
    return at


def rk4_step(field: Field, points: np.ndarray, dt: float) -> np.ndarray:
    with np.errstate(all="ignore"):
        k1 = field(points)
        k2 = field(points + dt / 2 * k1)
        k3 = field(points + dt / 2 * k2)
        k4 = field(points + dt * k3)
        return points + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def column(value, count: int) -> np.ndarray:
    """A formula's value on `count` points (a constant formula gives a number)."""
    return np.broadcast_to(np.asarray(value, dtype=np.float64), (count,)).copy()
