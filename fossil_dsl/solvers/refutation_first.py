"""A sum-of-squares refutation before another procedure (sos_refutation.py), and the
query left beyond the ball round the origin where one is found there (ball_split.py)."""
from __future__ import annotations

import time
from dataclasses import replace
from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status
from fossil_dsl.solvers.ball_split import SEARCH_SHARE, excluded_radius, split_query
from fossil_dsl.solvers.sos_refutation import SosBackend

REFUTATION_SHARE = 0.25  # of a query's time, at most, for the refutation before the solver


class RefutationFirst:
    """A sum-of-squares refutation first, then `backend` with the time left: for
    polynomial problems, where Z3 stalls on what a small semidefinite program proves at
    once (an 8-state quadratic's positivity: no answer from Z3 in 50 s). The learning
    loop puts it before Z3 from BEFORE_Z3_FROM states, else before the fallback's own
    procedure (frontends/api.py). Counterexamples still come from `backend` alone. A
    query that leaves out a ball round the origin goes to `backend` without the ball
    inside which a refutation is found (ball_split.py), where there is one."""

    def __init__(self, backend):
        self.backend = backend
        self.name = f"{SosBackend.name}, then {backend.name}"

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop=None) -> Answer:
        started = time.monotonic()
        answer = SosBackend().check(formula, variables, REFUTATION_SHARE * timeout, stop)
        if answer.status is Status.UNSAT:
            return answer
        if excluded_radius(formula, variables) is not None:  # where bisection is slow
            left = timeout - (time.monotonic() - started)
            formula = split_query(formula, variables,
                                  time.monotonic() + SEARCH_SHARE * max(0.0, left))[0]
        left = max(0.0, timeout - (time.monotonic() - started))
        answer = self.backend.check(formula, variables, left, stop)
        # named after the procedure that answered, which the kernel then tries first
        return replace(answer, solver=answer.solver or self.backend.name)
