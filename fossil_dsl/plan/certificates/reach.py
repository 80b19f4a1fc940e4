"""Reach: from I, eventually G (reach while avoid with the safe set = the domain)."""
from __future__ import annotations

from fossil_dsl.plan.certificates.base import Certificate, register
from fossil_dsl.plan.certificates.rwa import DEFAULT_LAYERS, reach_conditions


@register
class Reach(Certificate):
    form = "reach"
    title = "reach certificate (reach-while-avoid with S = D)"
    discrete_time = True
    keeps_equilibrium = False

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=False),)

    def conditions(self):
        return reach_conditions(self, self.spec.domain, self.role("goal"), "D", "G")

