"""Finding violations without a solver: points near a counterexample, fresh samples, and
points moved along a level set, each kept where a condition fails on it exactly.

A mixin of the Learner: it uses the learner's plan, states, generator, box, conditions,
samples, levels() and environment(); it adds points to `samples` and nothing else.
"""
from __future__ import annotations

import torch

from fossil_dsl.engine.ascent import climb
from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.engine.loss import GUARD_BAND, guard_mask, violation_of
from fossil_dsl.engine.sampling import around, box_scale, sample
from fossil_dsl.plan.certificates.base import Condition, level_set_parts

FRESH_FACTOR = 4  # fresh samples drawn to look for violations, per training sample
FRESH_KEPT = 50  # violating fresh samples added per condition and search, the worst first
# A guard such as B(x) = 0 holds on no random sample, so fresh samples cannot show a
# violation of its condition: the worst of them in the band are moved along the level
# set, uphill on the violation, and kept where they violate within LEVEL_BAND of it.
CLIMB_POINTS = 200
CLIMB_STEPS = 30
CLIMB_STEP = 0.02  # of the box's width, per step and coordinate
LEVEL_BAND = 0.01  # relative, as GUARD_BAND
LOCAL_SEARCH = 2000  # points drawn near a counterexample to find the violations near it


class ViolationSearch:
    def add_counterexample(self, name: str, point) -> None:
        condition = self.conditions[name]
        centre = torch.tensor([list(map(float, point))], dtype=torch.float64)
        scale = box_scale(self.box)
        extra = around(centre, condition.region, self.states,
                       self.plan.options.counterexample_neighbours, 0.02 * scale,
                       self.generator, self.box)
        if len(extra) == 1:  # a set of measure zero (a boundary): weigh the point itself
            extra = extra.repeat(5, 1)
        self.samples[name] = torch.cat([self.samples[name], extra])
        # a counterexample often sits in a thin sliver of violations: look for the rest
        nearby = around(centre, condition.region, self.states, LOCAL_SEARCH, 0.05 * scale,
                        self.generator, self.box)
        self._keep_violators(condition, nearby, self.levels())

    def add_fresh_violators(self) -> bool:
        """Draw fresh samples for every condition and keep those that violate it exactly:
        each is a certain counterexample, found without a solver. Whether any was found."""
        levels = self.levels()
        found = False
        for condition in self.plan.conditions:
            count = FRESH_FACTOR * self.plan.samples[condition.name]
            points = sample(condition.region, self.states, count, self.generator, self.box)
            found = self._keep_violators(condition, points, levels) or found
            if level_set_parts(condition.guard) is not None:
                found = self._climb_level_set(condition, points, levels) or found
        return found

    def _climb_level_set(self, condition: Condition, points: torch.Tensor, levels) -> bool:
        """Move the worst points in the guard's band along its level set, uphill on the
        violation, and keep those that end up violating it."""
        box = condition.region.bounding_box() or self.box
        if box is None or not len(points):
            return False
        env = self.detached_environment(condition, points, levels)
        violation = torch.as_tensor(violation_of(condition.claim, env)).expand(len(points))
        band = guard_mask(condition.guard, env, len(points), GUARD_BAND)
        starts = points[band][violation[band].argsort(descending=True)[:CLIMB_POINTS]]
        left, right = level_set_parts(condition.guard)

        def objective(x):
            env = self.environment(condition, x, levels)
            return violation_of(condition.claim, env), evaluate(left, env) - evaluate(right, env)
        moved = climb(starts, objective, box, CLIMB_STEPS, CLIMB_STEP)
        inside = holds(condition.region.contains_formula(self.states),
                       state_env(self.states, moved), len(moved))
        return self._keep_violators(condition, moved[inside], levels, LEVEL_BAND)

    def _keep_violators(self, condition: Condition, points: torch.Tensor, levels,
                        band: float = 0.0) -> bool:
        """Add to the condition's samples the points (the worst FRESH_KEPT) where its
        guard holds (within `band`, relative) and its claim does not, with no margin.
        Whether there was one."""
        if condition.exclude_origin:
            points = points[points.norm(dim=1) > 1e-6]
        if not len(points):
            return False
        env = self.detached_environment(condition, points, levels)
        violation = torch.as_tensor(violation_of(condition.claim, env),
                                    dtype=torch.float64).expand(len(points))
        bad = (violation > 0) & guard_mask(condition.guard, env, len(points), band)
        if not bad.any():
            return False
        worst = violation[bad].argsort(descending=True)[:FRESH_KEPT]
        self.samples[condition.name] = torch.cat([self.samples[condition.name],
                                                  points[bad][worst]])
        return True

    def detached_environment(self, condition: Condition, points: torch.Tensor, levels) -> dict:
        """The condition's values at the points, for judging, not training."""
        env = self.environment(condition, points.clone().requires_grad_(True), levels)
        return {k: v.detach() if isinstance(v, torch.Tensor) else v for k, v in env.items()}

    def add_region_samples(self, name: str, count: int = 100) -> None:
        """After UNKNOWN: learn more about the whole region the query was about."""
        region = self.conditions[name].region
        extra = sample(region, self.states, count, self.generator, self.box)
        self.samples[name] = torch.cat([self.samples[name], extra])
