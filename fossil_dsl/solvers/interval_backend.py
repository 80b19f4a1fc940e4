"""A delta-decision procedure on codac's outward-rounded interval arithmetic.

The query is read as a closed set (strict comparisons are relaxed to non-strict ones,
which only enlarges it), each comparison becomes codac's forward-backward contractor
(with its centred form; codac_compiler.py), `and`/`or` become intersection/union of
contractors, and the boxes of a depth-first search are contracted and bisected:

- UNSAT only when every box has been contracted to the empty set. Each contraction is an
  interval computation under outward rounding, so the enlarged set, and therefore the
  query, has no point in the box: the answer rests on no floating-point sampling.
- delta-SAT when a box narrower than `delta` in every direction survives contraction;
  its midpoint is returned as the counterexample (a lead for the learner, not a proof).
  A box whose midpoint alone is refuted is kept aside while the search looks (for
  WITNESS_SEARCH more boxes) for one whose midpoint is not; it is returned if none is.
- UNKNOWN on timeout, or when contraction cannot bound every variable.
"""
from __future__ import annotations

import threading
import time
from dataclasses import replace
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import upward_rounding
from fossil_dsl.ir.sharing import worth_naming
from fossil_dsl.solvers.codac_compiler import Compiler, combine
from fossil_dsl.solvers.api import Answer, Status, UnsupportedTheory
from fossil_dsl.solvers import taylor_boxes

DELTA = 1e-4  # the width under which a surviving box counts as a (delta-)solution
WITNESS_SEARCH = 2000  # boxes searched for a better witness after a doubtful one


class IntervalBackend:
    name = "interval"

    def __init__(self, delta: float = DELTA, leads_only: bool = False, taylor: bool = True):
        self.delta, self.taylor = delta, taylor  # taylor: taylor_boxes takes a share
        # leads_only: codac's own tanh, not outward-rounded but three times faster to
        # search with; for the CEGIS loop, whose answers the kernel judges again
        self.rigorous = not leads_only
        self._compiled: dict = {}  # (query, names) -> its contractor (check_within)
        # the search a deadline stopped: (query, names), its contractor and boxes left. A
        # caller that asks the same query again (the loop's falsifier, after its first
        # slice of 10 s) resumes it: am05's decrease took 28 s, and was asked for 10 s,
        # then 24 s from the start again
        self._paused = None
        self._taylor = None  # (query, names) and taylor_boxes' search on it

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop: threading.Event | None = None) -> Answer:
        names = sorted(set(variables) | L.free_vars(formula))
        deadline, key = time.monotonic() + timeout, (formula, tuple(names))
        codac_first, share = taylor_boxes.shares(names) if self.taylor else (0.0, 0.0)
        if share:
            if codac_first:
                answer = self._codac(formula, names, variables, stop, key,
                                     min(deadline, time.monotonic() + codac_first))
                if answer.status is not Status.UNKNOWN or (stop and stop.is_set()):
                    return answer
            if (found := self._taylor_first(key, formula, names, share * timeout)):
                return found
        return self._codac(formula, names, variables, stop, key, deadline)

    def _codac(self, formula, names, variables, stop, key, deadline: float) -> Answer:
        """Codac's search on the query until the deadline, resumed where the last call
        paused on the same query."""
        paused, self._paused = self._paused, None
        with upward_rounding() as codac:
            if paused is not None and paused[0] == key:
                return self._search(*paused[1:], names, variables, deadline, stop, key)
            try:
                compiler = Compiler(codac, names, self.rigorous, _named_terms(formula))
                contractor = compiler.defined(compiler.formula(formula))
            except UnsupportedTheory as exc:
                return Answer(Status.UNKNOWN, reason=str(exc))
            if contractor is None:  # the formula is TRUE: any point
                return _unbounded() if names else Answer(Status.SAT, {})
            start = codac.IntervalVector([[-codac.oo, codac.oo]] * compiler.dimension)
            if (answer := _settled_at_once(contractor, start, len(names))) is not None:
                return answer
            split = _worth_splitting(formula, names)
            return self._search(contractor, [start], split, names, variables, deadline,
                                stop, key)

    def _taylor_first(self, key, formula, names, seconds: float) -> Answer | None:
        """taylor_boxes' UNSAT within `seconds`, or None (resumed where a call asks the
        same query again). A point where the query holds only ends it: codac's
        delta-solutions lie nearer the sets' edges, as refinements from counterexamples
        need (tests/test_conserved.py, the unicycle)."""
        if self._taylor is None or self._taylor[0] != key:
            self._taylor = (key, taylor_boxes.Search(formula, names))
        answer = self._taylor[1].run(seconds)
        return replace(answer, solver=taylor_boxes.NAME) \
            if answer.status is Status.UNSAT else None

    def check_within(self, query: L.Formula, region: L.Formula, variables: Sequence[str],
                     timeout: float, stop: threading.Event | None = None) -> Answer:
        """Is `query and region` satisfiable? The query's contractor is kept for the
        next region (the pieces of a split query share it; compiling a large query
        costs as much as refuting a piece)."""
        names = sorted(set(variables) | L.free_vars(query) | L.free_vars(region))
        deadline = time.monotonic() + timeout
        with upward_rounding() as codac:
            key = (query, tuple(names))
            try:
                if key not in self._compiled:
                    compiler = Compiler(codac, names, self.rigorous, _named_terms(query))
                    self._compiled = {key: (compiler.defined(compiler.formula(query)),
                                            compiler.named)}
                compiled, named = self._compiled[key]
                inside = Compiler(codac, names, self.rigorous, named).formula(region)
            except UnsupportedTheory as exc:
                return Answer(Status.UNKNOWN, reason=str(exc))
            parts = [c for c in (compiled, inside) if c is not None]
            if not parts:
                return _unbounded()
            contractor = combine(parts, lambda a, b: a & b)
            start = codac.IntervalVector([[-codac.oo, codac.oo]] * (len(names) + len(named)))
            if (answer := _settled_at_once(contractor, start, len(names))) is not None:
                return answer
            split = _worth_splitting(L.conjunction(query, region), names)
            return self._search(contractor, [start], split, names, variables, deadline, stop)

    def _search(self, contractor, stack, split, names, variables, deadline, stop,
                key=None) -> Answer:
        """Bisection from the boxes of `stack`; where the deadline stops it and `key`
        names the query, the boxes left are kept for a call that asks it again."""
        boxes, unresolved, since = 0, None, 0
        while stack:
            box = stack.pop()
            boxes += 1
            if boxes % 64 == 0 and stop is not None and stop.is_set():
                return Answer(Status.UNKNOWN, reason=f"stopped after {boxes} boxes")
            since += unresolved is not None
            if since > WITNESS_SEARCH:
                return _delta_sat(unresolved, names, variables, self.delta)
            contractor.contract(box)
            if box.is_empty():
                continue
            if max(box[i].diam() for i in split) < self.delta:
                if _contract_to_fixpoint(contractor, box, len(names)):
                    continue
                if _middle_may_satisfy(contractor, box, len(names)):
                    return _delta_sat(box, names, variables, self.delta)
                # its middle is refuted: look on for a better witness, keep this one
                unresolved = unresolved or box
                continue
            if boxes % 256 == 0 and time.monotonic() > deadline:
                if unresolved is not None:
                    return _delta_sat(unresolved, names, variables, self.delta)
                if key is not None:
                    self._paused = (key, contractor, stack + [box], split)
                return Answer(Status.UNKNOWN, reason=f"timeout after {boxes} boxes, "
                              f"{len(stack) + 1} left to refute")
            widest = max(split, key=lambda i: box[i].diam())
            first, second = box.bisect(widest, 0.5)
            stack += [second, first]
        if unresolved is not None:
            return _delta_sat(unresolved, names, variables, self.delta)
        return Answer(Status.UNSAT)


