"""The kernel's rules for difference equations, x(k+1) = f(x(k)), beyond stability and
safety (rules.py has those). docs/certificates.md, "Discrete time", has the argument
for each.

What a step changes: a trajectory is a sequence of points, not a curve, so it can jump
over a set's boundary without ever lying on it. Every rule therefore proves where each
step lands (f(x) ∈ D, f(x) ∈ S, f(x) ∈ F) wherever the argument keeps a trajectory
inside a set, instead of the boundary conditions of continuous time; and reaching a set
rests on a decrease by the fixed amount γ per step, on a bounded set where V is bounded
below.
"""
from __future__ import annotations

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel.obligations import GAMMA, Facts
from fossil_dsl.kernel.registry import rule
from fossil_dsl.kernel.rules import (DISCRETE, barrier_conditions, compare,
                                     region_of_attraction, stable_while_avoid)

ROA_GUARANTEE = (
    "every trajectory from I stays in Ω = {x in D : V(x) <= β} and converges to the "
    "origin: V <= β on I, every step from Ω lands in D, and V is positive and strictly "
    "decreasing at every step on Ω away from the origin (V(0) = 0), so every step from Ω "
    "lands in Ω")


# the continuous rules' functions: in discrete time they prove f(x) ∈ D on Ω, and B's
# invariance, instead of V > β on ∂D and dB/dt < 0 where B = 0
rule("region of attraction", DISCRETE, guarantee=ROA_GUARANTEE)(region_of_attraction)
rule("stable while avoid", DISCRETE, guarantee=ROA_GUARANTEE + (
    "; and those trajectories never enter U: B <= 0 on I, B > 0 on U within D, and every "
    "step from a point of D with B <= 0 lands where B <= 0 (the trajectories stay in "
    "Ω, inside D)"))(stable_while_avoid)


def reach_guarantee(safe_words: str, goal_words: str) -> str:
    return (f"every trajectory from I reaches {goal_words} within finitely many steps and "
            f"stays in {safe_words} until then: V <= 0 on I, and every step from a point "
            f"of {safe_words} outside {goal_words} with V <= 0 lands in {safe_words} with "
            f"V lower by at least {GAMMA} ({safe_words} is bounded, so V is bounded below "
            "on it and cannot decrease for ever)")


def reach_steps(facts: Facts, outside_goal: L.Formula, goal_words: str) -> None:
    """V <= 0 on I ⊆ S; from S ∩ {V <= 0} outside the goal, each step lands in S and
    lowers V by γ; S bounded and V defined on its closure (so bounded below there)."""
    V, dV = facts.value("V"), facts.change("V")
    safe = facts.role("safe")
    initial = facts.member(facts.role("initial"))
    facts.bounded("safe", "the safe set S", safe)
    facts.inside("relation:initial in safe", "I lies in S", initial, facts.member(safe))
    facts.defined("V on the closure of S", facts.closure(safe), [V])
    facts.holds("condition:initial", "V(x) <= 0 on I", initial, compare("<=", V))
    region = L.conjunction(facts.member(safe), compare("<=", V), outside_goal)
    facts.holds("condition:decrease", f"V(f(x)) - V(x) <= -{GAMMA} for x in S outside "
                f"{goal_words} with V(x) <= 0", region, compare("<=", dV, E.Num(-GAMMA)))
    facts.lands_in("condition:image", f"f(x) lies in S for x in S outside {goal_words} "
                   "with V(x) <= 0", region, safe)


@rule("reach while avoid", DISCRETE, guarantee=reach_guarantee("S", "G"))
def reach(facts: Facts) -> None:
    reach_steps(facts, L.negation(facts.member(facts.role("goal"))), "G")


# reach: the checker makes the safe set the domain
rule("reach", DISCRETE, guarantee=reach_guarantee("D", "G"))(reach)


@rule("reach and stay while avoid", DISCRETE, guarantee=(
    "every trajectory from I stays in S until it reaches A = F ∩ {V <= β}, which it does "
    "within finitely many steps, and then stays in A, inside F, for ever: V <= 0 on I; "
    "every step from a point of S outside A with V <= 0 lands in S with V lower by at "
    f"least {GAMMA} (S is bounded, so V is bounded below on it); every step from A lands "
    "in F with V <= β, that is in A"))
def reach_and_stay(facts: Facts) -> None:
    V, dV, beta = facts.value("V"), facts.change("V"), facts.level("beta")
    final = facts.role("final")
    in_a = L.conjunction(facts.member(final), compare("<=", V, beta))
    reach_steps(facts, L.negation(in_a), "A = F ∩ {V <= β}")
    facts.disjoint("relation:final and unsafe", "F and U are disjoint", facts.member(final),
                   facts.member(facts.role("unsafe")))
    facts.lands_in("condition:stay_image", "f(x) lies in F for x in F with V(x) <= β", in_a,
                   final)
    facts.holds("condition:stay_level", "V(f(x)) <= β for x in F with V(x) <= β", in_a,
                compare("<=", E.add(V, dV), beta))


@rule("reach-avoid-remain", DISCRETE, guarantee=reach_guarantee("S", "G") + (
    "; from then on it stays in R = {x in D : B(x) <= 0}, inside F, for ever: G lies in D "
    "and B <= 0 on G, B > 0 on D \\ F, and every step from R lands in D with B <= 0"))
def reach_avoid_remain(facts: Facts) -> None:
    goal_set, final = facts.role("goal"), facts.member(facts.role("final"))
    goal, domain = facts.member(goal_set), facts.spec.domain
    reach_steps(facts, L.negation(goal), "G")
    facts.inside("relation:goal in domain", "G lies in D", goal, facts.member(domain))
    facts.disjoint("relation:final and unsafe", "F and U are disjoint", final,
                   facts.member(facts.role("unsafe")))
    barrier_conditions(facts, "B", goal, L.negation(final), "G", "D \\ F", prefix="barrier_")
    facts.lands_in("condition:barrier_image", "f(x) lies in D for x in D with B(x) <= 0",
                   L.conjunction(facts.member(domain), compare("<=", facts.value("B"))),
                   domain)
