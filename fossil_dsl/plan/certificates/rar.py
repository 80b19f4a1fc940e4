"""Reach, avoid, remain: reach G without leaving S (V), then remain in F (barrier B)."""
from __future__ import annotations

from fossil_dsl.plan.certificates.barrier import DEFAULT_LAYERS as BARRIER_LAYERS
from fossil_dsl.plan.certificates.barrier import barrier_conditions
from fossil_dsl.plan.certificates.base import Certificate, register, value_of
from fossil_dsl.plan.certificates.rwa import DEFAULT_LAYERS, reach_conditions
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sets import Difference


@register
class ReachAvoidRemain(Certificate):
    form = "reach-avoid-remain"
    title = "reach-avoid-remain certificate (reach-while-avoid V and barrier B)"
    discrete_time = True
    keeps_equilibrium = False

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=False),
                self.second_function("B", BARRIER_LAYERS, zero_at_origin=False))

    def conditions(self):
        outside_final = Difference(self.spec.domain, self.role("final"))
        found = reach_conditions(self, self.role("safe"), self.role("goal"), "S", "G") + \
            barrier_conditions(self, "B", self.role("goal"), outside_final, "G", "D \\ F",
                               prefix="barrier_")
        if not self.discrete:
            return found
        # a step can jump out of D, where {B <= 0} says nothing: it must land in D
        domain = self.spec.domain
        return found + (self.lands_in("barrier_image", "f(x) ∈ D for every x in D with "
                                      "B(x) <= 0", domain, domain,
                                      L.Compare("<=", value_of("B"), E.ZERO)),)
