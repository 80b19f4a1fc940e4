"""What a run tries, in order (an unstable origin's stability refuted first): for `region:
largest` a V shaped to the basin; for safety a conserved quantity's barrier, then one
round a repelling equilibrium in U; a sum-of-squares certificate where the system is
polynomial (each proved by proving.py), then the learning loop with the time left.
Whatever is tried, the kernel judges the final formulas (and checks any refutation) alone."""
from __future__ import annotations

import functools
import itertools
import time

import numpy as np
from dataclasses import replace

from fossil_dsl.engine import (basin, first_integral, quadratic_roa, repelling, sos,
                               sos_controlled, sos_reach, sos_roa, swa_parts, unstable_origin)
from fossil_dsl.engine.learning import learn, learn_briefly, learning_imported
from fossil_dsl.engine.proving import (SOS_QUERY_SECONDS, NotSetUp, budgets, only_function,
                                       prove_found, verify_given)
from fossil_dsl.engine.sos_barrier import barrier
from fossil_dsl.engine.loop import Cegis, CegisOutcome, as_listener
from fossil_dsl.ir import traversal
from fossil_dsl.kernel import Claim
from fossil_dsl.engine.lemma_radius import lemma_radius
from fossil_dsl.plan.compile import Plan, origin_radius, variant_plan
from fossil_dsl.solvers.api import Backend
from fossil_dsl.solvers.sos_refutation import ATOMS_MAX_VARIABLES

BASIN_SHARE = 0.3  # of the run's time, at most, for shaping V to the basin (region: largest)
SOS_SHARE = 0.25  # of the run's time, at most, for the sum-of-squares attempt
SOS_SECONDS = 30.0  # and never more than this
# the shaped V has no cheaper alternative in a `region: largest` run (a degree-8 decrease
# condition near the excluded ball takes the interval procedure 5-20 s)
BASIN_QUERY_SECONDS = 30.0
# the reach attempt's refutations get twice what its program took, and at least this:
# a refutation program is about as large as the program (a 5-state map's degree-6
# decrease, probe49/e08: V found in 16 s, its decrease refuted in 12-18 s), and a small
# floor keeps hopeless ones short (g04: its quartic V's refutations took 40 s and failed;
# a quadratic V's are found in well under a second)
REACH_REFUTING_SECONDS = 5.0
# the first quadratic V of a field with elementary functions: a larger program and more
# time for its refutations (probe44/y12's decrease, 8 variables with sin and cos: 1035
# Gram entries in s0 alone, refuted in 10 s; by bisection not in 60 s) and per query
# (probe67/aq18's decrease: 9 s of Taylor forms, solvers/taylor_boxes.py)
QUADRATIC_REFUTING = (20.0, 3_000, 25.0)  # (seconds, largest program, seconds per query)
# of the time left, for learning V beside a B found by RAR's barrier program (probe59/ac08:
# learning both failed in 120 s, V beside the program's B was certified in 50 s)
LEARNED_BESIDE_SHARE = 0.6
REPELLING_TRIES = 2  # barriers round a repelling equilibrium proved, at most
QUADRATIC_TRIES = 2  # quadratic V of the linearisation proved, at most
CONSERVED_REFINEMENTS = 3  # conserved-quantity barriers chosen again with counterexamples
BASIN_TOTAL_SHARE = 0.5  # of the run's time, at most, for the whole attempt
BASIN_REFINEMENTS = 3  # programs solved again with the solvers' counterexamples
BASIN_REFINING_SHARE = 0.1  # of the run's time, at most, for each
BASIN_REFUTING_SECONDS = 10.0  # for sum-of-squares refutations of its obligations


def run_attempts(plan: Plan, backend: Backend | None, progress=None) -> tuple[Plan, CegisOutcome]:
    """The plan that was run (a found function becomes its candidate) and its outcome."""
    listener = as_listener(progress)
    deadline = time.monotonic() + plan.options.timeout
    if (refuted := unstable_origin.refutation(plan)) is not None:
        return plan, unstable_origin.refuted_outcome(plan, refuted)
    notes = []
    for applies, attempt in ((basin.applies, _shaped_to_basin),
                             (first_integral.applies, _conserved),
                             (repelling.applies, _repelling),
                             (sos.applies, _sum_of_squares),
                             (sos_controlled.applies, _controlled_sum_of_squares),
                             (quadratic_roa.applies, _quadratic_region),
                             (swa_parts.applies, functools.partial(
                                 swa_parts.attempt, prove=_region_proved)),
                             (sos_roa.applies, _region_sum_of_squares),
                             (sos_reach.applies, _reach_sum_of_squares),
                             (quadratic_roa.reaches, _quadratic_region),
                             (sos_reach.applies_late, _reach_sum_of_squares)):
        if backend is not None and applies(plan):
            found, note = attempt(plan, backend, listener, deadline)
            if found is not None:
                return found
            notes.append(note)
    note = "; ".join(n for n in notes if n)
    return learn(plan, backend, listener, deadline, note)


