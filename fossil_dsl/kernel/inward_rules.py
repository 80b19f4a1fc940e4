"""A variant of the region-of-attraction rule (and of stable while avoid) in continuous
time for a sublevel set that meets the boundary of D, as it must where I touches ∂D (a
ball inscribed in a box). The main rule asks V > β on ∂D; here Ω = {x in the closure of
D : V(x) <= β} may reach ∂D, and at each of its points there the field must point
strictly into D across every comparison of D's description that is at equality. Then
no trajectory leaves Ω (a comparison at equality turns strict at once, V = β falls at
once) and V decreases on the compact Ω to the origin. The argument, in full, is in
docs/certificates.md.
"""
from __future__ import annotations

from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel.obligations import Facts
from fossil_dsl.kernel.registry import Strengthening, variant_rule
from fossil_dsl.kernel.rules import CONTINUOUS, ROA_GUARANTEE, avoiding, ball_refuted, compare, \
    no_ball_left_out, region_of_attraction

INWARD = "field points into D"
INWARD_GUARANTEE = (
    "every trajectory from I stays in Ω = {x in the closure of D : V(x) <= β} and "
    "converges to the origin: V <= β on I; where Ω meets the boundary of D the field "
    "points strictly into D, and where V = β in Ω, V strictly decreases, so Ω cannot be "
    "left; and V is positive and strictly decreasing on Ω away from the origin (V(0) = 0)")
SWA_INWARD_GUARANTEE = INWARD_GUARANTEE + (
    "; and those trajectories never enter U: B <= 0 on I, B > 0 on U, and B strictly "
    "decreases wherever B = 0 in D")


def literals(formula: L.Formula) -> list[L.Compare]:
    """The comparisons of `formula` with its negations moved onto them (D's description
    is then monotone in them: a comparison that turns true cannot take x out of D)."""
    return list(L.comparisons(L.negations_inward(formula)))


def points_inward(facts: Facts) -> None:
    """For each comparison a <= b (or a < b, or the mirror) of D's description: d(b - a)/dt
    > 0 wherever a = b in the closure of D with V(x) <= β."""
    domain = facts.member(facts.spec.domain)
    closure, V = L.closed_outer(domain), facts.value("V")
    within = compare("<=", V, facts.level("beta"))
    seen = []
    for literal in literals(domain):
        low, high = (literal.left, literal.right) if literal.relation in ("<", "<=") \
            else (literal.right, literal.left)
        if (low, high) in seen:
            continue
        seen.append((low, high))
        rate = calculus.change(E.add(high, E.neg(low)), facts.states, facts.field, False)
        at_equality = L.conjunction(compare("<=", low, high), compare(">=", low, high))
        facts.holds(f"condition:inward:{len(seen) - 1}",
                    f"the field points into D where {E.to_text(low)} = {E.to_text(high)} "
                    "in Ω", L.conjunction(closure, at_equality, within), compare(">", rate))


def region_reaching_the_boundary(facts: Facts) -> None:
    region_of_attraction(facts, kept=points_inward)


def stable_while_avoid_reaching_the_boundary(facts: Facts) -> None:
    region_reaching_the_boundary(facts)
    avoiding(facts)


def _ball_strengthenings(guarantee: str) -> tuple[Strengthening, ...]:
    return (Strengthening("no ball left out, directly", ball_refuted, guarantee),
            Strengthening("no ball left out", no_ball_left_out, guarantee))


variant_rule("region of attraction", CONTINUOUS, name=INWARD, guarantee=INWARD_GUARANTEE,
             strengthenings=_ball_strengthenings(INWARD_GUARANTEE))(
    region_reaching_the_boundary)
variant_rule("stable while avoid", CONTINUOUS, name=INWARD, guarantee=SWA_INWARD_GUARANTEE,
             strengthenings=_ball_strengthenings(SWA_INWARD_GUARANTEE))(
    stable_while_avoid_reaching_the_boundary)
