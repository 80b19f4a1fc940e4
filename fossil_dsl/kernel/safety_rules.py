"""The kernel's rules for safety (`from I: always not U`): the barrier rule of
docs/certificates.md in both time domains, its strengthening to "never leaves D", and a
variant for continuous time in which B never increases in D (Prajna and Jadbabaie's
condition: what a conserved quantity meets, where no B can strictly decrease on its zero
level set; the argument is in docs/certificates.md).
"""
from __future__ import annotations

from fossil_dsl.ir import logic as L
from fossil_dsl.kernel.obligations import Facts
from fossil_dsl.kernel.registry import Strengthening, rule, strengthening, variant_rule
from fossil_dsl.kernel.rules import CONTINUOUS, DISCRETE, barrier_conditions, barrier_signs, \
    compare


def safety_guarantee(discrete: bool) -> str:
    return ("trajectories from I never enter U while they remain in D: B <= 0 on I, "
            "B > 0 on U, and the zero level set of B cannot be crossed outwards "
            + ("(the set {B <= 0} is mapped into itself)" if discrete
               else "(B strictly decreases wherever B = 0)"))


def safety_relations(facts: Facts) -> tuple[L.Formula, L.Formula]:
    """I lies in D, I and U are disjoint; (I, U) as formulas."""
    initial, unsafe = facts.member(facts.role("initial")), facts.member(facts.role("unsafe"))
    facts.inside("relation:initial in domain", "I lies in D", initial,
                 facts.member(facts.spec.domain))
    facts.disjoint("relation:initial and unsafe", "I and U are disjoint", initial, unsafe)
    return initial, unsafe


@rule("safety", CONTINUOUS, DISCRETE, guarantee=safety_guarantee)
def safety(facts: Facts) -> None:
    initial, unsafe = safety_relations(facts)
    barrier_conditions(facts, "B", initial, unsafe, "I", "U")


UNCONDITIONAL_SAFETY = (
    "trajectories from I never enter U, and never leave D: B <= 0 on I, B > 0 on U within "
    "D, the zero level set of B cannot be crossed outwards in D {how}, and {exit}")


@strengthening("safety", CONTINUOUS, name="never leaves D", guarantee= UNCONDITIONAL_SAFETY.format(
    how="(B strictly decreases wherever B = 0)",
    exit="B > 0 on the boundary of D, so a trajectory would have to cross B = 0 in D "
         "before it could leave D"))
def safety_on_the_boundary(facts: Facts) -> None:
    facts.holds("strong:boundary", "B(x) > 0 on the boundary of D",
                facts.boundary(facts.spec.domain), compare(">", facts.value("B")))


@strengthening("safety", DISCRETE, name="never leaves D", guarantee= UNCONDITIONAL_SAFETY.format(
    how="(the set {B <= 0} is mapped into itself)",
    exit="every x in D with B(x) <= 0 is mapped into D, so no step leaves D"))
def safety_steps_stay_in_domain(facts: Facts) -> None:
    domain = facts.spec.domain
    facts.lands_in("strong:image", "f(x) lies in D for every x in D with B(x) <= 0",
                   L.conjunction(facts.member(domain), compare("<=", facts.value("B"))), domain)


NON_INCREASING = "non-increasing B"
NON_INCREASING_GUARANTEE = (
    "trajectories from I never enter U while they remain in D: B <= 0 on I, B > 0 on U, "
    "and dB/dt <= 0 throughout D, so B never increases along a trajectory in D and stays "
    "<= 0")
UNCONDITIONAL_NON_INCREASING = (
    "trajectories from I never enter U, and never leave D: B <= 0 on I, B > 0 on U within "
    "D, dB/dt <= 0 throughout D, so B stays <= 0 while the trajectory is in D, and B > 0 on "
    "the boundary of D, which a trajectory would have to reach before it could leave D")


def safety_non_increasing(facts: Facts) -> None:
    initial, unsafe = safety_relations(facts)
    barrier_signs(facts, "B", initial, unsafe, "I", "U")
    facts.holds("condition:non-increasing", "dB/dt <= 0 for x in D",
                facts.member(facts.spec.domain), compare("<=", facts.change("B")))


variant_rule("safety", CONTINUOUS, name=NON_INCREASING, guarantee=NON_INCREASING_GUARANTEE,
             strengthenings=(Strengthening("never leaves D", safety_on_the_boundary,
                                           UNCONDITIONAL_NON_INCREASING),))(
    safety_non_increasing)