def _shaped_to_basin(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, certified outcome) or None, what happened). Where the
    solvers refute the V found, their counterexamples are added to its program and it is
    solved again (up to BASIN_REFINEMENTS times)."""
    listener.phase(0, "V shaped to the simulated basin")
    started = time.monotonic()
    budget = started + BASIN_SHARE * plan.options.timeout
    # the whole attempt, proofs and refinements included: the rest of the run (sum of
    # squares, learning, raising β) keeps the other half
    deadline = min(deadline, started + BASIN_TOTAL_SHARE * plan.options.timeout)
    search = basin.BasinSearch(plan)
    finding = search.find(budget)
    note = "no V shaped to the basin found"
    for _ in range(BASIN_REFINEMENTS + 1):
        if finding is None or time.monotonic() > deadline:
            break
        given, outcome = _shaped_proof(plan, finding, backend, listener, deadline)
        if outcome.certified:
            return (given, replace(outcome, strategy=finding.describe())), ""
        note = f"{finding.describe()}: not proved: {outcome.reason}"
        points = [v.counterexample for v in outcome.verdicts if v.counterexample is not None]
        if not points:
            break
        finding = search.refine(np.array(points, dtype=float), min(
            deadline, time.monotonic() + BASIN_REFINING_SHARE * plan.options.timeout))
    return None, note


def _shaped_proof(plan: Plan, finding, backend: Backend, listener, deadline: float):
    """(plan with V given, outcome): proved with the ball the Taylor lemma needs, else
    (where that is not proved: a ball of 1/1600 was too small for the interval
    procedure's boxes near the origin) with the plan's own ball, ε-stability rather
    than nothing; the counterexamples are then the latter's."""
    radius = plan.origin_radius or origin_radius(plan.spec)
    lemma = _ball_left_out(plan, finding, radius)
    for attempt in _lemma_then_own(lemma, replace(plan, origin_radius=radius)):
        given, outcome = verify_given(attempt, backend, listener, deadline,
                                      only_function(attempt, finding.formula),
                                      BASIN_QUERY_SECONDS,
                                      time.monotonic() + BASIN_REFUTING_SECONDS)
        if outcome.certified or time.monotonic() > deadline:
            break
    return given, outcome


def _lemma_then_own(lemma: Plan, own: Plan) -> tuple:
    """The plans to prove with in turn: the Taylor lemma's ball (asymptotic stability),
    then, where that is another ball, the plan's own (ε-stability rather than nothing)."""
    return (lemma,) if lemma.origin_radius == own.origin_radius else (lemma, own)


def _ball_left_out(plan: Plan, finding, radius) -> Plan:
    """The plan with the ball round the origin that the conditions leave out: the
    neighbourhood of the origin goes to the kernel's Taylor lemma (a polynomial of degree
    8 near 0 is beyond Z3, and a numerical procedure needs the ball excluded), so the
    ball is made small enough for the lemma's estimates where halving it helps (a
    quadratic part nearly flat in one direction needs a smaller ball)."""
    return _lemma_plan(plan, {plan.functions[0].name: finding.formula}, radius=radius)


def _lemma_plan(plan: Plan, formulas: dict, controller=None, levels=None,
                radius=None) -> Plan:
    """The plan with the largest ball, of `radius` (default the plan's) halved up to
    four times, whose neighbourhood of the origin the kernel's Taylor lemma covers for
    the formulas (else the plan's own ball)."""
    radius = radius or plan.origin_radius
    if not radius:
        return plan
    claim = Claim(plan.spec, formulas, controller or {}, levels or {}, radius)
    return replace(plan, origin_radius=lemma_radius(claim) or radius)


def _repelling(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with B given, certified outcome) or None, what happened)."""
    listener.phase(0, "barrier round a repelling equilibrium")
    note = ""  # (none in U: nothing to say)
    for finding in itertools.islice(repelling.candidates(plan), REPELLING_TRIES):
        found, note = prove_found(plan, backend, listener, deadline, finding,
                                  REACH_REFUTING_SECONDS)
        if found is not None:
            return found, ""
    return None, note


def _quadratic_region(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, β fixed, the controller set, certified outcome) or None, why)."""
    listener.phase(0, "the linearisation's quadratic V")
    budget = time.monotonic() + min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    note = "no quadratic V of the linearisation decreases where it holds I"
    for index, finding in enumerate(itertools.islice(quadratic_roa.candidates(plan, budget),
                                                     QUADRATIC_TRIES)):
        larger = index == 0 and not all(map(traversal.is_arithmetic, plan.spec.dynamics))
        proved = variant_plan(plan) or plan if finding.reaches_boundary else plan
        found, note = _region_proved(proved, backend, listener, deadline, finding,
                                     *(QUADRATIC_REFUTING if larger else
                                       (REACH_REFUTING_SECONDS, ATOMS_MAX_VARIABLES,
                                        SOS_QUERY_SECONDS)))
        if found is not None:
            return found, ""
    return None, note


