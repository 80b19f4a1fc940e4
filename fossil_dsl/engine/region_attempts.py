"""The attempts for stability-type properties and regions (`region: largest` V shaped
to the simulated basin, the linearisation's quadratic V on its smallest sublevel set
holding I, the region-of-attraction program), and their proof with the ball round the
origin that the kernel's Taylor lemma covers. The order they run in is attempts.py's."""
from __future__ import annotations

import functools
import itertools
import time
from dataclasses import replace

import numpy as np

from fossil_dsl.engine import basin, quadratic_roa, sos_roa
from fossil_dsl.engine.lemma_radius import lemma_radius
from fossil_dsl.engine.proving import (REACH_REFUTING_SECONDS, SOS_QUERY_SECONDS, SOS_SECONDS,
                                       SOS_SHARE, budgets, only_function, program_finding,
                                       prove_found, set_up, verify_given)
from fossil_dsl.ir import traversal
from fossil_dsl.kernel import Claim
from fossil_dsl.plan.compile import Plan, origin_radius, variant_plan
from fossil_dsl.solvers.api import Backend
from fossil_dsl.solvers.sos_refutation import ATOMS_MAX_VARIABLES

BASIN_SHARE = 0.3  # of the run's time, at most, for shaping V to the basin (region: largest)
# the shaped V has no cheaper alternative in a `region: largest` run (a degree-8 decrease
# condition near the excluded ball takes the interval procedure 5-20 s)
BASIN_QUERY_SECONDS = 30.0
BASIN_TOTAL_SHARE = 0.5  # of the run's time, at most, for the whole attempt
BASIN_REFINEMENTS = 3  # programs solved again with the solvers' counterexamples
BASIN_REFINING_SHARE = 0.1  # of the run's time, at most, for each
BASIN_REFUTING_SECONDS = 10.0  # for sum-of-squares refutations of its obligations
# the first quadratic V of a field with elementary functions: a larger program and more
# time for its refutations (probe44/y12's decrease, 8 variables with sin and cos: 1035
# Gram entries in s0 alone, refuted in 10 s; by bisection not in 60 s) and per query
# (probe67/aq18's decrease: 9 s of Taylor forms, solvers/taylor_boxes.py)
QUADRATIC_REFUTING = (20.0, 3_000, 25.0)  # (seconds, largest program, seconds per query)
QUADRATIC_TRIES = 2  # quadratic V of the linearisation proved, at most


def shaped_to_basin(plan: Plan, backend: Backend, listener, deadline: float):
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
    return lemma_plan(plan, {plan.functions[0].name: finding.formula}, radius=radius)


def lemma_plan(plan: Plan, formulas: dict, controller=None, levels=None,
               radius=None) -> Plan:
    """The plan with the largest ball, of `radius` (default the plan's) halved up to
    four times, whose neighbourhood of the origin the kernel's Taylor lemma covers for
    the formulas (else the plan's own ball)."""
    radius = radius or plan.origin_radius
    if not radius:
        return plan
    claim = Claim(plan.spec, formulas, controller or {}, levels or {}, radius)
    return replace(plan, origin_radius=lemma_radius(claim) or radius)


def quadratic_region(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, β fixed, the controller set, certified outcome) or None, why)."""
    listener.phase(0, "the linearisation's quadratic V")
    budget = time.monotonic() + min(SOS_SECONDS, SOS_SHARE * plan.options.timeout)
    note = "no quadratic V of the linearisation decreases where it holds I"
    for index, finding in enumerate(itertools.islice(quadratic_roa.candidates(plan, budget),
                                                     QUADRATIC_TRIES)):
        larger = index == 0 and not all(map(traversal.is_arithmetic, plan.spec.dynamics))
        proved = variant_plan(plan) or plan if finding.reaches_boundary else plan
        found, note = region_proved(proved, backend, listener, deadline, finding,
                                    *(QUADRATIC_REFUTING if larger else
                                      (REACH_REFUTING_SECONDS, ATOMS_MAX_VARIABLES,
                                       SOS_QUERY_SECONDS)))
        if found is not None:
            return found, ""
    return None, note


def region_proved(plan: Plan, backend: Backend, listener, deadline: float, finding,
                  refuting: float, atoms_limit: int = ATOMS_MAX_VARIABLES,
                  querying: float = SOS_QUERY_SECONDS):
    """(plan with V given, β fixed and the controller set, certified outcome) or None,
    and what happened: proved with the Taylor lemma's ball, else with the plan's own."""
    lemma = lemma_plan(plan, finding.formulas, finding.controller, finding.levels)
    note = ""
    for attempt in _lemma_then_own(lemma, plan):
        found, note = prove_found(attempt, backend, listener, deadline, finding, refuting,
                                  querying, finding.formulas, atoms_limit=atoms_limit,
                                  prepare=functools.partial(set_up, finding=finding))
        if found is not None:
            return found, ""
    return None, note


def region_sum_of_squares(plan: Plan, backend: Backend, listener, deadline: float):
    """((plan with V given, β fixed and the controller set, certified outcome) or None,
    what happened)."""
    finding = program_finding(plan, listener, "sum-of-squares program (region of attraction)",
                              sos_roa.search)
    if finding is None:
        return None, "no sum-of-squares region of attraction found"
    refuting, querying = budgets(finding, REACH_REFUTING_SECONDS, deadline)
    return region_proved(plan, backend, listener, deadline, finding, refuting,
                         querying=querying)


def lemma_ball(plan: Plan, finding) -> Plan | None:
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
