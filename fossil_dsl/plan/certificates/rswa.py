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
    discrete_time = True
    keeps_equilibrium = False

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=False),)

    def conditions(self):
        if self.discrete:
            return self._steps()
        V, dV, beta = value_of("V"), change_of("V"), level_of("beta")
        final = self.role("final")
        stay = (
            self._stay_boundary(),
            Condition("stay_decrease", f"{self.change_word('V')} <= -{GAMMA} for every x "
                      "in F with V(x) >= β", final, L.Compare("<=", dV, E.Num(-GAMMA)),
                      guard=L.Compare(">=", V, beta), escapable_guard=True),
        )
        return reach_conditions(self, self.role("safe"), final, "S", "F") + stay

    def _stay_boundary(self, note: str = "") -> Condition:
        return Condition("stay_boundary", f"V(x) > β for every x on the boundary of F{note}",
                         Boundary(self.role("final")), L.Compare(">", value_of("V"),
                                                                 level_of("beta")))

    def _steps(self) -> tuple[Condition, ...]:
        """Discrete time, with A = F ∩ {V <= β}: from S outside A where V <= 0, every
        step lands in S and lowers V by γ; from A, every step lands in A. (V > β on ∂F
        only places β, so that A is a sublevel set inside F: a step can jump over ∂F.)"""
        V, dV, beta = value_of("V"), change_of("V"), level_of("beta")
        safe, final = self.role("safe"), self.role("final")
        in_a = L.conjunction(final.contains_formula(self.spec.states), L.Compare("<=", V, beta))
        outside_a = L.conjunction(L.Compare("<=", V, E.ZERO), L.negation(in_a))
        within = L.Compare("<=", V, beta)
        return (
            Condition("initial", "V(x) <= 0 for every x in I", self.role("initial"),
                      L.Compare("<=", V, E.ZERO)),
            self.lands_in("image", "f(x) ∈ S for every x in S with V(x) <= 0 outside "
                          "A = F ∩ {V <= β}", safe, safe, outside_a),
            Condition("decrease", f"V(f(x)) - V(x) <= -{GAMMA} for every x in S with "
                      "V(x) <= 0 outside A", safe, L.Compare("<=", dV, E.Num(-GAMMA)),
                      guard=outside_a, escapable_guard=True),
            self._stay_boundary(" (it places β; the argument does not use it)"),
            self.lands_in("stay_image", "f(x) ∈ F for every x in F with V(x) <= β", final,
                          final, within),
            Condition("stay_level", "V(f(x)) <= β for every x in F with V(x) <= β", final,
                      L.Compare("<=", E.add(V, dV), beta), guard=within,
                      escapable_guard=True),
        )

    def levels(self):
        # β just under V on ∂F: then V must decrease only on a thin band inside F, and
        # the learner may meet stay_decrease elsewhere by pushing V below β
        return (Level("beta", "V", above="stay_boundary",
                      text="β: just below the smallest V on the boundary of F"),)
