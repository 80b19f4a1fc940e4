"""A query whose elementary functions all act on one state, refuted slab by slab across it.

Why: a 6-state planar quadrotor's decrease condition (probe65/ao10: sin and cos of the
pitch th, a quadratic V that decreases at every sample with a thin margin near th =
0.44) is neither refuted whole (the facts about sin and cos over th's whole range are too
loose) nor by bisection (244 000 boxes in 60 s were not enough: boxes must be narrow in
all six directions). Cut along th alone, each slab's range is narrow, the Taylor facts
(taylor_facts.py) hold sin and cos within 2e-4 there, and each slab's piece has a
refutation of its own: the other five directions are settled by the program, not by
boxes.

Slabs of width at most WIDEST are tried first, across the state's range from the query's
own conjuncts, the outermost first; one without a refutation is halved, down to NARROWEST
(then the split fails: the rest is not tried), and the split is given up as soon as the
slabs left would not be done by the deadline at the pace so far. The outermost slabs are
open (v <= e_1, v >= e_K), so the pieces cover every point whatever the range;
positivstellensatz.SlabSplit checks the refutations, exactly, against pieces it computes
itself from the query and the edges.
"""
from __future__ import annotations

import math
import time
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.atom_facts import argument_range, replaceable
from fossil_dsl.solvers.positivstellensatz import SlabSplit, slab
from fossil_dsl.solvers.sos_refutation import refute

WIDEST = Fraction(1, 5)  # the slabs first tried are at most this wide
NARROWEST = Fraction(1, 20)  # a slab this narrow without a refutation: the split fails
GRID = 1000  # edges are multiples of 1/GRID
ATOMS_LIMIT = 12_000  # the largest program for a slab (ao10's: up to 8 000 variables)
FROM_STATES = 4  # below this, bisection refutes such queries well enough


def slab_variable(query: L.Formula, states: Sequence[str]) -> str | None:
    """The one state that every function application's argument depends on (sin and
    cos of a pitch angle), where the query has at least FROM_STATES states; else None."""
    if len(states) < FROM_STATES:
        return None
    found = set()
    for comparison in L.comparisons(query):
        for side in (comparison.left, comparison.right):
            for node in E.walk(side):
                if replaceable(node):
                    found |= E.free_vars(node.arg)
    return found.pop() if len(found) == 1 and found <= set(states) else None


def refuted_in_slabs(query: L.Formula, states: Sequence[str], deadline: float,
                     atoms_limit: int = ATOMS_LIMIT) -> SlabSplit | None:
    """Refutations of the query's slabs across its slab variable, or None (no such
    variable, no bounded range, a slab NARROWEST wide not refuted, or the deadline)."""
    variable = slab_variable(query, states)
    reach = None if variable is None else argument_range(query, E.Var(variable))
    if reach is None or not reach[0] < reach[1]:
        return None
    low, high = reach
    count = max(1, math.ceil((high - low) / WIDEST))
    edges = sorted({_on_grid(low + (high - low) * k / count) for k in range(1, count)})
    ends = [None, *edges, None]
    # the outermost slabs first, where the field bends most from its linearisation and
    # a refutation is likeliest to fail (then nothing more is tried)
    pending = sorted(zip(ends, ends[1:]), key=lambda ends_: _distance(ends_, low, high))
    found: dict = {}
    started, tried = time.monotonic(), 0
    while pending:
        now = time.monotonic()
        if now > deadline or (tried and (now - started) / tried * len(pending) > deadline - now):
            return None  # (at the pace so far, the slabs left would not be done in time)
        lower, upper = pending.pop()
        tried += 1
        refutation = refute(slab(query, variable, lower, upper), states, deadline,
                            atoms_limit)
        if refutation is not None:
            found[lower] = (upper, refutation)
            continue
        bottom, top = low if lower is None else lower, high if upper is None else upper
        middle = _on_grid((bottom + top) / 2)
        if top - bottom < 2 * NARROWEST or not bottom < middle < top:
            return None
        pending += [(middle, upper), (lower, middle)]
    ordered = [found[lower] for lower in sorted(found, key=lambda e: -math.inf if e is None
                                                else e)]
    return SlabSplit(variable, tuple(upper for upper, _ in ordered[:-1]),
                     tuple(refutation for _, refutation in ordered))


def _distance(ends, low: Fraction, high: Fraction) -> Fraction:
    """How far the slab's middle lies from the origin (the open ends at the range's)."""
    lower, upper = ends
    return abs((low if lower is None else lower) + (high if upper is None else upper))


def _on_grid(value: Fraction) -> Fraction:
    return Fraction(round(value * GRID), GRID)