def _settled_at_once(contractor, start, dimension: int) -> Answer | None:
    """UNSAT where the first contraction empties the start box, UNKNOWN where it leaves a
    variable unbounded; else None (the search goes on)."""
    contractor.contract(start)
    if start.is_empty():
        return Answer(Status.UNSAT)
    if any(start[i].is_unbounded() for i in range(dimension)):
        return _unbounded()
    return None


def _middle_may_satisfy(contractor, box, dimension: int) -> bool:
    """Whether the box's middle point (in its first `dimension` directions, the query's
    variables; named terms keep their intervals) survives contraction: a witness the
    learner can use, rather than a box that only interval overestimation keeps alive."""
    middle = box.mid()
    point = type(box)([[middle[i], middle[i]] if i < dimension else [box[i].lb(), box[i].ub()]
                       for i in range(box.size())])
    contractor.contract(point)
    return not point.is_empty()


def _worth_splitting(formula: L.Formula, names) -> list[int]:
    """The variables to bisect: those in a comparison other than a bound `x <= c`, which
    contraction already enforces exactly (bisecting them would only multiply boxes)."""
    involved = set()
    for comparison in L.comparisons(formula):
        sides = (comparison.left, comparison.right)
        bound = any(isinstance(a, E.Var) for a in sides) and \
            not any(E.free_vars(side) for side in sides if not isinstance(side, E.Var))
        if not bound:
            involved |= E.free_vars(comparison.left) | E.free_vars(comparison.right)
    indices = [i for i, name in enumerate(names) if name in involved]
    return indices or list(range(len(names)))


def _contract_to_fixpoint(contractor, box, dimension: int, passes: int = 50) -> bool:
    """Contract until the box stops shrinking in its first `dimension` directions (one
    forward-backward pass is not idempotent); True if it becomes empty."""
    def width():
        return max((box[i].diam() for i in range(dimension)), default=0.0)
    for _ in range(passes):
        before = width()
        contractor.contract(box)
        if box.is_empty():
            return True
        if width() > 0.99 * before:
            return False
    return False


def _named_terms(formula: L.Formula) -> tuple[E.Expr, ...]:
    sides = [side for c in L.comparisons(formula) for side in (c.left, c.right)]
    return tuple(worth_naming(sides))


def _unbounded() -> Answer:
    return Answer(Status.UNKNOWN, reason="the query does not bound every variable, and the "
                  "interval verifier searches bounded boxes only")


def _delta_sat(box, names, variables, delta) -> Answer:
    middle = box.mid()
    point = {name: Fraction(float(middle[i])) for i, name in enumerate(names)}
    return Answer(Status.SAT, {v: point[v] for v in variables if v in point},
                  reason=f"delta-sat (delta = {delta:g}): a box this narrow could not be refuted",
                  approximate=True)
