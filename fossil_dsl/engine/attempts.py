"""What a run tries, in order: a sum-of-squares Lyapunov function where the system is
polynomial (proved by sum-of-squares refutations of the kernel's obligations, or by the
solvers like a given candidate), then the learning loop with the time left. Whatever is
tried, the kernel judges the final formulas (and checks any refutation) alone."""
from __future__ import annotations

import time

import numpy as np
from dataclasses import replace

from fossil_dsl.engine import basin, first_integral, sos, sos_reach, torch_import
from fossil_dsl.engine.given import verifier_only
from fossil_dsl.engine.sos_barrier import barrier
from fossil_dsl.engine.loop import (Cegis, CegisOutcome, IterationRecord, Verdict, as_listener,
                                    failure_reason)
from fossil_dsl.kernel import Claim, list_obligations
from fossil_dsl.kernel.prove import SUM_OF_SQUARES
from fossil_dsl.kernel.rules import lemma_radius
from fossil_dsl.plan.compile import Plan, origin_radius, with_conditions
from fossil_dsl.solvers.api import Backend, Status
from fossil_dsl.solvers.sos_refutation import refute

BASIN_SHARE = 0.3  # of the run's time, at most, for shaping V to the basin (region: largest)
SOS_SHARE = 0.25  # of the run's time, at most, for the sum-of-squares attempt
SOS_SECONDS = 30.0  # and never more than this
# per solver query on the sum-of-squares candidate, where no refutation settles a
# condition: a candidate the solvers cannot prove at once is left to learning (bb25: an
# interval proof of 50 s against 6 s of learning)
SOS_QUERY_SECONDS = 5.0
# the shaped V has no cheaper alternative in a `region: largest` run (a degree-8 decrease
# condition near the excluded ball takes the interval procedure 5-20 s)
BASIN_QUERY_SECONDS = 30.0
# the reach attempt's refutations get twice what its program took, and at least this:
# a refutation program is about as large as the program (a 5-state map's degree-6
# decrease, probe49/e08: V found in 16 s, its decrease refuted in 12-18 s), and a small
# floor keeps hopeless ones short (g04: its quartic V's refutations took 40 s and failed;
# a quadratic V's are found in well under a second)
REACH_REFUTING_SECONDS = 5.0
CONSERVED_REFINEMENTS = 3  # conserved-quantity barriers chosen again with counterexamples
BASIN_TOTAL_SHARE = 0.5  # of the run's time, at most, for the whole attempt
BASIN_REFINEMENTS = 3  # programs solved again with the solvers' counterexamples
BASIN_REFINING_SHARE = 0.1  # of the run's time, at most, for each
BASIN_REFUTING_SECONDS = 10.0  # for sum-of-squares refutations of its obligations


def run_attempts(plan: Plan, backend: Backend | None, progress=None) -> tuple[Plan, CegisOutcome]:
    """The plan that was run (a found function becomes its candidate) and its outcome."""
    listener = as_listener(progress)
    deadline = time.monotonic() + plan.options.timeout
    notes = []
    if backend is not None and basin.applies(plan):
        found, note = _shaped_to_basin(plan, backend, listener, deadline)
        if found is not None:
            return found
        notes.append(note)
    if backend is not None and first_integral.applies(plan):
        found, note = _conserved(plan, backend, listener, deadline)
        if found is not None:
            return found
        notes.append(note)
    if backend is not None and sos.applies(plan):
        found, note = _sum_of_squares(plan, backend, listener, deadline)
        if found is not None:
            return found
        notes.append(note)
    if backend is not None and sos_reach.applies(plan):
        found, note = _reach_sum_of_squares(plan, backend, listener, deadline)
        if found is not None:
            return found
        notes.append(note)
    note = "; ".join(n for n in notes if n)
    deadline += _learning_imported(plan)
    outcome = Cegis(plan, backend, listener, deadline).run()
    variant = _variant_plan(plan) if verifier_only(plan) and not outcome.certified else None
    if variant is not None:  # a given function may meet the variant's conditions instead
        other = Cegis(variant, backend, listener, deadline).run()
        if other.certified:
            return variant, replace(other, strategy="given function")
    return plan, replace(outcome, strategy="learning" + (f" ({note})" if note else ""))