def _region_proved(plan: Plan, backend: Backend, listener, deadline: float, finding,
                   refuting: float, atoms_limit: int = ATOMS_MAX_VARIABLES,
                   querying: float = SOS_QUERY_SECONDS):
    """(plan with V given, β fixed and the controller set, certified outcome) or None,
    and what happened: proved with the Taylor lemma's ball, else with the plan's own."""
    lemma = _lemma_plan(plan, finding.formulas, finding.controller, finding.levels)
    note = ""
    for attempt in _lemma_then_own(lemma, plan):
        found, note = prove_found(attempt, backend, listener, deadline, finding, refuting,
                                  querying, finding.formulas, atoms_limit=atoms_limit,
                                  prepare=functools.partial(_set_up, finding=finding))
        if found is not None:
            return found, ""
    return None, note


def _region_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, β fixed and the controller set, certified outcome) or None,
    what happened)."""
    finding = _program_finding(plan, listener, "sum-of-squares program (region of attraction)",
                               sos_roa.search)
    if finding is None:
        return None, "no sum-of-squares region of attraction found"
    refuting, querying = budgets(finding, REACH_REFUTING_SECONDS, deadline)
    return _region_proved(plan, backend, listener, deadline, finding, refuting,
                          querying=querying)


def _sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, certified outcome) or None, what happened)."""
    listener.phase(0, "sum-of-squares program")
    budget = min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    search = barrier if plan.certificate.form == "safety" else sos.lyapunov
    finding = search(plan, time.monotonic() + budget)
    if finding is None:
        return None, "no sum-of-squares certificate found"
    found, note = prove_found(plan, backend, listener, deadline, finding, budget)
    ball = _lemma_ball(plan, finding) if found is None else None
    if ball is not None:  # the solvers' "counterexamples" were next to the origin
        found, note = prove_found(ball, backend, listener, deadline, finding, budget,
                                  BASIN_QUERY_SECONDS)
    return found, note


