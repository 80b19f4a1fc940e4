"""Verifier-only runs: every function of the certificate is given (`candidate:`) and there
is no controller, so nothing is trained. The levels are chosen from samples drawn with
numpy, and torch is never imported."""
from __future__ import annotations

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.levels import initial_samples, level_value
from fossil_dsl.plan.compile import Plan


def verifier_only(plan: Plan) -> bool:
    return (plan.controller is None and not plan.options.learn_only
            and all(f.candidate is not None for f in plan.functions))


class GivenFunctions:
    """Stands in for the learner of the loop when there is nothing to learn."""

    controller = None
    trainable = False

    def __init__(self, plan: Plan):
        self.plan = plan
        self.networks: dict = {}
        self.digits = plan.options.digits
        self.candidates = {f.name: f.candidate for f in plan.functions}
        self.samples = initial_samples(plan, np.random.default_rng(plan.options.seed))
        self.fixed_levels = {}  # name -> value a found candidate was made for

    def levels(self) -> dict[str, float]:
        return {level.name: self._level(level) for level in self.plan.levels}

    def _level(self, level) -> float:
        if level.name in self.fixed_levels:
            return float(self.fixed_levels[level.name])
        return float(level_value(self.values(level.function, level.above),
                                 self.values(level.function, level.below),
                                 self.plan.options.margin))

    def values(self, function: str, condition: str | None) -> np.ndarray | None:
        if condition is None:
            return None
        points = self.samples[condition]
        value = evaluate(self.candidates[function], state_env(self.plan.states, points))
        return np.broadcast_to(np.asarray(value, dtype=np.float64), (len(points),))
