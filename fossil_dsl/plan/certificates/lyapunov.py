"""Lyapunov functions: stability of the origin on the domain."""
from __future__ import annotations

from fossil_dsl.plan.certificates.base import Certificate, Condition, change_of, register, value_of
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.spec import Layer


@register
class Lyapunov(Certificate):
    form = "stability"
    title = "Lyapunov function"
    discrete_time = True

    def functions(self):
        return (self.first_function("V", (Layer("square", 8),), zero_at_origin=True),)

    def conditions(self):
        domain = self.spec.domain
        return (
            Condition("positive", "V(x) > 0 for every x in D, x ≠ 0", domain,
                      L.Compare(">", value_of("V"), E.ZERO), exclude_origin=True,
                      scaled_margin=True),
            Condition("decrease", f"{self.change_word('V')} < 0 for every x in D, x ≠ 0",
                      domain, L.Compare("<", change_of("V"), E.ZERO), exclude_origin=True,
                      scaled_margin=True),
        )

