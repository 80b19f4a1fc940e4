"""The loop's interval verifier on split queries: each query is cut into the pieces of a
cover (kernel/cover.py, the cover checked as the kernel checks it), the pieces checked
in parallel by a checker (cluster/pieces.py); the first piece with a point gives the
counterexample and stops the rest."""
from __future__ import annotations

import threading
from dataclasses import replace
from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.kernel import cover
from fossil_dsl.solvers.api import Answer, Backend, Status


class SplitBackend:
    def __init__(self, inner: Backend, pieces):
        self.inner, self.pieces = inner, pieces
        self.name = inner.name
        self.delta = getattr(inner, "delta", None)

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop: threading.Event | None = None) -> Answer:
        names = [v for v in variables if v in L.free_vars(formula)]
        split = cover.check_split(formula, names, self.pieces, timeout, self.delta)
        if split is None:
            return self.inner.check(formula, variables, timeout, stop)
        answer = split.answer
        model = None if answer.model is None else \
            {v: answer.model[v] for v in variables if v in answer.model}
        reason = f"a piece of {split.pieces}: {answer.reason}" \
            if answer.status is Status.UNKNOWN else answer.reason
        return replace(answer, model=model, reason=reason, solver=self.name)
