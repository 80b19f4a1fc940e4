"""The Python interface; the `fossilc` command is a thin layer over these functions."""
from __future__ import annotations

import importlib
import importlib.util
import time
from dataclasses import replace

from fossil_dsl.frontends.arguments import OptionError, check_options
from fossil_dsl.frontends.build import BespokeSet, BuildError, build_spec, spec_text
from fossil_dsl.frontends.checking import (CheckResult, check_file, check_source, check_text,
                                           load, loads, parse)
from fossil_dsl.engine.attempts import run_attempts
from fossil_dsl.engine.region import largest_level
from fossil_dsl.engine.split import SplitBackend
from fossil_dsl.engine import torch_import
from fossil_dsl.plan.compile import Plan, compile_spec
from fossil_dsl.kernel import Verdict, judge, not_certified
from fossil_dsl.kernel.prove import ATOMS_REFUTATION_FIRST
from fossil_dsl.outputs.region import region_report
from fossil_dsl.outputs.result import Result, build_result, claim_of
from fossil_dsl.solvers import registry
from fossil_dsl.solvers.fallback import FallbackBackend
from fossil_dsl.solvers.positivstellensatz import BEFORE_Z3_FROM
from fossil_dsl.ir.enclosure import import_codac
from fossil_dsl.ir.spec import CheckedSpec

# re-exported: specs built in Python are part of this API
__all__ = ["BespokeSet", "BuildError", "CheckResult", "OptionError", "build_spec", "check_file",
           "check_source", "check_text", "load", "loads", "parse", "spec_text", "synthesise"]


def synthesise(spec: CheckedSpec, progress=None, certificate=None, pieces=None,
               **options) -> Result:
    """Compile a checked spec and run CEGIS. `options` override the synthesis block:
    verifier, seed, max_iters, timeout, learning_rate, margin, digits, query_timeout,
    delta (precision of a delta-decision verifier), learn_only (train, report violation
    rates on fresh samples, prove nothing).
    `certificate` is a Certificate subclass to use instead of the registered one.
    `pieces` (cluster.pieces.LocalPieces or DaskPieces) splits the interval procedure's
    queries, in the loop and in the kernel, into pieces checked in parallel."""
    options = check_options(options)  # a bad value raises OptionError before any work
    plan = compile_spec(spec, certificate=certificate, **options)
    _import_run_libraries()
    started = time.monotonic()
    imports = torch_import.seconds_spent()
    backend = None if plan.options.learn_only else _backend(plan, pieces)
    plan, outcome = run_attempts(plan, backend, progress)
    started += torch_import.seconds_spent() - imports  # start-up, not the run's work
    verdict = _judge(plan, outcome, pieces, deadline=started + plan.options.timeout)
    found = None
    if plan.options.largest_region and verdict.certified:
        outcome, verdict, found = _largest(plan, outcome, verdict, pieces, started)
    result = build_result(plan, outcome, verdict, time.monotonic() - started)
    return replace(result, region=region_report(result, found)) if found else result


# Libraries a run's strategies and verifiers import on first use (the linearisation's
# Lyapunov and Riccati solvers, the sum-of-squares programs, the solvers). Imported
# before a run's clock starts, so that a run's time is its own work: 0.2-0.4 s of
# imports had been most of a sub-second run's time (docs/benchmarks.md, session 41).
# codac is not among them: it is imported by import_codac(), which keeps the rounding
# mode that codac's import changes; nor torch: only runs that learn import it
# (engine/torch_import.py), and the time that takes is left out of the run's.
RUN_LIBRARIES = ("scipy.linalg", "scipy.sparse", "clarabel", "cvc5", "z3")


def _import_run_libraries() -> None:
    for name in RUN_LIBRARIES:
        if importlib.util.find_spec(name.partition(".")[0]) is not None:
            importlib.import_module(name)
    if importlib.util.find_spec("codac") is not None:
        import_codac()


def _largest(plan: Plan, outcome, verdict: Verdict, pieces, started: float):
    """The outcome and verdict at the largest β the kernel proves (engine/region.py)."""
    deadline = started + plan.options.timeout

    def judge_at(claim):
        # the obligations together get at most what is left of the run (a level judged
        # past the deadline overran a 120 s run by 15 s; with a per-obligation bound,
        # by 3 s)
        return judge(claim, timeout=plan.options.query_timeout, delta=plan.options.delta,
                     pieces=pieces, deadline=deadline)
    found = largest_level(claim_of(plan, outcome), verdict, judge_at, deadline,
                          plan.options.seed)
    candidate = replace(outcome.candidate,
                        levels={**outcome.candidate.levels, "beta": found.level})
    return replace(outcome, candidate=candidate), found.verdict, found


def _judge(plan: Plan, outcome, pieces=None, deadline: float | None = None) -> Verdict:
    """The kernel's verdict on the engine's final formulas (judged afresh from the spec
    and those formulas alone; the engine's own answers are not used), within what is
    left of the run's timeout: the language's `timeout` is for the whole run (f1_barr3
    certified in 122 s of a 120 s run when the judgement had a bound per obligation
    only)."""
    if not outcome.certified:
        return not_certified(outcome.reason)
    verdict = judge(claim_of(plan, outcome), timeout=plan.options.query_timeout,
                    delta=plan.options.delta, pieces=pieces, deadline=deadline)
    if not verdict.certified and deadline is not None and time.monotonic() >= deadline:
        return replace(verdict, reason=f"the run's timeout ({plan.options.timeout:g} s) "
                       f"passed while the kernel judged the final candidate: "
                       f"{verdict.reason}")
    return verdict


def _backend(plan: Plan, pieces=None):
    """The plan's verifier, raced by its fallback where it has one. For polynomial
    problems a sum-of-squares refutation is tried too: before the solvers from
    BEFORE_Z3_FROM states on, else by the fallback before its own procedure (so only
    once Z3 has not answered at once: a 4-state quadratic condition stalled Z3 for 60 s).
    CVC5 joins the race for polynomial problems half a second after the fallback: it
    found at once the counterexample to a 4-state quadratic decrease condition on which
    Z3 and the interval search each spent 30 s without an answer (given the head start
    over the fallback, it cost the portfolio's reach-type rows 1 to 3 s of verifying).
    Problems with elementary functions get the refutation first (through the queries'
    polynomial form) from ATOMS_REFUTATION_FIRST states on, where bisection slows down."""
    from fossil_dsl.solvers.refutation_first import RefutationFirst

    def load(name: str):
        backend = registry.load(name, plan.options.delta, search=True)
        return SplitBackend(backend, pieces) if pieces and name == "interval" else backend
    backend = load(plan.verifier)
    polynomial, many = plan.verifier == "z3", len(plan.states) >= BEFORE_Z3_FROM
    if plan.fallback:
        fallback = load(plan.fallback)
        if polynomial and not many:
            fallback = RefutationFirst(fallback)
        if polynomial and plan.fallback != "cvc5" and registry.is_installed("cvc5"):
            fallback = FallbackBackend(fallback, registry.load("cvc5"))
        backend = FallbackBackend(backend, fallback)
    atoms_first = not polynomial and len(plan.states) >= ATOMS_REFUTATION_FIRST
    return RefutationFirst(backend) if (polynomial and many) or atoms_first else backend
