"""An obligation as a complete SMT-LIB 2 script (unsat means it holds): what `-o DIR`
writes and what `fossilc recheck` derives again and compares with."""
from __future__ import annotations

from typing import Sequence

from fossil_dsl.kernel.obligations import Obligation
from fossil_dsl.solvers.api import UnsupportedTheory
from fossil_dsl.solvers.smtlib import query_text


def script(obligation: Obligation, states: Sequence[str], spec_name: str) -> str:
    comments = [f"{spec_name}: {obligation.name}: {obligation.text}",
                "unsat means the obligation holds"]
    try:
        return query_text(obligation.query, states, comments=comments)
    except UnsupportedTheory as exc:  # e.g. a power SMT-LIB cannot write
        return f"; {comments[0]}\n; not expressible in SMT-LIB 2: {exc}\n"
