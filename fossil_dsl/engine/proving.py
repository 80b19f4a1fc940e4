"""Proving a function found by an attempt (a program's, a conserved quantity, a
repelling equilibrium's barrier): sum-of-squares refutations of the kernel's obligations
first, then one pass of the solvers for what they leave; nothing is learned."""
from __future__ import annotations

import time
from dataclasses import replace

from fossil_dsl.engine.loop import Cegis, CegisOutcome, IterationRecord, Verdict, failure_reason
from fossil_dsl.engine.sos_reach import same_polynomial
from fossil_dsl.kernel import Claim, list_obligations
from fossil_dsl.kernel.prove import SUM_OF_SQUARES
from fossil_dsl.plan.compile import Plan
from fossil_dsl.solvers.api import Backend, Status
from fossil_dsl.solvers.positivstellensatz import SlabSplit
from fossil_dsl.solvers.slab_split import refuted_in_slabs, slab_variable
from fossil_dsl.solvers.sos_refutation import ATOMS_MAX_VARIABLES, refute

# per solver query on a found candidate, where no refutation settles a condition: a
# candidate the solvers cannot prove at once is left to learning (bb25: an interval
# proof of 50 s against 6 s of learning)
SOS_QUERY_SECONDS = 5.0
# the same for a reach program's functions solved for a polynomial stand-in of the field:
# its conditions with elementary functions can only be proved by the solvers, and
# learning is the weaker alternative there (probe60/ad08, a tanh ring's RAR: the quartic
# V's decrease took the interval procedure 6 s; at 5 s, learning then failed in 100 s)
STAND_IN_QUERY_SECONDS = 15.0
# or this share of the time left, if more: probe64/am05's degree-4 V (a CSTR with exp)
# needed 28 s of the interval procedure for its decrease, and learning failed after it
STAND_IN_SHARE = 0.3
# for refutations slab by slab (solvers/slab_split.py), where they would settle what the
# refutations leave: probe65/ao10's decrease, 10 slabs of its pitch at 5-7 s each
SLAB_SECONDS = 80.0
SLAB_SHARE = 0.5  # of the run's time left, at most (learning may still do it)
SOS_SHARE = 0.25  # of the run's time, at most, for a sum-of-squares attempt's program
SOS_SECONDS = 30.0  # and never more than this
# the reach attempt's refutations get twice what its program took, and at least this:
# a refutation program is about as large as the program (a 5-state map's degree-6
# decrease, probe49/e08: V found in 16 s, its decrease refuted in 12-18 s), and a small
# floor keeps hopeless ones short (g04: its quartic V's refutations took 40 s and failed;
# a quadratic V's are found in well under a second)
REACH_REFUTING_SECONDS = 5.0


def budgets(finding, floor: float, deadline: float) -> tuple[float, float]:
    """(seconds of refutations, seconds per solver query) for a program's functions: for
    a stand-in's, the conditions with elementary functions are proved by the solvers
    (probe55/p07: interval), and where the stand-in misled the program the solvers' pass
    finds that in a fraction of a second (probe48/c03: 5 s of refuting to no end before);
    likewise where the functions were variables bounded by their facts (probe76/az24's
    quartic V, found with the facts of tanh on D: its decrease not refuted, and the
    interval procedure's query 9 boxes short of a proof after 5 s, proved with longer
    queries, the kernel's proof 7 s); else twice the program's time, at least `floor`."""
    if finding.stand_in or getattr(finding, "abstracted", False):
        share = STAND_IN_SHARE * (deadline - time.monotonic())
        return 2 * finding.seconds, max(STAND_IN_QUERY_SECONDS, share)
    return max(floor, 2 * finding.seconds), SOS_QUERY_SECONDS


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


def prove_found(plan: Plan, backend: Backend, listener, deadline: float, finding,
                refuting_seconds: float, query_seconds: float = SOS_QUERY_SECONDS,
                formulas: dict | None = None, prepare=None,
                atoms_limit: int = ATOMS_MAX_VARIABLES):
    """((plan with the function given, certified outcome) or None, what happened)."""
    try:
        given, outcome = verify_given(plan, backend, listener, deadline,
                                      formulas or only_function(plan, finding.formula),
                                      query_seconds, time.monotonic() + refuting_seconds,
                                      prepare, atoms_limit)
    except NotSetUp as exc:
        return None, f"{finding.describe()}: {exc}"
    if not outcome.certified:
        return None, f"{finding.describe()}: not proved: {outcome.reason}"
    return (given, replace(outcome, strategy=finding.describe())), ""


