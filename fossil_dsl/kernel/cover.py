"""Split verification: a query is unsatisfiable if each piece of a cover of the whole
space is.

The pieces are the query in each box of a bisection of a hull H (any box: it need not
contain the query's set) and one more piece, the query outside H. They are checked in parallel by
whoever the caller hands them to (local processes, Dask workers); what makes their
UNSATs a proof is that the pieces cover every point, and that is checked here, exactly,
rather than assumed from how they were made:

- every box has positive width in every direction and lies inside H;
- their interiors are pairwise disjoint, and their volumes add up to H's;

so their union is a closed set dense in H, hence H itself. A point outside H is in the
last piece, whose formula is the query and "some coordinate is outside H's interval".
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from math import prod
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status

Box = tuple[tuple[Fraction, Fraction], ...]  # (low, high) per variable


@dataclass(frozen=True)
class Split:
    pieces: int  # how many the query was cut into
    answer: Answer  # UNSAT only if the cover checks and every piece is refuted


def check_split(query: L.Formula, names: Sequence[str], pieces, timeout: float,
                delta: float | None) -> Split | None:
    """The query cut into a checked cover and its pieces checked by `pieces` (cluster/
    pieces.py); None where the query has no bounded hull to cut (check it whole)."""
    hull = hull_of(query, names)
    if hull is None:
        return None
    boxes = bisected(hull, pieces.pieces)
    count = len(boxes) + 1
    problem = covers(hull, boxes)
    if problem:
        return Split(count, Answer(Status.UNKNOWN, reason=f"not a cover: {problem}"))
    where = regions(names, hull, boxes)
    answers = pieces.check_all(query, where, names, timeout, delta)
    if len(answers) != len(where):
        return Split(count, Answer(Status.UNKNOWN,
                                   reason=f"{len(answers)} answers for {count} pieces"))
    # a piece with a point says more than one stopped because of it
    failed = next((a for a in answers if a.status is Status.SAT), None) or \
        next((a for a in answers if a.status is not Status.UNSAT), None)
    return Split(count, failed or Answer(Status.UNSAT))


def hull_of(query: L.Formula, names: Sequence[str]) -> Box | None:
    """A box round what interval contraction leaves of the query, a little wider (so the
    piece outside it is refuted at once); None if none is bounded. Any box would do: it
    only decides where the cuts fall."""
    from fossil_dsl.solvers.interval_hull import hull
    found = hull(query, names) if names else None
    if found is None:
        return None
    box = []
    for low, high in found:
        margin = Fraction(max(1e-9, 1e-6 * (high - low)))
        box.append((Fraction(low) - margin, Fraction(high) + margin))
    return tuple(box)


def bisected(hull: Box, count: int) -> list[Box]:
    """At least `count` boxes: H halved again and again across its widest side."""
    boxes = [hull]
    while len(boxes) < count:
        box = max(boxes, key=lambda b: max(hi - lo for lo, hi in b))
        boxes.remove(box)
        side = max(range(len(box)), key=lambda i: box[i][1] - box[i][0])
        low, high = box[side]
        middle = (low + high) / 2
        boxes += [box[:side] + ((low, middle),) + box[side + 1:],
                  box[:side] + ((middle, high),) + box[side + 1:]]
    return boxes


def covers(hull: Box, boxes: Sequence[Box]) -> str:
    """"" if the boxes cover H exactly (as the docstring above argues), else why not."""
    if any(hi <= lo for lo, hi in hull):
        return "the hull is empty or flat"
    for box in boxes:
        if len(box) != len(hull) or any(hi <= lo for lo, hi in box):
            return f"a box is flat or of another dimension: {box}"
        if any(lo < h_lo or hi > h_hi for (lo, hi), (h_lo, h_hi) in zip(box, hull)):
            return f"a box is not inside the hull: {box}"
    for i, first in enumerate(boxes):
        for second in boxes[i + 1:]:
            if all(max(a_lo, b_lo) < min(a_hi, b_hi)
                   for (a_lo, a_hi), (b_lo, b_hi) in zip(first, second)):
                return f"two boxes overlap: {first} and {second}"
    if sum(_volume(b) for b in boxes) != _volume(hull):
        return "the boxes' volumes do not add up to the hull's"
    return ""


def _volume(box: Box) -> Fraction:
    return prod((hi - lo for lo, hi in box), start=Fraction(1))


def regions(names: Sequence[str], hull: Box, boxes: Sequence[Box]) -> list[L.Formula]:
    """Where the pieces are: each box, then the outside of H (a piece is the query and
    its region)."""
    return [_within(names, box) for box in boxes] + [L.negation(_within(names, hull))]


def _within(names: Sequence[str], box: Box) -> L.Formula:
    return L.conjunction(*[part for name, (lo, hi) in zip(names, box)
                           for part in (L.Compare(">=", E.Var(name), E.Num(lo)),
                                        L.Compare("<=", E.Var(name), E.Num(hi)))])
