"""The kernel's rule per property form and time domain (docs/certificates.md has the
argument for each). A rule lists every obligation: the conditions on the functions and
the side facts the argument uses. Definedness of what a condition evaluates is added
by `Facts.never` itself.
"""
from __future__ import annotations

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.kernel.local import negative_near_origin
from fossil_dsl.kernel.obligations import BALL_ROOM, GAMMA, Claim, Facts, Obligation
from fossil_dsl.kernel.prove import SUM_OF_SQUARES
from fossil_dsl.kernel.registry import rule, strengthening

CONTINUOUS, DISCRETE = TimeDomain.CONTINUOUS, TimeDomain.DISCRETE
ZERO = E.ZERO


def compare(relation: str, left: E.Expr, right: E.Expr = ZERO) -> L.Formula:
    return L.Compare(relation, left, right)


def nonzero(value: E.Expr) -> L.Formula:
    return L.disjunction(compare("<", value), compare(">", value))


# ---- stable-type side facts ------------------------------------------------------
def equilibrium(facts: Facts, function: str) -> None:
    """f(0) = 0 for the closed loop, and V(0) = 0."""
    origin = {s: ZERO for s in facts.states}
    named = [(f"f{i}(0) = 0 (the origin is an equilibrium)", f"equilibrium:{s}", f)
             for i, (s, f) in enumerate(zip(facts.states, facts.field))]
    named.append((f"{function}(0) = 0", f"origin:{function}", facts.value(function)))
    for text, name, expression in named:
        try:
            query = nonzero(traversal.substitute(expression, origin))
        except E.ExprError as exc:  # undefined at the origin: the fact fails
            text, query = f"{text}; but it is undefined there ({exc})", L.TRUE
        facts.obligations.append(Obligation(name, text, query))


def neighbourhood(facts: Facts) -> None:
    """The origin is an interior point of D; with an excluded ball of radius r, the
    ball of radius BALL_ROOM * r lies in D (the ball is small next to the domain)."""
    domain = facts.member(facts.spec.domain)
    at_origin = L.substitute(L.open_inner(domain), {s: ZERO for s in facts.states})
    facts.obligations.append(Obligation(
        "neighbourhood", "the origin is an interior point of D (D contains a "
        "neighbourhood of it)", L.negation(at_origin)))
    if facts.r > 0:
        radius = BALL_ROOM * facts.r
        facts.inside("ball:room", f"the ball |x| <= {radius} ({BALL_ROOM} times the "
                     "excluded ball) lies in D", facts.ball(radius), domain)
    if facts.r > 0 and facts.discrete:
        # a step can land in the ball the conditions left out: either the Taylor lemma
        # covers the ball (V > 0 and V decreasing there too), or the ball is mapped
        # into itself (the ε-stability argument)
        facts.ball_covered = no_ball_left_out(facts)
        if not facts.ball_covered:
            image = E.add(*(E.power(f, E.Num(2)) for f in facts.field))
            facts.never("ball:image", f"the map sends the excluded ball |x| <= {facts.r} "
                        "into itself", facts.ball(facts.r),
                        compare(">", image, E.Num(facts.r ** 2)))


def away_words(facts: Facts) -> str:
    return f"|x| > {facts.r}" if facts.r > 0 else "x ≠ 0"


def lyapunov_conditions(facts: Facts, region: L.Formula, words: str) -> None:
    V, dV = facts.value("V"), facts.change("V")
    away = L.conjunction(region, facts.away_from_origin())
    change = "V(f(x)) - V(x)" if facts.discrete else "dV/dt"
    facts.holds("condition:positive", f"V(x) > 0 for x in {words}, {away_words(facts)}",
                away, compare(">", V))
    facts.holds("condition:decrease", f"{change} < 0 for x in {words}, {away_words(facts)}",
                away, compare("<", dV))


def stability_guarantee(discrete: bool) -> str:
    step = "every step" if discrete else "along every trajectory"
    return ("the origin is asymptotically stable: V is positive away from the origin "
            f"and strictly decreases {step} in the domain, so trajectories that remain in "
            "the domain converge to the origin (V(0) = 0)")


