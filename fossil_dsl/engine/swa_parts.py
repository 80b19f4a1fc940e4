"""Stable while avoid from its two parts, found apart: V and β for I's region of
attraction (the linearisation's quadratic V, quadratic_roa.py, then the program of
sos_roa.py) and B for I's safety against U (the barrier program, sos_barrier.py).

Why: quadratic_roa.py takes B = V - β, a barrier only where Ω misses U; an ellipsoid
round the origin that holds a dose far off in one direction reaches as far the other
way (probe69/as16, five compartments after an oral dose: Ω meets the toxic half-space
that the trajectories never come near, while the barrier program finds a quadratic B in
0.2 s). Nothing here is trusted: the pair is proved like any candidate.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field, replace

from fossil_dsl.engine import quadratic_roa, sos_roa
from fossil_dsl.engine.sos_barrier import barrier
from fossil_dsl.engine.proving import budgets
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, compile_spec, variant_plan

FORM = "stable while avoid"
SECONDS, SHARE = 30.0, 0.25  # for the programs: at most, and of the run's time
REFUTING_SECONDS = 5.0  # of refutations at least (twice the program's time if more)


@dataclass(frozen=True)
class PartsFinding:
    formulas: dict  # "V", "B" -> exact formulas
    levels: dict  # "beta" -> Fraction
    operating: object
    seconds: float
    reaches_boundary: bool  # Ω meets ∂D: the kernel's variant (inward_rules.py)
    found: str  # how V and B were found
    stand_in: int = 0  # the degree of the field's stand-in V was found for (0: none)
    controller: dict = field(default_factory=dict)  # (no inputs: none)
    gain: None = None

    def describe(self) -> str:
        return self.found


def applies(plan: Plan) -> bool:
    return plan.certificate.form == FORM and not plan.spec.inputs \
        and plan.spec.time is TimeDomain.CONTINUOUS and quadratic_roa.applies(plan)


def attempt(plan: Plan, backend, listener, deadline: float, prove):
    """((plan with V and B given, β fixed, certified outcome) or None, what happened);
    `prove` is region_attempts.py's proof of a region's finding (with the Taylor lemma's ball,
    else the plan's own), given the refutations' and queries' seconds."""
    listener.phase(0, "V and B found apart")
    budget = time.monotonic() + min(SECONDS, SHARE * plan.options.timeout)
    for finding in findings(plan, budget):
        proved = variant_plan(plan) or plan if finding.reaches_boundary else plan
        found, _ = prove(proved, backend, listener, deadline, finding,
                         *budgets(finding, REFUTING_SECONDS, deadline))
        if found is not None:
            return found, ""
    return None, "no V and B found apart proved"


def findings(plan: Plan, deadline: float):
    """V and β of I's region of attraction (the linearisation's quadratic V, then the
    region-of-attraction program's) with the barrier program's B, in turn."""
    started = time.monotonic()
    found = barrier(plan, deadline)
    if found is None:
        return
    region = _region_plan(plan)
    quadratic = itertools.islice(quadratic_roa.candidates(region, deadline), 1)
    for finding in itertools.chain(quadratic, _program(region, deadline)):
        if finding is None:
            continue
        yield PartsFinding({"V": finding.formulas["V"], "B": found.formula},
                           dict(finding.levels), finding.operating,
                           time.monotonic() - started,
                           getattr(finding, "reaches_boundary", False),
                           f"V: {finding.describe()}; B: {found.describe()}",
                           getattr(finding, "stand_in", 0))


def _program(region: Plan, deadline: float):
    """The region-of-attraction program's finding (or None), only when asked for."""
    if sos_roa.applies(region):
        yield sos_roa.search(region, deadline)


def _region_plan(plan: Plan) -> Plan:
    """The plan of `from I: stable` for the same system, I and D."""
    spec = plan.spec
    roles = {k: v for k, v in spec.property.roles.items() if k in ("domain", "initial")}
    return compile_spec(replace(spec, property=replace(
        spec.property, form="region of attraction", roles=roles)), seed=plan.options.seed)