def _learning_imported(plan: Plan) -> float:
    """Seconds spent importing torch for the loop's learning (0 where it learns nothing,
    or torch was in already): start-up, which the loop's deadline is moved on by."""
    if verifier_only(plan):
        return 0.0
    before = torch_import.seconds_spent()
    torch_import.learning_support()
    return torch_import.seconds_spent() - before


def _variant_plan(plan: Plan) -> Plan | None:
    """The plan with the conditions of the kernel rule's variant, if it has one."""
    conditions = plan.certificate.variant_conditions()
    return None if conditions is None else with_conditions(plan, conditions)


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
    for attempt in (lemma,) if lemma.origin_radius == radius else \
            (lemma, replace(plan, origin_radius=radius)):
        given, outcome = _given(attempt, backend, listener, deadline,
                                _only(attempt, finding.formula), BASIN_QUERY_SECONDS,
                                time.monotonic() + BASIN_REFUTING_SECONDS)
        if outcome.certified or time.monotonic() > deadline:
            break
    return given, outcome


def _ball_left_out(plan: Plan, finding, radius) -> Plan:
    """The plan with the ball round the origin that the conditions leave out: the
    neighbourhood of the origin goes to the kernel's Taylor lemma (a polynomial of degree
    8 near 0 is beyond Z3, and a numerical procedure needs the ball excluded), so the
    ball is made small enough for the lemma's estimates where halving it helps (a
    quadratic part nearly flat in one direction needs a smaller ball)."""
    claim = Claim(plan.spec, {plan.functions[0].name: finding.formula}, {}, {}, radius)
    return replace(plan, origin_radius=lemma_radius(claim) or radius)


def _sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, certified outcome) or None, what happened)."""
    listener.phase(0, "sum-of-squares program")
    budget = min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    search = barrier if plan.certificate.form == "safety" else sos.lyapunov
    finding = search(plan, time.monotonic() + budget)
    if finding is None:
        return None, "no sum-of-squares certificate found"
    found, note = _proved(plan, backend, listener, deadline, finding, budget)
    ball = _lemma_ball(plan, finding) if found is None else None
    if ball is not None:  # the solvers' "counterexamples" were next to the origin
        found, note = _proved(ball, backend, listener, deadline, finding, budget,
                              BASIN_QUERY_SECONDS)
    return found, note


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


def _reach_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V (and B) given and the controller set, certified outcome) or None,
    what happened)."""
    listener.phase(0, "sum-of-squares program (reach)")
    budget = min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    finding = sos_reach.search(plan, time.monotonic() + budget)
    if finding is None:
        return None, "no sum-of-squares reach certificate found"
    prepare = (lambda cegis: _controller_set(cegis, finding)) if finding.controller else None
    refuting = max(REACH_REFUTING_SECONDS, 2 * finding.seconds)
    return _proved(plan, backend, listener, deadline, finding, refuting,
                   formulas=finding.formulas, prepare=prepare)


def _conserved(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with B given, certified outcome) or None, what happened): B from conserved
    quantities, proved by the non-increasing rule in continuous time; the solvers'
    counterexamples to B's signs on I and U are added to the samples and B chosen again
    (up to CONSERVED_REFINEMENTS times)."""
    listener.phase(0, "conserved quantities")
    budget = time.monotonic() + min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    variant = _variant_plan(plan) or plan
    extra, note = ([], []), "no conserved quantity separates I from U"
    for _ in range(CONSERVED_REFINEMENTS + 1):
        finding = first_integral.search(plan, budget, extra)
        if finding is None or time.monotonic() > budget:
            break
        prepare = (lambda cegis: _controller_set(cegis, finding)) if finding.controller \
            else None
        try:
            given, outcome = _given(variant, backend, listener, deadline,
                                    _only(variant, finding.formula), SOS_QUERY_SECONDS,
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


class NotSetUp(Exception):
    """A found function's companion (a controller) could not be given to the loop."""


def _verified_once(cegis: Cegis) -> CegisOutcome:
    """The loop's candidate verified as it is (nothing is learned)."""
    candidate = cegis.exact_candidate()
    verdicts, queries, seconds = cegis.verify(candidate, 1)
    record = IterationRecord(1, 0.0, verdicts, 0.0, seconds)
    cegis.listener.finished(record)
    certified = all(v.status is Status.UNSAT for v in verdicts)
    return CegisOutcome(certified, "every condition proved" if certified else
                        failure_reason(verdicts), candidate, queries, tuple(verdicts),
                        (record,), 0.0, seconds, cegis.networks)


