"""The loop's interval verifier on split queries: each query is cut into the pieces of a
cover (kernel/cover.py, the cover checked as the kernel checks it), the pieces checked
in parallel by a checker (cluster/pieces.py); the first piece with a point gives the
counterexample and stops the rest."""
from __future__ import annotations

import threading
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
        hull = cover.hull_of(formula, names)
        boxes = cover.bisected(hull, self.pieces.pieces) if hull is not None else []
        if hull is None or cover.covers(hull, boxes):
            return self.inner.check(formula, variables, timeout, stop)
        regions = cover.regions(names, hull, boxes)
        answers = self.pieces.check_all(formula, regions, names, timeout, self.delta)
        if len(answers) != len(regions):
            return Answer(Status.UNKNOWN, reason="a piece was not answered", solver=self.name)
        found = next((a for a in answers if a.status is Status.SAT), None)
        if found is not None:
            model = {v: found.model[v] for v in variables if found.model and v in found.model}
            return Answer(Status.SAT, model, found.reason, found.approximate, self.name)
        if all(a.status is Status.UNSAT for a in answers):
            return Answer(Status.UNSAT, solver=self.name)
        unknown = next(a for a in answers if a.status is Status.UNKNOWN)
        return Answer(Status.UNKNOWN, reason=f"a piece of {len(answers)}: {unknown.reason}",
                      solver=self.name)
