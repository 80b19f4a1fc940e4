"""A complete solver first, and a delta-decision verifier where it gives up.

Z3 decides polynomial arithmetic completely, but on hard nonlinear queries (a degree-4
decrease condition in 3 states, say) it can run out of time. The interval verifier then
often refutes the same query in seconds: its UNSAT is a proof as well, and its delta-SAT
a counterexample to learn from. Each answer names the solver that gave it.

CEGIS asks the same condition again after each learning step, with new weights. Once the
first solver has given up on a query of some form and the second has decided it, later
queries of that form (the same formula with other numbers) go to the second solver first.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.smt.api import Answer, Backend, Status

FIRST_SHARE = 0.1  # of the query's time budget that the first solver gets


class FallbackBackend:
    def __init__(self, first: Backend, second: Backend):
        self.first, self.second = first, second
        self.name = f"{first.name}, then {second.name}"
        self.second_decides: set[tuple] = set()

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float) -> Answer:
        form = _form(formula)
        if form in self.second_decides:
            answer = self._ask(self.second, formula, variables, timeout * (1 - FIRST_SHARE))
            if answer.status is not Status.UNKNOWN:
                return answer
            self.second_decides.discard(form)
            return self._ask(self.first, formula, variables, timeout * FIRST_SHARE)
        answer = self._ask(self.first, formula, variables, timeout * FIRST_SHARE)
        if answer.status is not Status.UNKNOWN:
            return answer
        second = self._ask(self.second, formula, variables, timeout * (1 - FIRST_SHARE))
        if second.status is Status.UNKNOWN:
            return Answer(Status.UNKNOWN, reason=f"{self.first.name}: {answer.reason}; "
                          f"{self.second.name}: {second.reason}")
        self.second_decides.add(form)
        return replace(second, reason=f"{self.first.name} gave up ({answer.reason}); "
                       f"{second.reason or 'decided'} by {self.second.name}")

    @staticmethod
    def _ask(backend: Backend, formula: L.Formula, variables, timeout: float) -> Answer:
        answer = backend.check(formula, variables, timeout)
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
