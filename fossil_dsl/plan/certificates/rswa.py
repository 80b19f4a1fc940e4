"""Reach and stay while avoid: reach F without leaving S, then stay in F for ever."""
from __future__ import annotations

from fossil_dsl.plan.certificates.base import (Certificate, Condition, Level, change_of, level_of,
                                          register, value_of)
from fossil_dsl.plan.certificates.rwa import DEFAULT_LAYERS, GAMMA, reach_conditions
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sets import Boundary


@register
class ReachAndStayWhileAvoid(Certificate):
    form = "reach and stay while avoid"
    title = "reach-and-stay-while-avoid certificate (reach-while-avoid and a level β)"
    keeps_equilibrium = False

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=False),)

    def conditions(self):
        V, dV, beta = value_of("V"), change_of("V"), level_of("beta")
        final = self.role("final")
        stay = (
            Condition("stay_boundary", "V(x) > β for every x on the boundary of F",
                      Boundary(final), L.Compare(">", V, beta)),
            Condition("stay_decrease", f"{self.change_word('V')} <= -{GAMMA} for every x "
                      "in F with V(x) >= β", final, L.Compare("<=", dV, E.Num(-GAMMA)),
                      guard=L.Compare(">=", V, beta), escapable_guard=True),
        )
        return reach_conditions(self, self.role("safe"), final, "S", "F") + stay

    def levels(self):
        # β just under V on ∂F: then V must decrease only on a thin band inside F, and
        # the learner may meet stay_decrease elsewhere by pushing V below β
        return (Level("beta", "V", above="stay_boundary",
                      text="β: just below the smallest V on the boundary of F"),)

