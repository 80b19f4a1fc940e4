"""A complete solver first, and a delta-decision verifier alongside it where the first
does not answer at once.

Z3 decides polynomial arithmetic completely, but on hard nonlinear queries (a degree-4
decrease condition in 3 states, say) it can run for a long time. The interval verifier
often refutes the same query in a fraction of a second: its UNSAT is a proof as well, and
its delta-SAT a counterexample to learn from. So the first solver runs alone for
HEAD_START seconds (most of its answers come sooner); then the second starts on the same
query in this thread while the first goes on in its own, and the first definite answer
(SAT or UNSAT) wins and stops the other. Each answer names the solver that gave it.

A delta-SAT point where a polynomial query is false when evaluated exactly is no answer:
near the origin, where a decrease V(f(x)) - V(x) < 0 is of order |x|^2, the interval
procedure's boxes of width 1e-4 are never refuted, and such points won the race every
iteration (probe43/x06: 20 iterations, each learning from a point at 1e-4 of the origin,
before CVC5 proved the condition in 4 s). After one, the other solver is waited for (at
most SPURIOUS_WAIT seconds). If it gives no answer either, the answer is UNKNOWN: the
query is undecided, and the point, which is no counterexample, comes with it only as a
lead for the learner.

CEGIS asks the same condition again after each learning step, with new weights. Once the
second solver has won on a query of some form, later queries of that form (the same
formula with other numbers) give it the head start instead.
"""
from __future__ import annotations

import threading
import time
from dataclasses import replace
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Backend, Status

HEAD_START = 0.5  # s the leading solver runs alone before the other joins it
# s past the race's time limit after which a leader that has not returned is left behind
# (its thread is a daemon): a Z3 check that does not heed its interrupt must not hold
# the run past its own timeout
ABANDON_AFTER = 5.0
SPURIOUS_WAIT = 15.0  # s the other solver is still given after a point that is no answer


class FallbackBackend:
    def __init__(self, first: Backend, second: Backend):
        self.first, self.second = first, second
        self.name = f"{first.name}, then {second.name}"
        self.second_decides: set[tuple] = set()

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop: threading.Event | None = None) -> Answer:
        form = _form(formula)
        order = (self.second, self.first) if form in self.second_decides \
            else (self.first, self.second)
        answer, winner = _race(*order, formula, variables, timeout, stop)
        if winner is self.second:
            self.second_decides.add(form)
        elif winner is self.first:
            self.second_decides.discard(form)
        return answer


def _race(leader: Backend, follower: Backend, formula, variables, timeout: float,
          stop: threading.Event | None) -> tuple[Answer, Backend | None]:
    """The first definite answer of the two solvers, and which gave it (None if neither
    did). The leader runs alone for HEAD_START seconds, then both run."""
    started = time.monotonic()
    finished = threading.Event()  # set when one solver has answered for good
    answers: dict[str, Answer] = {}

    def lead():
        answers["leader"] = _ask(leader, formula, variables, timeout, finished)
        if definite(answers["leader"], formula):
            finished.set()

    thread = threading.Thread(target=lead, daemon=True)
    thread.start()
    relay = _relay(stop, finished) if stop is not None else None
    thread.join(min(HEAD_START, timeout))
    if not finished.is_set():
        left = max(0.0, timeout - (time.monotonic() - started))
        answers["follower"] = _ask(follower, formula, variables, left, finished)
        if definite(answers["follower"], formula):
            finished.set()
    wait = max(0.0, started + timeout + ABANDON_AFTER - time.monotonic())
    if answers.get("follower", Answer(Status.UNKNOWN)).status is Status.SAT:
        wait = min(wait, SPURIOUS_WAIT)  # a point that is no answer: not the whole time
    thread.join(wait)
    finished.set()  # ends the relay
    if relay is not None:
        relay.join()
    answered = dict(answers)  # a leader left behind may still write its answer
    if "leader" not in answered:
        answered["leader"] = Answer(Status.UNKNOWN, reason=f"{leader.name} had not stopped "
                                    f"{ABANDON_AFTER:g} s past its time limit; left behind")
    return _outcome(leader, follower, answered, formula)


def _relay(stop: threading.Event, finished: threading.Event) -> threading.Thread:
    """Passes a stop from outside on to both solvers."""
    def watch():
        while not finished.wait(0.05):
            if stop.is_set():
                finished.set()
    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    return thread


def _outcome(leader, follower, answers, formula) -> tuple[Answer, Backend | None]:
    lead, follow = answers["leader"], answers.get("follower")
    if definite(lead, formula):
        return lead, leader
    if follow is not None and definite(follow, formula):
        return replace(follow, reason=f"{leader.name} had not answered "
                       f"({lead.reason}); {follow.reason or 'decided'} by {follower.name}"), \
            follower
    for point in (lead, follow):  # no answer, but a point to learn from is worth having
        if point is not None and point.status is Status.SAT:
            return replace(point, status=Status.UNKNOWN, reason=f"{point.reason} (not a "
                           "solution when evaluated exactly; neither solver decided)"), None
    reasons = [f"{leader.name}: {lead.reason}"]
    if follow is not None:
        reasons.append(f"{follower.name}: {follow.reason}")
    return Answer(Status.UNKNOWN, reason="; ".join(reasons)), None


def definite(answer: Answer, formula: L.Formula) -> bool:
    """UNSAT, or SAT at a point where the formula holds exactly, or cannot be evaluated
    exactly (it has functions such as sin): not a point where it is exactly false."""
    if answer.status is Status.UNSAT:
        return True
    if answer.status is not Status.SAT or not answer.model:
        return answer.status is Status.SAT
    try:
        exact = {name: E.Num(Fraction(value)) for name, value in answer.model.items()}
    except (TypeError, ValueError):  # a value that is no rational number: not judged
        return True
    return L.truth(L.substitute(formula, exact)) is not False


def _ask(backend: Backend, formula, variables, timeout: float, stop) -> Answer:
    answer = backend.check(formula, variables, timeout, stop)
    return replace(answer, solver=answer.solver or backend.name)


def _form(formula: L.Formula) -> tuple:
    """The formula with its numbers left out: what stays the same from one CEGIS
    iteration to the next."""
    parts: list = []
    stack: list = [formula]
    while stack:
        node = stack.pop()
        if isinstance(node, L.Compare):
            parts.append(node.relation)
            stack.extend((node.left, node.right))
        elif isinstance(node, L.Formula):
            parts.append(type(node).__name__)
            stack.extend(L.children(node))
        else:
            parts.append(node.name if isinstance(node, E.Var) else node.func
                         if isinstance(node, E.Apply) else
                         None if isinstance(node, E.Num) else type(node).__name__)
            stack.extend(E.children(node))
    return tuple(parts)
