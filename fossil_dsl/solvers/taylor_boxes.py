"""Refuting a query on batches of boxes with second-order Taylor forms.

The query's hull (arb_box.starting_box) is bisected breadth-wise in batches of boxes; a
box is dropped where the query cannot hold on it: a comparison of the conjunction (every
disjunct of a disjunction) is false on the whole box. Each side g = left - right is
bounded on the box by its natural interval extension and, where g is smooth (no abs),
by its second-order Taylor form about the box's centre c:
    g(x) in g(c) + sum_i g_i(c) d_i + sum_i g_ii(B) d_i^2 / 2 + sum_{i<j} g_ij(B) d_i d_j,
d = x - c, g_i, g_ij the partial derivatives, B the box (Taylor's theorem with Lagrange's
remainder on the segment from c to x, which lies in B). Every bound is outward-rounded
interval arithmetic (vector_intervals.py, vector_elementary.py); where a derivative is
undefined on B (a division by an interval holding 0) its bound is the whole line, so
the form refutes nothing there. UNSAT when no box is left; UNKNOWN at the deadline or
when a box narrower than MIN_WIDTH of the hull survives; SAT, with the point, where the
query certainly holds at a surviving box's centre. Strict comparisons are read as
non-strict (a larger set) for refuting, so an UNSAT holds for the query as written.

Why: a decrease condition near a stable equilibrium is a sum of terms that cancel to
-mu |x|^2; natural interval extensions lose the cancellation in proportion to the box's
width, the Taylor form keeps it to second order, so boxes a sixth of their distance
from the origin wide suffice where codac needs a thirtieth (probe67/aq18, the acrobot:
its LQR candidate's decrease in 962 000 boxes, 259 000 in unit-curvature coordinates;
codac had no end after 3.2 million; docs/benchmarks.md, session 68).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace
from fractions import Fraction
from functools import cached_property

import numpy as np

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.calculus import derivative
from fossil_dsl.solvers import taylor_coordinates as coordinates
from fossil_dsl.solvers import vector_intervals as V
from fossil_dsl.solvers.vector_enclosure import enclose
from fossil_dsl.solvers.api import Answer, Status, UnsupportedTheory
from fossil_dsl.solvers.arb_box import starting_box

NAME = "taylor"  # the procedure's name in proofs and re-checks
BATCH = 4096  # boxes per numpy evaluation
MIN_WIDTH = 1e-9  # of the hull's width in each direction: narrower surviving boxes end it
# before codac's contractors (interval_backend.py), which need no derivatives and are
# stronger on two states and on thin sets: this share of their time, larger from 4 states
# on, where their bisection blows up (probe67/aq18's decrease: 15 s of 25). On 3
# variables codac has a first short slice (seconds): it settles most small queries at
# once (the portfolio's row06: 0.3-1.0 s of the loop's verification, 1.3-6.3 s with
# Taylor first); a tenth of the time instead cost 1-4 s on queries Taylor settles
FIRST_FROM_STATES, FIRST_SHARE, LARGE_SHARE, CODAC_FIRST = 3, 0.4, 0.7, 0.25


@dataclass(frozen=True)
class Side:
    """g = left - right of a comparison, and which sign of g the comparison needs."""
    expr: E.Expr
    needs: str  # ">=" (g >= 0), "<=" or "="
    names: tuple[str, ...]
    strict: bool = False  # g > 0 (g < 0): refuted as g >= 0, witnessed only as g > 0

    @cached_property
    def gradient(self) -> tuple[E.Expr, ...]:
        return tuple(derivative(self.expr, v) for v in self.names)

    @cached_property
    def hessian(self) -> dict[tuple[int, int], E.Expr]:
        entries = {}
        for i, first in enumerate(self.gradient):
            for j in range(i, len(self.names)):
                entry = derivative(first, self.names[j])
                if entry != E.ZERO:
                    entries[(i, j)] = entry
        return entries

    @cached_property
    def smooth(self) -> bool:
        """Whether the Taylor form applies: twice differentiable wherever defined (abs
        is not) and not affine (whose natural extension is already tight)."""
        nodes = list(E.walk(self.expr))
        if any(isinstance(n, E.Apply) and n.func == "abs" for n in nodes):
            return False
        return bool(self.hessian)


def refute(formula: L.Formula, variables, timeout: float, stop=None) -> Answer:
    """UNSAT where the search drops every box of the query's hull by `timeout` seconds."""
    return Search(formula, variables).run(timeout)


check = refute  # the Backend protocol's name (`fossilc recheck` calls the module so)


