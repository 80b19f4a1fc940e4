"""What every verifier backend offers: satisfiability of a neutral formula, with a
model when SAT, and honest UNKNOWN (with its reason) otherwise."""
from __future__ import annotations

import threading
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from typing import Mapping, Protocol, Sequence

from fossil_dsl.diagnostics import FslError
from fossil_dsl.ir.logic import Formula


class Status(Enum):
    SAT = "sat"
    UNSAT = "unsat"
    UNKNOWN = "unknown"


@dataclass(frozen=True)
class Answer:
    status: Status
    model: Mapping[str, Fraction] | None = None
    reason: str = ""
    # True if the query bounded irrational constants by intervals, or if the model has
    # irrational coordinates that are reported as nearby rationals
    approximate: bool = False
    solver: str = ""  # which solver answered, where a backend combines several
    evidence: object = None  # what proves an UNSAT where the backend has it (a refutation)


class UnsupportedTheory(FslError):
    """The backend cannot express part of the formula (for example sin(x) in Z3)."""


class Backend(Protocol):
    name: str

    def check(self, formula: Formula, variables: Sequence[str], timeout: float,
              stop: threading.Event | None = None) -> Answer:
        """Is `formula` satisfiable over the reals? `variables` are reported in the model.
        Once `stop` is set (from another thread), the backend should give up soon, with
        UNKNOWN: another solver has answered."""
        ...
