"""Reach while avoid: from I, reach G without leaving the safe set S."""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.plan.certificates.base import (Certificate, Condition, change_of, register,
                                               value_of)
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sets import Boundary, Difference, SetExpr
from fossil_dsl.ir.spec import Layer

DEFAULT_LAYERS = (Layer("square", 8),)
GAMMA = Fraction(1, 100)  # the decrease rate that forces G to be reached in finite time


def reach_conditions(certificate: Certificate, safe: SetExpr, goal: SetExpr,
                     safe_words: str, goal_words: str, name: str = "V",
                     prefix: str = "") -> tuple[Condition, ...]:
    """V <= 0 on I, V > 0 on ∂S, and dV <= -γ on S \\ G where V <= 0. In discrete
    time, a step can jump over ∂S: instead of V > 0 there, every step from S \\ G
    where V <= 0 lands in S."""
    V, dV = value_of(name), change_of(name)
    change = certificate.change_word(name)
    initial = Condition(f"{prefix}initial", f"{name}(x) <= 0 for every x in I",
                        certificate.role("initial"), L.Compare("<=", V, E.ZERO))
    decrease = Condition(
        f"{prefix}decrease", f"{change} <= -{GAMMA} for every x in {safe_words} outside "
        f"{goal_words} with {name}(x) <= 0", Difference(safe, goal),
        L.Compare("<=", dV, E.Num(-GAMMA)), guard=L.Compare("<=", V, E.ZERO),
        escapable_guard=certificate.discrete)
    if certificate.discrete:
        kept = certificate.lands_in(f"{prefix}image", f"f(x) ∈ {safe_words} for every x in "
                                    f"{safe_words} outside {goal_words} with {name}(x) <= 0",
                                    Difference(safe, goal), safe, L.Compare("<=", V, E.ZERO))
        return initial, kept, decrease
    boundary = Condition(f"{prefix}boundary", f"{name}(x) > 0 for every x on the boundary "
                         f"of {safe_words}", Boundary(safe), L.Compare(">", V, E.ZERO))
    return initial, boundary, decrease


@register
class ReachWhileAvoid(Certificate):
    form = "reach while avoid"
    title = "reach-while-avoid certificate"
    discrete_time = True
    keeps_equilibrium = False

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=False),)

    def conditions(self):
        return reach_conditions(self, self.role("safe"), self.role("goal"), "S", "G")
