"""A complete solver first, and a delta-decision verifier where it gives up.

Z3 decides polynomial arithmetic completely, but on hard nonlinear queries (a degree-4
decrease condition in 3 states, say) it can run out of time. The interval verifier then
often refutes the same query in seconds: its UNSAT is a proof as well, and its delta-SAT
a counterexample to learn from. Each answer names the solver that gave it.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.smt.api import Answer, Backend, Status

FIRST_SHARE = 0.25  # of the query's time budget that the first solver gets


class FallbackBackend:
    def __init__(self, first: Backend, second: Backend):
        self.first, self.second = first, second
        self.name = f"{first.name}, then {second.name}"

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float) -> Answer:
        answer = self.first.check(formula, variables, timeout * FIRST_SHARE)
        if answer.status is not Status.UNKNOWN:
            return replace(answer, solver=answer.solver or self.first.name)
        second = self.second.check(formula, variables, timeout * (1 - FIRST_SHARE))
        if second.status is Status.UNKNOWN:
            return Answer(Status.UNKNOWN, reason=f"{self.first.name}: {answer.reason}; "
                          f"{self.second.name}: {second.reason}")
        return replace(second, solver=second.solver or self.second.name,
                       reason=f"{self.first.name} gave up ({answer.reason}); "
                       f"{second.reason or 'decided'} by {self.second.name}")