def no_ball_left_out(facts: Facts) -> bool:
    """V > 0 and V decreasing also inside the excluded ball (but at 0), from the Taylor
    expansions there (kernel/local.py): the ε of ε-stability goes."""
    V = facts.value("V")
    return facts.r > 0 and negative_near_origin(facts, "positive", E.neg(V), "-V") \
        and negative_near_origin(facts, "decrease", facts.change("V"), "the change of V")


def ball_refuted(facts: Facts) -> bool:
    """V > 0 and V decreasing on the excluded ball too (but at 0), as two obligations
    on the punctured ball itself: a refutation of their polynomial form (kernel/prove.py)
    proves them where the lemma's third-derivative bounds take minutes (6 states, sin)."""
    if facts.r <= 0:
        return False
    punctured = L.conjunction(facts.ball(facts.r),
                              L.Compare(">", facts.squared_norm(), E.ZERO))
    words = f"0 < |x| <= {facts.r}"
    change = "V(f(x)) - V(x)" if facts.discrete else "dV/dt"
    facts.never("ball:positive", f"V(x) > 0 for {words}", punctured,
                L.negation(compare(">", facts.value("V"))), SUM_OF_SQUARES, True)
    facts.never("ball:decrease", f"{change} < 0 for {words}", punctured,
                L.negation(compare("<", facts.change("V"))), SUM_OF_SQUARES, True)
    return True


def ball_strengthenings(form: str, guarantee) -> None:
    """The ball round the origin proved directly, else by the Taylor lemma."""
    for name, add in (("no ball left out, directly", ball_refuted),
                      ("no ball left out", no_ball_left_out)):
        strengthening(form, CONTINUOUS, name=name, guarantee=guarantee)(add)


ROA_GUARANTEE = (
    "every trajectory from I stays in Ω = {x in D : V(x) <= β} and converges to the "
    "origin: V <= β on I and V > β on the boundary of D, so Ω cannot be left, and V is "
    "positive and strictly decreasing on Ω away from the origin (V(0) = 0)")


def reach_guarantee(safe_words: str, goal_words: str) -> str:
    return (f"every trajectory from I reaches {goal_words} in finite time and stays in "
            f"{safe_words} until then: V <= 0 on I, V > 0 on the boundary of {safe_words}, "
            f"and V decreases at rate at least {GAMMA} wherever V <= 0 in {safe_words} "
            f"outside {goal_words} ({safe_words} is bounded, so V cannot decrease forever)")


@rule("stability", CONTINUOUS, DISCRETE, guarantee=stability_guarantee)
def stability(facts: Facts) -> None:
    equilibrium(facts, "V")
    neighbourhood(facts)
    # on the closure: a trajectory that remains in D has its limit points there
    lyapunov_conditions(facts, facts.closure(facts.spec.domain), "the closure of D")


# (in discrete time the rule itself uses the lemma where it applies: see neighbourhood)
ball_strengthenings("stability", stability_guarantee)


def stable_sublevel_set(facts: Facts, kept=None) -> None:
    """Ω = {x in D : V(x) <= β} cannot be left, and V is a strict Lyapunov function on
    it: every trajectory from Ω converges to the origin, and the origin is stable.
    `kept` (continuous time) adds the obligations that keep Ω in place of V > β on ∂D
    (inward_rules.py)."""
    equilibrium(facts, "V")
    neighbourhood(facts)
    V, beta = facts.value("V"), facts.level("beta")
    domain = facts.spec.domain
    if facts.discrete:  # a step can jump over ∂D: it must land in D (step_rules.py)
        facts.lands_in("condition:image", "f(x) lies in D for every x in D with V(x) <= β",
                       L.conjunction(facts.member(domain), compare("<=", V, beta)), domain)
    elif kept is not None:
        kept(facts)
    else:
        facts.holds("condition:boundary", "V(x) > β on the boundary of D",
                    facts.boundary(domain), compare(">", V, beta))
    # on the closure: the limit points of a trajectory in Ω lie there
    omega = L.conjunction(facts.closure(domain), compare("<=", V, beta))
    lyapunov_conditions(facts, omega, "Ω = {x in D : V(x) <= β}")
    # with V(0) = 0 < β and V continuous, Ω holds a neighbourhood of the origin
    facts.obligations.append(Obligation("level:beta", "β > 0", compare("<=", beta)))
    if facts.r > 0:
        facts.holds("ball:sublevel", f"V(x) < β on the excluded ball |x| <= {facts.r}, "
                    "so no trajectory leaves Ω from it", facts.ball(facts.r),
                    compare("<", V, beta))