class Search:
    """The search on one query; `run` again goes on from the boxes a deadline left."""

    def __init__(self, formula: L.Formula, variables):
        self.names = tuple(sorted(set(variables) | L.free_vars(formula)))
        self.transform, self.stack, self.boxes = None, [], 0
        self.answer: Answer | None = None
        hull = starting_box(formula, list(self.names))
        if hull is None:
            self.answer = Answer(Status.UNKNOWN, reason="the query bounds no box")
            return
        try:
            tree = _compiled(formula, self.names)
            with np.errstate(all="ignore"):
                self.transform = _unit_curvature(tree, self.names, hull)
            if self.transform is not None:
                formula, z_names, hull = coordinates.substituted(formula, self.names,
                                                                 self.transform, hull)
                tree = _compiled(formula, z_names)
        except UnsupportedTheory as exc:
            self.answer = Answer(Status.UNKNOWN, reason=str(exc))
            return
        self.tree, self.searched = tree, z_names if self.transform else self.names
        self.stack = [(np.array([[lo for lo, _ in hull]]), np.array([[hi for _, hi in hull]]))]
        self.scale = np.maximum(self.stack[0][1][0] - self.stack[0][0][0], 1e-300)

    def run(self, timeout: float) -> Answer:
        if self.answer is None:
            with np.errstate(all="ignore"):  # overflows and NaNs are accounted for
                found = self._search(time.monotonic() + timeout)
            if found.status is Status.UNKNOWN and found.reason.startswith("timeout"):
                return found  # the boxes left are kept for another run
            self.answer = self._in_states(found)
        return self.answer

    def _in_states(self, answer: Answer) -> Answer:
        if answer.status is not Status.SAT or self.transform is None:
            return answer
        point = coordinates.back(self.transform, [answer.model[n] for n in self.searched])
        return replace(answer, model=dict(zip(self.names, point)))

    def _search(self, deadline: float) -> Answer:
        stack = self.stack
        while stack:
            if time.monotonic() > deadline:
                return Answer(Status.UNKNOWN, reason=f"timeout after {self.boxes} boxes")
            low, high = stack.pop()
            self.boxes += len(low)
            batch = _Boxes(self.searched, low, high)
            alive = ~_refuted(self.tree, batch)
            if not alive.any():
                continue
            witnessed = alive & _holds_at_centre(self.tree, batch)
            if witnessed.any():
                centre = batch.centre[witnessed.argmax()]
                return Answer(Status.SAT, {n: Fraction(float(v))
                                           for n, v in zip(self.searched, centre)},
                              reason="the query holds at a box's centre (outward-rounded)")
            low, high, spread = low[alive], high[alive], batch.spread[alive]
            relative = (high - low) / self.scale
            if (relative.max(axis=1) < MIN_WIDTH).any():
                return Answer(Status.UNKNOWN, reason=f"a box narrower than {MIN_WIDTH} of "
                              "the hull is not refuted")
            spread = np.where(np.isfinite(spread), spread, 0.0) * (relative > MIN_WIDTH)
            axis = np.where(spread.max(axis=1) > 0, spread.argmax(axis=1),
                            relative.argmax(axis=1))
            stack.extend(_halves(low, high, axis))
        return Answer(Status.UNSAT, reason=f"{self.boxes} boxes")


def _unit_curvature(tree, names, hull):
    """taylor_coordinates.transform for the largest smooth side's Hessian at the origin
    (at the hull's centre if the origin is outside it), or None."""
    sides = [side for side in _sides(tree) if side.smooth]
    if not sides:
        return None
    main = max(sides, key=lambda side: sum(1 for _ in E.walk(side.expr)))
    at_origin = all(lo <= 0 <= hi for lo, hi in hull)
    point = {n: np.array([0.0 if at_origin else (lo + hi) / 2])
             for n, (lo, hi) in zip(names, hull)}
    env, memo = {n: (v, v) for n, v in point.items()}, {}
    hessian = np.zeros((len(names), len(names)))
    for (i, j), entry in main.hessian.items():
        low, high = enclose(entry, env, memo)
        hessian[i, j] = hessian[j, i] = (np.atleast_1d(low)[0] + np.atleast_1d(high)[0]) / 2
    return coordinates.transform(hessian)


def _sides(tree):
    if isinstance(tree, Side):
        yield tree
    elif isinstance(tree, tuple):
        for part in tree[1]:
            yield from _sides(part)


def _compiled(formula: L.Formula, names):
    """The formula as nested ("and" | "or", parts) with Sides as leaves, True, False."""
    if isinstance(formula, L.BoolConst):
        return formula.value
    if isinstance(formula, L.Compare):
        if formula.relation not in ("<", "<=", ">", ">=", "="):
            raise UnsupportedTheory(f"relation {formula.relation}")
        needs = {"<": "<=", ">": ">="}.get(formula.relation, formula.relation)
        return Side(E.add(formula.left, E.neg(formula.right)), needs, names,
                    formula.relation in ("<", ">"))
    if isinstance(formula, L.Not):
        return _compiled(L.negated_inward(formula.arg), names)
    if isinstance(formula, (L.And, L.Or)):
        kind = "and" if isinstance(formula, L.And) else "or"
        return kind, tuple(_compiled(arg, names) for arg in formula.args)
    raise UnsupportedTheory(f"cannot read {type(formula).__name__}")


