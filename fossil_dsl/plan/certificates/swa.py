"""Stable while avoid: a region-of-attraction certificate V and a barrier B."""
from __future__ import annotations

from fossil_dsl.plan.certificates.barrier import DEFAULT_LAYERS as BARRIER_LAYERS
from fossil_dsl.plan.certificates.barrier import barrier_conditions
from fossil_dsl.plan.certificates.base import Certificate, register
from fossil_dsl.plan.certificates.roa import DEFAULT_LAYERS, ReachingBoundary, \
    inward_conditions, roa_conditions, roa_level


@register
class StableWhileAvoid(ReachingBoundary, Certificate):
    form = "stable while avoid"
    title = "stable-while-avoid certificate (region of attraction V and barrier B)"
    discrete_time = True

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=True),
                self.second_function("B", BARRIER_LAYERS, zero_at_origin=False))

    def conditions(self):
        return roa_conditions(self) + self._barrier()

    def levels(self):
        return (roa_level(self),)

    def variant_conditions(self):
        inward = inward_conditions(self)
        return None if inward is None else inward + roa_conditions(self)[1:] + self._barrier()

    def _barrier(self):
        return barrier_conditions(self, "B", self.role("initial"), self.role("unsafe"), "I",
                                  "U", prefix="barrier_")

