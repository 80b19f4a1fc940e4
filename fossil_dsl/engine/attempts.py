"""What a run tries, in order (an unstable origin's stability refuted first): for `region:
largest` a V shaped to the basin; for safety a conserved quantity's barrier, then one
round a repelling equilibrium in U; a sum-of-squares certificate where the system is
polynomial, the linearisation's quadratic V (each proved by proving.py; the
stability-type attempts are in region_attempts.py), then the learning loop with the time
left.
Whatever is tried, the kernel judges the final formulas (and checks any refutation) alone."""
from __future__ import annotations

import functools
import itertools
import time
from dataclasses import replace

import numpy as np

from fossil_dsl.engine import (basin, first_integral, quadratic_roa, repelling, sos,
                               sos_controlled, sos_reach, sos_roa, swa_parts, unstable_origin)
from fossil_dsl.engine.learning import learn, learn_briefly, learning_imported
from fossil_dsl.engine.loop import Cegis, CegisOutcome, as_listener
from fossil_dsl.engine.proving import (REACH_REFUTING_SECONDS, SOS_QUERY_SECONDS, SOS_SECONDS,
                                       SOS_SHARE, NotSetUp, budgets, controller_set,
                                       only_function, program_finding, prove_found, set_up,
                                       verify_given)
from fossil_dsl.engine.region_attempts import (BASIN_QUERY_SECONDS, lemma_ball,
                                               quadratic_region, region_proved,
                                               region_sum_of_squares, shaped_to_basin)
from fossil_dsl.engine.sos_barrier import barrier
from fossil_dsl.plan.compile import Plan, variant_plan
from fossil_dsl.solvers.api import Backend

# of the time left, for learning V beside a B found by RAR's barrier program (probe59/ac08:
# learning both failed in 120 s, V beside the program's B was certified in 50 s)
LEARNED_BESIDE_SHARE = 0.6
REPELLING_TRIES = 2  # barriers round a repelling equilibrium proved, at most
CONSERVED_REFINEMENTS = 3  # conserved-quantity barriers chosen again with counterexamples


def run_attempts(plan: Plan, backend: Backend | None, progress=None) -> tuple[Plan, CegisOutcome]:
    """The plan that was run (a found function becomes its candidate) and its outcome."""
    listener = as_listener(progress)
    deadline = time.monotonic() + plan.options.timeout
    if (refuted := unstable_origin.refutation(plan)) is not None:
        return plan, unstable_origin.refuted_outcome(plan, refuted)
    notes = []
    for applies, attempt in ((basin.applies, shaped_to_basin),
                             (first_integral.applies, _conserved),
                             (repelling.applies, _repelling),
                             (sos.applies, _sum_of_squares),
                             (sos_controlled.applies, _controlled_sum_of_squares),
                             (quadratic_roa.applies, quadratic_region),
                             (swa_parts.applies, functools.partial(
                                 swa_parts.attempt, prove=region_proved)),
                             (sos_roa.applies, region_sum_of_squares),
                             (sos_reach.applies, _reach_sum_of_squares),
                             (quadratic_roa.reaches, quadratic_region),
                             (sos_reach.applies_late, _reach_sum_of_squares)):
        if backend is not None and applies(plan):
            found, note = attempt(plan, backend, listener, deadline)
            if found is not None:
                return found
            notes.append(note)
    note = "; ".join(n for n in notes if n)
    return learn(plan, backend, listener, deadline, note)


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


def _sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, certified outcome) or None, what happened)."""
    listener.phase(0, "sum-of-squares program")
    budget = min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    search = barrier if plan.certificate.form == "safety" else sos.lyapunov
    finding = search(plan, time.monotonic() + budget)
    if finding is None:
        return None, "no sum-of-squares certificate found"
    found, note = prove_found(plan, backend, listener, deadline, finding, budget)
    ball = lemma_ball(plan, finding) if found is None else None
    if ball is not None:  # the solvers' "counterexamples" were next to the origin
        found, note = prove_found(ball, backend, listener, deadline, finding, budget,
                                  BASIN_QUERY_SECONDS)
    return found, note


def _controlled_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with B given and the controller set, certified outcome) or None, what
    happened): a quadratic B's programs, the learning loop's first iteration, then the
    programs of higher degree."""
    phase = "sum-of-squares program (closed loop)"
    finding = program_finding(plan, listener, phase, sos_controlled.quadratic)
    if finding is None:
        quick = learn_briefly(plan, backend, listener, deadline)
        if quick is not None:
            return quick, ""
        finding = program_finding(plan, listener, phase, sos_controlled.higher)
    if finding is None:
        return None, "no sum-of-squares barrier found for an LQR gain"
    return prove_found(plan, backend, listener, deadline, finding,
                       min(SOS_SECONDS, SOS_SHARE * plan.options.timeout),
                       prepare=lambda cegis: controller_set(cegis, finding))


def _reach_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V (and B) given and the controller set, certified outcome) or None,
    what happened)."""
    finding = program_finding(plan, listener, "sum-of-squares program (reach)",
                              sos_reach.search)
    if finding is None:
        return None, "no sum-of-squares reach certificate found"
    if not finding.degree:  # RAR's B alone
        return _learned_beside(plan, backend, listener, deadline, finding)
    return prove_found(plan, backend, listener, deadline, finding,
                       *budgets(finding, REACH_REFUTING_SECONDS, deadline), finding.formulas,
                       prepare=lambda cegis: set_up(cegis, finding))


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
        prepare = (lambda cegis: controller_set(cegis, finding)) if finding.controller \
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