def region_of_attraction(facts: Facts, kept=None) -> None:
    stable_sublevel_set(facts, kept)
    V, beta = facts.value("V"), facts.level("beta")
    initial = facts.role("initial")
    facts.inside("relation:initial in domain", "I lies in D", facts.member(initial),
                 facts.member(facts.spec.domain))
    facts.holds("condition:initial", "V(x) <= β on I", facts.member(initial),
                compare("<=", V, beta))


def largest_region_guarantee(discrete: bool) -> str:
    kept = ("every step from Ω lands in D, and V decreases at every step"
            if discrete else "V > β on the boundary of D, so Ω cannot be left, and V "
            "strictly decreases along every trajectory")
    return ("the origin is asymptotically stable and Ω = {x in D : V(x) <= β} lies in its "
            f"region of attraction: every trajectory from Ω stays in Ω and converges to "
            f"the origin, since {kept} on Ω away from the origin, where V is positive "
            "(V(0) = 0 < β)")


# `prove stable` with `region: largest`: the region is the result, there is no I
rule("largest region of attraction", CONTINUOUS, DISCRETE,
     guarantee=largest_region_guarantee)(stable_sublevel_set)
ball_strengthenings("largest region of attraction", largest_region_guarantee)


rule("region of attraction", guarantee=ROA_GUARANTEE)(region_of_attraction)
ball_strengthenings("region of attraction", ROA_GUARANTEE)


def barrier_signs(facts: Facts, name: str, inside: L.Formula, outside: L.Formula,
                  inside_words: str, outside_words: str, prefix: str = "") -> None:
    """name <= 0 on `inside`, > 0 on `outside` within D."""
    B = facts.value(name)
    facts.holds(f"condition:{prefix}initial", f"{name}(x) <= 0 on {inside_words}", inside,
                compare("<=", B))
    facts.holds(f"condition:{prefix}unsafe", f"{name}(x) > 0 on {outside_words} within D",
                L.conjunction(outside, facts.member(facts.spec.domain)), compare(">", B))


def barrier_conditions(facts: Facts, name: str, inside: L.Formula, outside: L.Formula,
                       inside_words: str, outside_words: str, prefix: str = "") -> None:
    barrier_signs(facts, name, inside, outside, inside_words, outside_words, prefix)
    B, dB = facts.value(name), facts.change(name)
    domain = facts.member(facts.spec.domain)
    if facts.discrete:
        facts.holds(f"condition:{prefix}invariance", f"{name}(f(x)) <= 0 for x in D with "
                    f"{name}(x) <= 0", L.conjunction(domain, compare("<=", B)),
                    compare("<=", E.add(dB, B)))
    else:
        level = L.conjunction(domain, compare("<=", B), compare(">=", B))
        facts.holds(f"condition:{prefix}flow", f"d{name}/dt < 0 for x in D with "
                    f"{name}(x) = 0", level, compare("<", dB))


SWA_GUARANTEE = ROA_GUARANTEE + ("; and those trajectories never enter U: B <= 0 on I, "
                                 "B > 0 on U, and B strictly decreases wherever B = 0 in D")


ball_strengthenings("stable while avoid", SWA_GUARANTEE)


@rule("stable while avoid", guarantee=SWA_GUARANTEE)
def stable_while_avoid(facts: Facts) -> None:
    region_of_attraction(facts)
    avoiding(facts)


def avoiding(facts: Facts) -> None:
    """The barrier of stable while avoid: I and U disjoint, B's conditions for I and U."""
    initial, unsafe = facts.member(facts.role("initial")), facts.member(facts.role("unsafe"))
    facts.disjoint("relation:initial and unsafe", "I and U are disjoint", initial, unsafe)
    barrier_conditions(facts, "B", initial, unsafe, "I", "U", prefix="barrier_")


