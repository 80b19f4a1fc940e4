"""Barrier certificates: safety (trajectories from I never enter U)."""
from __future__ import annotations

from fossil_dsl.plan.certificates.base import (Certificate, Condition, change_of, level_set,
                                          register, value_of)
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sets import Complement, Difference, Intersection, SetExpr
from fossil_dsl.ir.spec import Layer

DEFAULT_LAYERS = (Layer("square", 10),)


def barrier_conditions(certificate: Certificate, name: str, inside: SetExpr,
                       outside: SetExpr, inside_words: str, outside_words: str,
                       prefix: str = "") -> tuple[Condition, ...]:
    """name <= 0 on `inside`, > 0 on `outside`, and {name <= 0} cannot be left in D."""
    B, dB = value_of(name), change_of(name)
    initial = Condition(f"{prefix}initial", f"{name}(x) <= 0 for every x in {inside_words}",
                        inside, L.Compare("<=", B, E.ZERO))
    domain = certificate.spec.domain
    # only the part of the avoided set inside D matters (the guarantee holds within D),
    # and it is bounded even where the set is not (e.g. {x0 + x1^2 <= 0})
    unsafe = Condition(f"{prefix}unsafe", f"{name}(x) > 0 for every x in {outside_words}",
                       _within(outside, domain), L.Compare(">", B, E.ZERO))
    if certificate.discrete:
        # B(f(x)) - B(x) <= 0 where B(x) <= 0 implies B(f(x)) <= 0: {B <= 0} is invariant
        flow = Condition(f"{prefix}invariance",
                         f"{name}(f(x)) <= 0 for every x in D with {name}(x) <= 0", domain,
                         L.Compare("<=", E.add(dB, B), E.ZERO),
                         guard=L.Compare("<=", B, E.ZERO), escapable_guard=True)
    else:
        flow = Condition(f"{prefix}flow",
                         f"d{name}/dt < 0 for every x in D with {name}(x) = 0", domain,
                         L.Compare("<", dB, E.ZERO), guard=level_set(name))
    return initial, unsafe, flow


def _within(region: SetExpr, domain: SetExpr) -> SetExpr:
    if region is domain or isinstance(region, Complement) or \
            (isinstance(region, Difference) and region.left is domain):
        return region  # already inside the domain
    return Intersection(region, domain)


@register
class Barrier(Certificate):
    form = "safety"
    title = "barrier certificate"
    discrete_time = True
    keeps_equilibrium = False

    def functions(self):
        return (self.first_function("B", DEFAULT_LAYERS, zero_at_origin=False),)

    def conditions(self):
        return barrier_conditions(self, "B", self.role("initial"), self.role("unsafe"),
                                  "I", "U")

    def variant_conditions(self) -> tuple[Condition, ...] | None:
        """The conditions of the kernel's variant rule for continuous time (B never
        increases in D; kernel/safety_rules.py): what a conserved quantity meets."""
        if self.discrete:
            return None
        initial, unsafe, _ = self.conditions()
        flow = Condition("non-increasing", "dB/dt <= 0 for every x in D", self.spec.domain,
                         L.Compare("<=", change_of("B"), E.ZERO))
        return initial, unsafe, flow