def verify_given(plan: Plan, backend: Backend, listener, deadline: float, formulas,
                 query_seconds: float, refuting_until: float | None = None, prepare=None,
                 atoms_limit: int = ATOMS_MAX_VARIABLES):
    """The plan with the found functions (name -> formula) as its candidates, and its
    outcome: proved by refutations of the kernel's obligations where they settle every
    condition, else by the solvers; the
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
    outcome = _refuted(given, cegis, refuting_until or deadline, atoms_limit)
    listener.finished(outcome.history[-1])
    if not outcome.certified:
        outcome = _merged(_verified_once(cegis), outcome.refutations)
    return given, outcome


def only_function(plan: Plan, formula) -> dict:
    """The formula as the plan's one function (a Lyapunov V, a barrier B)."""
    return {f.name: formula for f in plan.functions}


def _refuted(plan: Plan, cegis: Cegis, deadline: float, atoms_limit: int) -> CegisOutcome:
    """Sum-of-squares refutations of the kernel's obligations for the candidate, found
    numerically and rounded (the kernel checks them exactly); certified here when they
    settle every condition."""
    started = time.monotonic()
    candidate = cegis.exact_candidate()
    claim = Claim(plan.spec, dict(candidate.formulas), dict(candidate.controller),
                  dict(candidate.levels), plan.origin_radius)
    refutations, unrefuted = {}, []
    for obligation in list_obligations(claim):
        found = refute(obligation.query, plan.states, deadline, atoms_limit)
        if found is not None:
            refutations[obligation.name] = found
        else:
            unrefuted.append(obligation)
    if all(slab_variable(o.query, plan.states) for o in unrefuted):
        # what is left may be refuted slab by slab; only worth its time where every
        # obligation the refutations leave could be (what slabs leave, such as a
        # divisor's being nonzero, goes to the solvers next)
        now = time.monotonic()
        slabs_until = now + min(SLAB_SECONDS, SLAB_SHARE * (cegis.deadline - now))
        for obligation in unrefuted:
            found = refuted_in_slabs(obligation.query, plan.states, slabs_until)
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
    return tuple(replace(v, status=Status.UNSAT, solver=SUM_OF_SQUARES, counterexample=None,
                         reason=_how(refutations[f"condition:{v.condition}"]))
                 if v.status is not Status.UNSAT and f"condition:{v.condition}" in refutations
                 else v for v in verdicts)


def _how(refutation) -> str:
    """What the summary says of a refutation beside the procedure's name."""
    if isinstance(refutation, SlabSplit):
        return f"refuted in {len(refutation.slabs)} slabs across {refutation.variable}"
    return ""


def program_finding(plan: Plan, listener, phase: str, search):
    """What a program's search finds within the sum-of-squares budget (or None)."""
    listener.phase(0, phase)
    return search(plan, time.monotonic() + min(SOS_SECONDS, SOS_SHARE * plan.options.timeout))


def set_up(cegis: Cegis, finding) -> None:
    """The controller and the levels (RSWA's β) the functions were found for."""
    if finding.controller:
        controller_set(cegis, finding)
    cegis.learner.fixed_levels = dict(finding.levels)


def controller_set(cegis: Cegis, finding) -> None:
    """Sets the loop's controller network to the gain the functions were found for;
    raises NotSetUp unless its exact formulas are the ones the program used."""
    from fossil_dsl.engine.linear import set_linear
    controller = cegis.learner.controller
    set_linear(controller, finding.gain, finding.operating)
    exact = controller.formulas(cegis.states, cegis.learner.digits)
    states = cegis.states
    if not all(same_polynomial(formula, finding.controller[u], states)
               for u, formula in zip(cegis.plan.controller.inputs, exact)):
        raise NotSetUp("the controller network cannot hold its gain")
