"""A query that leaves out a ball round the origin, refuted in two pieces: near the
origin by a sum-of-squares refutation of its polynomial form, away from it by another
procedure (the interval search, say).

Why: a condition such as V's decrease vanishes to second order at the origin, and
bisection needs boxes about as narrow as their distance to the origin to refute it, so
every halving of that distance costs as many boxes again (a 4-state swing system's
decrease: 33 000 boxes per octave, eight octaves down to |x| = 0.01, 100 s). Near the
origin the facts about sin, tanh, ... (atom_facts.py) are tight, and a small
semidefinite program refutes the polynomial form on a ball there (the same system:
0.03 s on |x| <= 0.8). What is left for bisection is the shell beyond.

Sound: the pieces are the query with |x|^2 <= R^2 and the query with |x|^2 >= R^2.
Every point lies in one of them, so the query is unsatisfiable if both are. The
refutation of the first is checked exactly (positivstellensatz.py), and it is exported
with R (NAME.split.json) so that it can be checked again.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.evidence_json import refutation_from_json, refutation_json
from fossil_dsl.solvers.positivstellensatz import Evidence, conjuncts
from fossil_dsl.solvers.sos_refutation import refute

RADIUS_STEP = math.sqrt(2)  # between the radii tried
SMALLEST_SHARE = 1 / 64  # of the query's outer radius: the smallest ball tried
BALL_ROOM = 4  # the ball tried is at least this many times the excluded one
SEARCH_SHARE = 0.1  # of a query's time, for finding the ball (the rest: beyond it)


@dataclass(frozen=True)
class BallSplit:
    """The query refuted within |x| <= radius by `inner`; beyond it by `procedure`."""

    radius: Fraction
    inner: Evidence
    procedure: str = ""


def pieces(query: L.Formula, states: Sequence[str],
           radius: Fraction) -> tuple[L.Formula, L.Formula]:
    """(the query within the ball |x| <= radius, the query outside its interior)."""
    norm, bound = E.squared_norm(states), E.Num(radius ** 2)
    return (L.conjunction(query, L.Compare("<=", norm, bound)),
            L.conjunction(query, L.Compare(">=", norm, bound)))


def excluded_radius(query: L.Formula, states: Sequence[str]) -> float | None:
    """r > 0 where a conjunct of the query is |x|^2 > r^2 (over all the states), else None
    (a query that leaves out the origin alone goes to solvers that decide x != 0)."""
    for conjunct in conjuncts(query):
        if isinstance(conjunct, L.Compare) and conjunct.relation == ">" \
                and isinstance(conjunct.right, E.Num) and conjunct.right.value > 0 \
                and _is_squared_norm(conjunct.left, states):
            return math.sqrt(conjunct.right.value)
    return None


def _is_squared_norm(expr: E.Expr, states: Sequence[str]) -> bool:
    """Syntactically x1^2 + ... + xn^2 (a sum of big expressions is not expanded)."""
    terms = expr.terms if isinstance(expr, E.Add) else (expr,)
    squared = [t.base.name for t in terms if isinstance(t, E.Pow) and isinstance(t.base, E.Var)
               and t.exponent == E.Num(2)]
    return len(squared) == len(terms) and sorted(squared) == sorted(states)


def radii(outer: float, excluded: float) -> list[Fraction]:
    """The balls to try, largest first: outer / sqrt(2)^k down to the smallest."""
    found, radius = [], outer / RADIUS_STEP
    floor = max(outer * SMALLEST_SHARE, BALL_ROOM * excluded)
    while radius >= floor:
        found.append(Fraction(radius).limit_denominator(1000))
        radius /= RADIUS_STEP
    return found


def refuted_inside(query: L.Formula, states: Sequence[str], outer: float,
                   deadline: float) -> BallSplit | None:
    """The largest ball of `radii` inside which the query is refuted (bisecting the
    list: a refutation on a ball is also found on smaller ones, with tighter facts),
    or None if even the smallest is not (then no more is tried)."""
    excluded = excluded_radius(query, states)
    if excluded is None or not outer > 0:
        return None
    options = radii(outer, excluded)
    best = None
    low, high = 0, len(options) - 1  # options[high] is tried first
    while low <= high and time.monotonic() < deadline:
        index = high if best is None else (low + high) // 2
        found = refute(pieces(query, states, options[index])[0], states, deadline)
        if found is None and best is None:
            return None
        if found is not None:
            best, high = BallSplit(options[index], found), index - 1
        else:
            low = index + 1
    return best


def split_query(query: L.Formula, states: Sequence[str], deadline: float
                ) -> tuple[L.Formula, BallSplit | None]:
    """The query left beyond the largest ball inside which it is refuted (found by
    `deadline`), and that split; the query itself and None if there is none."""
    found = refuted_inside(query, states, outer_radius(query, states), deadline)
    if found is None:
        return query, None
    return pieces(query, states, found.radius)[1], found


def outer_radius(query: L.Formula, names: Sequence[str]) -> float:
    """The largest |x| in the box that contraction leaves of the query (0: none)."""
    from fossil_dsl.solvers.interval_hull import hull
    box = hull(query, list(names))
    if box is None:
        return 0.0
    return math.sqrt(sum(max(abs(low), abs(high)) ** 2 for low, high in box))


# ---- the exported form (obligations/NAME.split.json) ----
def split_json(split: BallSplit, states: Sequence[str]) -> dict:
    return {"radius": str(split.radius), "procedure": split.procedure,
            "inner": refutation_json(split.inner, states)}


def split_from_json(data: dict) -> BallSplit:
    """Raises ValueError (or KeyError, TypeError) where the data is malformed."""
    return BallSplit(Fraction(data["radius"]), refutation_from_json(data["inner"]),
                     str(data.get("procedure", "")))
