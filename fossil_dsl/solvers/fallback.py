"""A complete solver first, and a delta-decision verifier alongside it where the first
does not answer at once.

Z3 decides polynomial arithmetic completely, but on hard nonlinear queries (a degree-4
decrease condition in 3 states, say) it can run for a long time. The interval verifier
often refutes the same query in a fraction of a second: its UNSAT is a proof as well, and
its delta-SAT a counterexample to learn from. So the first solver runs alone for
HEAD_START seconds (most of its answers come sooner); then the second starts on the same
query in this thread while the first goes on in its own, and the first definite answer
(SAT or UNSAT) wins and stops the other. Each answer names the solver that gave it.

CEGIS asks the same condition again after each learning step, with new weights. Once the
second solver has won on a query of some form, later queries of that form (the same
formula with other numbers) give it the head start instead.
"""
from __future__ import annotations

import threading
import time
from dataclasses import replace
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Backend, Status

HEAD_START = 0.5  # s the leading solver runs alone before the other joins it
# s past the race's time limit after which a leader that has not returned is left behind
# (its thread is a daemon): a Z3 check that does not heed its interrupt must not hold
# the run past its own timeout
ABANDON_AFTER = 5.0


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
        if answers["leader"].status is not Status.UNKNOWN:
            finished.set()

    thread = threading.Thread(target=lead, daemon=True)
    thread.start()
    relay = _relay(stop, finished) if stop is not None else None
    thread.join(min(HEAD_START, timeout))
    if not finished.is_set():
        left = max(0.0, timeout - (time.monotonic() - started))
        answers["follower"] = _ask(follower, formula, variables, left, finished)
        if answers["follower"].status is not Status.UNKNOWN:
            finished.set()
    thread.join(max(0.0, started + timeout + ABANDON_AFTER - time.monotonic()))
    finished.set()  # ends the relay
    if relay is not None:
        relay.join()
    answered = dict(answers)  # a leader left behind may still write its answer
    if "leader" not in answered:
        answered["leader"] = Answer(Status.UNKNOWN, reason=f"{leader.name} had not stopped "
                                    f"{ABANDON_AFTER:g} s past its time limit; left behind")
    return _outcome(leader, follower, answered)


def _relay(stop: threading.Event, finished: threading.Event) -> threading.Thread:
    """Passes a stop from outside on to both solvers."""
    def watch():
        while not finished.wait(0.05):
            if stop.is_set():
                finished.set()
    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    return thread


def _outcome(leader, follower, answers) -> tuple[Answer, Backend | None]:
    lead, follow = answers["leader"], answers.get("follower")
    if lead.status is not Status.UNKNOWN:
        return lead, leader
    if follow is not None and follow.status is not Status.UNKNOWN:
        return replace(follow, reason=f"{leader.name} had not answered "
                       f"({lead.reason}); {follow.reason or 'decided'} by {follower.name}"), \
            follower
    reasons = [f"{leader.name}: {lead.reason}"]
    if follow is not None:
        reasons.append(f"{follower.name}: {follow.reason}")
    return Answer(Status.UNKNOWN, reason="; ".join(reasons)), None


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
