"""The box that contraction leaves of the whole space: a query's hull, for splitting it
(kernel/cover.py) and for placing a ball inside it (ball_split.py)."""
from __future__ import annotations

from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import upward_rounding
from fossil_dsl.solvers.api import UnsupportedTheory
from fossil_dsl.solvers.codac_compiler import Compiler
from fossil_dsl.solvers.interval_backend import _contract_to_fixpoint


def hull(formula: L.Formula, names: Sequence[str]) -> list[tuple[float, float]] | None:
    """The box contraction leaves of the whole space (outward-rounded), per name; None
    if it is empty or unbounded, or the formula is outside the procedure's theory."""
    with upward_rounding() as codac:
        try:
            contractor = Compiler(codac, names).formula(formula)
        except UnsupportedTheory:
            return None
        if contractor is None:
            return None
        box = codac.IntervalVector([[-codac.oo, codac.oo]] * len(names))
        _contract_to_fixpoint(contractor, box, len(names), passes=5)
        if box.is_empty() or box.is_unbounded():
            return None
        return [(box[i].lb(), box[i].ub()) for i in range(len(names))]
