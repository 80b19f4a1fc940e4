"""Barrier certificates: safety (trajectories from I never enter U)."""
from __future__ import annotations

from fossil_dsl.certificates.base import (Certificate, Condition, change_of, level_set,
                                          register, value_of)
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.spec import Layer


@register
class Barrier(Certificate):
    form = "safety"
    title = "barrier certificate"

    def functions(self):
        return (self.first_function("B", (Layer("square", 10),), zero_at_origin=False),)

    def conditions(self):
        B, dB = value_of("B"), change_of("B")
        domain = self.spec.domain
        initial = Condition("initial", "B(x) <= 0 for every x in I", self.role("initial"),
                            L.Compare("<=", B, E.ZERO), samples="initial")
        unsafe = Condition("unsafe", "B(x) > 0 for every x in U", self.role("unsafe"),
                           L.Compare(">", B, E.ZERO), samples="unsafe")
        if self.discrete:
            # B(f(x)) - B(x) <= 0 where B(x) <= 0: the set {B <= 0} is invariant
            flow = Condition("invariance", "B(f(x)) <= 0 for every x in D with B(x) <= 0",
                             domain, L.Compare("<=", E.add(dB, B), E.ZERO),
                             guard=L.Compare("<=", B, E.ZERO), samples="domain")
        else:
            flow = Condition("flow", "dB/dt < 0 for every x in D with B(x) = 0", domain,
                             L.Compare("<", dB, E.ZERO), guard=level_set("B"),
                             samples="domain")
        return initial, unsafe, flow

    def guarantee(self):
        return ("trajectories from I never enter U while they remain in D: B <= 0 on I, "
                "B > 0 on U, and the zero level set of B cannot be crossed outwards "
                + ("(the set {B <= 0} is mapped into itself)" if self.discrete
                   else "(B strictly decreases wherever B = 0)"))