def _proved(plan: Plan, backend: Backend, listener, deadline: float, finding,
            refuting_seconds: float, query_seconds: float = SOS_QUERY_SECONDS,
            formulas: dict | None = None, prepare=None):
    """((plan with the function given, certified outcome) or None, what happened)."""
    try:
        given, outcome = _given(plan, backend, listener, deadline,
                                formulas or _only(plan, finding.formula), query_seconds,
                                time.monotonic() + refuting_seconds, prepare)
    except NotSetUp as exc:
        return None, f"{finding.describe()}: {exc}"
    if not outcome.certified:
        return None, f"{finding.describe()}: not proved: {outcome.reason}"
    return (given, replace(outcome, strategy=finding.describe())), ""


def _given(plan: Plan, backend: Backend, listener, deadline: float, formulas,
           query_seconds: float, refuting_until: float | None = None, prepare=None):
    """The plan with the found functions (name -> formula) as its candidates, and its
    outcome: proved by refutations of the
    kernel's obligations where they settle every condition, else by the solvers; the
    candidate is verified once (nothing is learned). `prepare(cegis)` sets up the rest
    of the loop (a controller), raising NotSetUp where it cannot."""
    given = replace(plan, functions=tuple(replace(f, candidate=formulas[f.name])
                                          for f in plan.functions))
    options = replace(plan.options, query_timeout=min(plan.options.query_timeout,
                                                      query_seconds))
    cegis = Cegis(replace(given, options=options), backend, listener, deadline)
    if prepare is not None:
        prepare(cegis)
    listener.phase(0, "sum-of-squares refutations")
    outcome = _refuted(given, cegis, refuting_until or deadline)
    listener.finished(outcome.history[-1])
    if not outcome.certified:
        outcome = _merged(_verified_once(cegis), outcome.refutations)
    return given, outcome


def _only(plan: Plan, formula) -> dict:
    """The formula as the plan's one function (a Lyapunov V, a barrier B)."""
    return {f.name: formula for f in plan.functions}


def _refuted(plan: Plan, cegis: Cegis, deadline: float) -> CegisOutcome:
    """Sum-of-squares refutations of the kernel's obligations for the candidate, found
    numerically and rounded (the kernel checks them exactly); certified here when they
    settle every condition."""
    started = time.monotonic()
    candidate = cegis.exact_candidate()
    claim = Claim(plan.spec, dict(candidate.formulas), {}, dict(candidate.levels),
                  plan.origin_radius)
    refutations = {}
    for obligation in list_obligations(claim):
        found = refute(obligation.query, plan.states, deadline)
        if found is not None:
            refutations[obligation.name] = found
    verdicts = _settled(tuple(Verdict(c.name, Status.UNKNOWN, "no refutation found")
                              for c in plan.conditions), refutations)
    certified = all(v.status is Status.UNSAT for v in verdicts)
    seconds = time.monotonic() - started
    return CegisOutcome(certified, "every condition proved" if certified else
                        "not every condition has a refutation", candidate, {}, verdicts,
                        (IterationRecord(1, 0.0, verdicts, 0.0, seconds),), 0.0, seconds, {},
                        refutations=refutations)


def _merged(outcome: CegisOutcome, refutations: dict) -> CegisOutcome:
    """The solvers' verdicts, with the conditions they did not prove settled by a
    refutation where there is one. (A "counterexample" of a delta-decision verifier near
    the origin is no obstacle: a refutation that checks shows there is none; where there
    is a true one, no refutation exists.)"""
    verdicts = _settled(outcome.verdicts, refutations)
    certified = not outcome.interrupted and all(v.status is Status.UNSAT for v in verdicts)
    return replace(outcome, certified=certified, verdicts=verdicts, refutations=refutations,
                   reason="every condition proved" if certified else outcome.reason)


def _settled(verdicts, refutations: dict) -> tuple[Verdict, ...]:
    """Each condition not proved yet that a refutation of the kernel's obligation for it
    settles, as proved by it."""
    return tuple(replace(v, status=Status.UNSAT, solver=SUM_OF_SQUARES, reason="",
                         counterexample=None)
                 if v.status is not Status.UNSAT and f"condition:{v.condition}" in refutations
                 else v for v in verdicts)