def _controlled_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with B given and the controller set, certified outcome) or None, what
    happened): a quadratic B's programs, the learning loop's first iteration, then the
    programs of higher degree."""
    phase = "sum-of-squares program (closed loop)"
    finding = _program_finding(plan, listener, phase, sos_controlled.quadratic)
    if finding is None:
        quick = learn_briefly(plan, backend, listener, deadline)
        if quick is not None:
            return quick, ""
        finding = _program_finding(plan, listener, phase, sos_controlled.higher)
    if finding is None:
        return None, "no sum-of-squares barrier found for an LQR gain"
    return prove_found(plan, backend, listener, deadline, finding,
                       min(SOS_SECONDS, SOS_SHARE * plan.options.timeout),
                       prepare=lambda cegis: _controller_set(cegis, finding))


def _lemma_ball(plan: Plan, finding) -> Plan | None:
    """Where the plan leaves no ball out (Z3 decides x ≠ 0 exactly, when it answers): the
    plan with a ball the kernel's Taylor lemma covers, so that the guarantee is the same
    and the interval procedure, which cannot refute boxes at the origin, can prove the
    rest (a 4-state cubic map: Z3 timed out on the sextic decrease, and the interval
    procedure's delta-sat box at 1e-4 from the origin was taken for a counterexample).
    None where it has a ball already, or the lemma does not apply."""
    if plan.origin_radius > 0 or finding.function != "V" \
            or not any(c.exclude_origin for c in plan.conditions):
        return None
    claim = Claim(plan.spec, {plan.functions[0].name: finding.formula}, {}, {},
                  origin_radius(plan.spec))
    radius = lemma_radius(claim)
    return None if radius is None else replace(plan, origin_radius=radius)


def _program_finding(plan: Plan, listener, phase: str, search):
    """What a program's search finds within the sum-of-squares budget (or None)."""
    listener.phase(0, phase)
    return search(plan, time.monotonic() + min(SOS_SECONDS, SOS_SHARE * plan.options.timeout))


def _reach_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V (and B) given and the controller set, certified outcome) or None,
    what happened)."""
    finding = _program_finding(plan, listener, "sum-of-squares program (reach)",
                               sos_reach.search)
    if finding is None:
        return None, "no sum-of-squares reach certificate found"
    if not finding.degree:  # RAR's B alone
        return _learned_beside(plan, backend, listener, deadline, finding)
    return prove_found(plan, backend, listener, deadline, finding,
                       *budgets(finding, REACH_REFUTING_SECONDS, deadline), finding.formulas,
                       prepare=lambda cegis: _set_up(cegis, finding))


def _learned_beside(plan: Plan, backend: Backend, listener, deadline: float, finding):
    """((plan with B given, certified outcome) or None, what happened): the loop learns V
    with the program's B fixed, for a share of the time left (then both are learned)."""
    given = replace(plan, functions=tuple(replace(f, candidate=finding.formulas.get(f.name))
                                          for f in plan.functions))
    until = time.monotonic() + LEARNED_BESIDE_SHARE * (deadline - time.monotonic())
    outcome = Cegis(given, backend, listener, until + learning_imported(given)).run()
    if outcome.certified:
        return (given, replace(outcome, strategy=f"learning V for {finding.describe()}")), ""
    return None, f"{finding.describe()}: no V learned for it: {outcome.reason}"


def _conserved(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with B given, certified outcome) or None, what happened): B from conserved
    quantities, proved by the non-increasing rule in continuous time; the solvers'
    counterexamples to B's signs on I and U are added to the samples and B chosen again
    (up to CONSERVED_REFINEMENTS times)."""
    listener.phase(0, "conserved quantities")
    budget = time.monotonic() + min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    variant = variant_plan(plan) or plan
    extra, note = ([], []), "no conserved quantity separates I from U"
    for _ in range(CONSERVED_REFINEMENTS + 1):
        finding = first_integral.search(plan, budget, extra)
        if finding is None or time.monotonic() > budget:
            break
        prepare = (lambda cegis: _controller_set(cegis, finding)) if finding.controller \
            else None
        try:
            given, outcome = verify_given(variant, backend, listener, deadline,
                                          only_function(variant, finding.formula),
                                          SOS_QUERY_SECONDS,
                                          time.monotonic() + REACH_REFUTING_SECONDS, prepare)
        except NotSetUp as exc:
            return None, f"{finding.describe()}: {exc}"
        if outcome.certified:
            return (given, replace(outcome, strategy=finding.describe())), ""
        note = f"{finding.describe()}: not proved: {outcome.reason}"
        points = {v.condition: v.counterexample for v in outcome.verdicts
                  if v.counterexample is not None}
        if not points.keys() & {"initial", "unsafe"}:
            break
        for index, role in enumerate(("initial", "unsafe")):
            if role in points:
                extra[index].append(np.asarray(points[role], dtype=float).reshape(1, -1))
    return None, note


def _set_up(cegis: Cegis, finding) -> None:
    """The controller and the levels (RSWA's β) the functions were found for."""
    if finding.controller:
        _controller_set(cegis, finding)
    cegis.learner.fixed_levels = dict(finding.levels)


def _controller_set(cegis: Cegis, finding) -> None:
    """Sets the loop's controller network to the gain the functions were found for;
    raises NotSetUp unless its exact formulas are the ones the program used."""
    from fossil_dsl.engine.linear import set_linear
    controller = cegis.learner.controller
    set_linear(controller, finding.gain, finding.operating)
    exact = controller.formulas(cegis.states, cegis.learner.digits)
    states = cegis.states
    if not all(sos_reach.same_polynomial(formula, finding.controller[u], states)
               for u, formula in zip(cegis.plan.controller.inputs, exact)):
        raise NotSetUp("the controller network cannot hold its gain")