def _halves(low, high, axis):
    rows = np.arange(len(low))
    middle = (low[rows, axis] + high[rows, axis]) / 2
    upper_low, lower_high = low.copy(), high.copy()
    upper_low[rows, axis] = middle
    lower_high[rows, axis] = middle
    all_low = np.concatenate([low, upper_low])
    all_high = np.concatenate([lower_high, high])
    return [(all_low[s:s + BATCH], all_high[s:s + BATCH])
            for s in range(0, len(all_low), BATCH)]


class _Boxes:
    """A batch of boxes and the enclosures computed on it (shared between sides)."""

    def __init__(self, names, low, high):
        self.names = names
        self.box = {n: (low[:, i], high[:, i]) for i, n in enumerate(names)}
        self.centre = (low + high) / 2
        self.point = {n: (self.centre[:, i], self.centre[:, i]) for i, n in enumerate(names)}
        self.offsets = [V.sub(self.box[n], self.point[n]) for n in names]
        self.on_box: dict = {}
        self.at_centre: dict = {}
        self.spread = np.zeros_like(self.centre)

    def natural(self, expr: E.Expr):
        return enclose(expr, self.box, self.on_box)

    def taylor(self, side: Side):
        """The Taylor form's enclosure; each direction's share of its width is added to
        `spread` (where the form is loose is where bisecting helps it most)."""
        value = enclose(side.expr, self.point, self.at_centre)
        shares = np.zeros_like(self.centre)
        for i, first in enumerate(side.gradient):
            term = V.mul(enclose(first, self.point, self.at_centre), self.offsets[i])
            shares[:, i] += term[1] - term[0]
            value = V.add(value, term)
        for (i, j), entry in side.hessian.items():
            curvature = self.natural(entry)
            if i == j:
                term = V.mul(V.mul(curvature, V.square(self.offsets[i])), (0.5, 0.5))
            else:
                term = V.mul(curvature, V.mul(self.offsets[i], self.offsets[j]))
            shares[:, i] += (term[1] - term[0]) / 2
            shares[:, j] += (term[1] - term[0]) / 2
            value = V.add(value, term)
        total = shares.sum(axis=1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            self.spread += np.where(np.isfinite(total) & (total > 0), shares / total, 0.0)
        return value


def _refuted(tree, boxes: _Boxes) -> np.ndarray:
    """Where (on the batch) the formula cannot hold."""
    count = len(boxes.centre)
    if tree is True or tree is False:
        return np.full(count, not tree)
    if isinstance(tree, Side):
        return _side_refuted(tree, boxes)
    kind, parts = tree
    result = np.full(count, kind == "or")
    for part in parts:
        result = result | _refuted(part, boxes) if kind == "and" \
            else result & _refuted(part, boxes)
    return result


def _holds_at_centre(tree, boxes: _Boxes) -> np.ndarray:
    """Where the formula certainly holds at the box's centre (every bound rigorous): a
    true solution, which ends the search (a lead for the learner, a counterexample)."""
    count = len(boxes.centre)
    if tree is True or tree is False:
        return np.full(count, tree)
    if isinstance(tree, Side):
        low, high = enclose(tree.expr, boxes.point, boxes.at_centre)
        if tree.needs == "=":
            return np.zeros(count, dtype=bool)
        value = low if tree.needs == ">=" else -high
        return np.broadcast_to(value > 0 if tree.strict else value >= 0, (count,))
    kind, parts = tree
    results = [_holds_at_centre(part, boxes) for part in parts]
    return np.logical_and.reduce(results) if kind == "and" else np.logical_or.reduce(results)


def _side_refuted(side: Side, boxes: _Boxes) -> np.ndarray:
    # (a side without variables has scalar bounds)
    refuted = np.broadcast_to(_excludes(side.needs, boxes.natural(side.expr)),
                              (len(boxes.centre),)).copy()
    if side.smooth and not refuted.all():
        refuted |= _excludes(side.needs, boxes.taylor(side))
    return refuted


def _excludes(needs: str, value) -> np.ndarray:
    low, high = value
    if needs == ">=":
        return high < 0
    if needs == "<=":
        return low > 0
    return (low > 0) | (high < 0)


def shares(names) -> tuple[float, float]:
    """Codac's first slice (seconds) and then this search's share of a query's time
    (none below FIRST_FROM_STATES variables)."""
    if len(names) < FIRST_FROM_STATES:
        return 0.0, 0.0
    if len(names) == FIRST_FROM_STATES:
        return CODAC_FIRST, FIRST_SHARE
    return 0.0, LARGE_SHARE
