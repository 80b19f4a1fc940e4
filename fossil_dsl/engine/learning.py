"""The learning loop as a run meets it after the engine's own attempts: the loop with the
compiler's templates; where they give up (every iteration used, time left), the loop
again with quartic templates in their place; for a function the user gave, its check
against the variant of the kernel's rule as well. The kernel judges whatever comes back."""
from __future__ import annotations

import time
from dataclasses import replace

from fossil_dsl.engine import torch_import, unstable_origin
from fossil_dsl.engine.given import verifier_only
from fossil_dsl.engine.loop import Cegis, CegisOutcome
from fossil_dsl.plan.compile import Plan, richer_plan, variant_plan
from fossil_dsl.solvers.api import Backend

# seconds left, at least, for a run with quartic templates to be worth starting
RICHER_MIN_SECONDS = 5.0
# before a costly program: the loop's first iteration, within this many seconds
BRIEF_ITERATIONS, BRIEF_SECONDS = 1, 5.0


def learn(plan: Plan, backend: Backend, listener, deadline: float,
          note: str = "") -> tuple[Plan, CegisOutcome]:
    """The plan that was run and its outcome; `note` says what the attempts before found."""
    deadline += learning_imported(plan)
    outcome = Cegis(plan, backend, listener, deadline).run()
    variant = variant_plan(plan) if verifier_only(plan) and not outcome.certified else None
    if variant is not None:  # a given function may meet the variant's conditions instead
        other = Cegis(variant, backend, listener, deadline).run()
        if other.certified:
            return variant, replace(other, strategy="given function")
    richer = richer_plan(plan) if _gave_up(plan, outcome, deadline) else None
    if richer is not None:
        listener.phase(0, "learning again with quartic templates")
        other = Cegis(richer, backend, listener, deadline).run()
        if other.certified:
            return richer, _after(outcome, other, note)
        note = "; ".join(n for n in (note, f"quartic templates: {other.reason}") if n)
    marginal = None if outcome.certified else unstable_origin.marginal_note(plan)
    return plan, replace(outcome, strategy="learning" + (f" ({note})" if note else ""),
                         reason=outcome.reason + (f" ({marginal})" if marginal else ""))


def learn_briefly(plan: Plan, backend: Backend, listener, deadline: float):
    """The outcome of the learning loop's first BRIEF_ITERATIONS iterations (at most
    BRIEF_SECONDS) where they certify, else None: the template seeded with the
    linearisation's quadratic is often the proof at once (probe44/y13 in 1.3 s, where
    the closed loop's barrier program tried first took 28 s)."""
    listener.phase(0, "learning, first iteration")
    brief = replace(plan, options=replace(plan.options, max_iters=BRIEF_ITERATIONS))
    until = min(deadline, time.monotonic() + BRIEF_SECONDS) + learning_imported(plan)
    outcome = Cegis(brief, backend, listener, until).run()
    return (plan, replace(outcome, strategy="learning")) if outcome.certified else None


def learning_imported(plan: Plan) -> float:
    """Seconds spent importing torch for the loop's learning (0 where it learns nothing,
    or torch was in already): start-up, which the loop's deadline is moved on by."""
    if verifier_only(plan):
        return 0.0
    before = torch_import.seconds_spent()
    torch_import.learning_support()
    return torch_import.seconds_spent() - before


def _gave_up(plan: Plan, outcome: CegisOutcome, deadline: float) -> bool:
    """Whether the loop used every iteration without a certificate, time left over."""
    return (not outcome.certified and not outcome.interrupted
            and len(outcome.history) >= plan.options.max_iters
            and deadline - time.monotonic() > RICHER_MIN_SECONDS)


def _after(first: CegisOutcome, second: CegisOutcome, note: str) -> CegisOutcome:
    """The second run's outcome with the first run's iterations and time before its own."""
    offset = len(first.history)
    history = first.history + tuple(replace(r, iteration=r.iteration + offset)
                                    for r in second.history)
    words = "; ".join(n for n in (note, "the quadratic templates gave up") if n)
    return replace(second, history=history,
                   learn_seconds=first.learn_seconds + second.learn_seconds,
                   verify_seconds=first.verify_seconds + second.verify_seconds,
                   strategy=f"learning with quartic templates ({words})")