def reach_while_avoid(facts: Facts, goal_role: str) -> None:
    V, dV = facts.value("V"), facts.change("V")
    safe, goal = facts.role("safe"), facts.role(goal_role)
    initial = facts.member(facts.role("initial"))
    facts.bounded("safe", "the safe set S", safe)
    facts.inside("relation:initial in interior of safe", "I lies in the interior of S",
                 initial, facts.interior(safe))
    # V is continuous on the compact closure of S, so it is bounded below there
    facts.defined("V on the closure of S", facts.closure(safe), [V])
    facts.holds("condition:initial", "V(x) <= 0 on I", initial, compare("<=", V))
    facts.holds("condition:boundary", "V(x) > 0 on the boundary of S",
                facts.boundary(safe), compare(">", V))
    outside_goal = L.conjunction(facts.member(safe), L.negation(facts.member(goal)),
                                 compare("<=", V))
    facts.holds("condition:decrease", f"dV/dt <= -{GAMMA} in S outside "
                f"{'G' if goal_role == 'goal' else 'F'} where V(x) <= 0", outside_goal,
                compare("<=", dV, E.Num(-GAMMA)))


@rule("reach while avoid", guarantee=reach_guarantee("S", "G"))
def reach(facts: Facts) -> None:
    reach_while_avoid(facts, "goal")
    facts.inside("relation:goal in interior of safe", "G lies in the interior of S",
                 facts.member(facts.role("goal")), facts.interior(facts.role("safe")))


# reach: the checker makes the safe set the domain
rule("reach", guarantee=reach_guarantee("D", "G"))(reach)


@rule("reach and stay while avoid", guarantee=(
    "every trajectory from I stays in S, reaches F ∩ {V < β} in finite time and then stays "
    "in F for ever: V <= 0 on I and V > 0 on ∂S, V decreases at rate at least "
    f"{GAMMA} wherever V <= 0 in S outside F ∩ {{V < β}}, and F ∩ {{V < β}} cannot be "
    "left, since V > β on ∂F and V decreases where V = β in F"))
def reach_and_stay(facts: Facts) -> None:
    reach_while_avoid(facts, "final")
    V, dV, beta = facts.value("V"), facts.change("V"), facts.level("beta")
    final = facts.role("final")
    facts.disjoint("relation:final and unsafe", "F and U are disjoint", facts.member(final),
                   facts.member(facts.role("unsafe")))
    facts.holds("condition:stay_boundary", "V(x) > β on the boundary of F",
                facts.boundary(final), compare(">", V, beta))
    facts.holds("condition:stay_decrease", f"dV/dt <= -{GAMMA} in F where V(x) >= β",
                L.conjunction(facts.member(final), compare(">=", V, beta)),
                compare("<=", dV, E.Num(-GAMMA)))


@rule("reach-avoid-remain", guarantee=reach_guarantee("S", "G") + (
    "; once in G, it remains in F while it stays in D: B <= 0 on G, B > 0 on D \\ F, and "
    "B strictly decreases wherever B = 0"))
def reach_avoid_remain(facts: Facts) -> None:
    reach(facts)
    goal, final = facts.member(facts.role("goal")), facts.member(facts.role("final"))
    facts.inside("relation:goal in final", "G lies in F", goal, final)
    facts.disjoint("relation:final and unsafe", "F and U are disjoint", final,
                   facts.member(facts.role("unsafe")))
    barrier_conditions(facts, "B", goal, L.negation(final), "G", "D \\ F", prefix="barrier_")


@strengthening("reach-avoid-remain", CONTINUOUS, name="remains in F", guarantee=reach_guarantee(
    "S", "G") + "; once in G, it remains in F for ever: B <= 0 on G, B > 0 on D \\ F, B "
    "strictly decreases wherever B = 0 in D, and F's closure lies in the interior of D, so "
    "a trajectory would have to cross B = 0 in D before it could leave F")
def remains_in_final(facts: Facts) -> None:
    facts.inside("strong:final in interior of domain", "the closure of F lies in the interior "
                 "of D", facts.closure(facts.role("final")), facts.interior(facts.spec.domain))
