"""A delta-decision procedure on codac's outward-rounded interval arithmetic.

The query is read as a closed set (strict comparisons are relaxed to non-strict ones,
which only enlarges it), each comparison becomes codac's forward-backward contractor
(with its centred form), `and`/`or` become intersection/union of contractors, and the
boxes of a depth-first search are contracted and bisected:

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
from collections import Counter
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import function, rational_interval, upward_rounding
from fossil_dsl.ir.sharing import worth_naming
from fossil_dsl.solvers.api import Answer, Status, UnsupportedTheory
from fossil_dsl.solvers import taylor_boxes

DELTA = 1e-4  # the width under which a surviving box counts as a (delta-)solution
WITNESS_SEARCH = 2000  # boxes searched for a better witness after a doubtful one


class IntervalBackend:
    name = "interval"

    def __init__(self, delta: float = DELTA, leads_only: bool = False, taylor: bool = True):
        self.delta, self.taylor = delta, taylor  # taylor: taylor_boxes goes first
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
        deadline = time.monotonic() + timeout
        key, paused, self._paused = (formula, tuple(names)), self._paused, None
        resumed = paused is not None and paused[0] == key
        if (found := self._taylor_first(key, formula, names, timeout)) is not None:
            return found
        with upward_rounding() as codac:
            if resumed:
                return self._search(*paused[1:], names, variables, deadline, stop, key)
            try:
                compiler = _Compiler(codac, names, self.rigorous, _named_terms(formula))
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

    def _taylor_first(self, key, formula, names, timeout: float) -> Answer | None:
        """taylor_boxes' UNSAT within its share of the time, or None (resumed where a
        call asks the same query again). A point where the query holds only ends it:
        codac's delta-solutions lie nearer the sets' edges, as refinements from
        counterexamples need (tests/test_conserved.py, the unicycle)."""
        if not (share := taylor_boxes.share(names) if self.taylor else 0.0):
            return None
        if self._taylor is None or self._taylor[0] != key:
            self._taylor = (key, taylor_boxes.Search(formula, names))
        answer = self._taylor[1].run(share * timeout)
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
                    compiler = _Compiler(codac, names, self.rigorous, _named_terms(query))
                    self._compiled = {key: (compiler.defined(compiler.formula(query)),
                                            compiler.named)}
                compiled, named = self._compiled[key]
                inside = _Compiler(codac, names, self.rigorous, named).formula(region)
            except UnsupportedTheory as exc:
                return Answer(Status.UNKNOWN, reason=str(exc))
            parts = [c for c in (compiled, inside) if c is not None]
            if not parts:
                return _unbounded()
            contractor = _combine(parts, lambda a, b: a & b)
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


class _Compiler:
    """Neutral formulas and expressions to codac contractors and analytic expressions."""

    def __init__(self, codac, names, rigorous: bool = True, named: Sequence[E.Expr] = ()):
        self.codac = codac
        self.rigorous = rigorous
        self.dimension = len(names) + len(named)
        self.vector = codac.VectorVar(self.dimension)
        self.index = {name: i for i, name in enumerate(names)}
        # a named term is one more variable of the box, its value fixed by its
        # definition (ir/sharing.py): the tree then holds one copy of it
        self.named = tuple(named)
        self.variable_of = {term: self.vector[len(names) + i] for i, term in enumerate(named)}
        # equal subexpressions become one codac node object: a network's neurons recur
        # in its derivative. codac (2.1.2) still evaluates the expression as a tree, once
        # per occurrence (an expression of depth 14 with each level used twice: 66 ms
        # per evaluation, 0.8 ms at depth 8): f1_barr3's flow query is 754 distinct
        # nodes but a 12 600-node tree, 10 ms per contraction
        self.shared: dict[E.Expr, object] = dict(self.variable_of)

    def defined(self, contractor):
        """The contractor with the named terms' definitions, on both sides: first they
        get their values from the variables, last the query's contraction of them is
        passed back to the variables."""
        if contractor is None or not self.named:
            return contractor
        codac = self.codac
        definitions = [codac.CtcInverse_Interval(
            codac.AnalyticFunction([self.vector], self.variable_of[term] - self._translate(term)),
            codac.Interval(0, 0)) for term in self.named]  # inner terms first
        return _combine(definitions + [contractor] + definitions[::-1], lambda a, b: a & b)

    def formula(self, formula: L.Formula):
        """A contractor for the closure of the formula's set; None for TRUE."""
        codac = self.codac
        if isinstance(formula, L.BoolConst):
            return None if formula.value else codac.CtcEmpty(self.dimension)
        if isinstance(formula, L.Not):
            return self.formula(L.negated_inward(formula.arg))
        if isinstance(formula, L.Compare):
            return self.compare(formula)
        parts = [self.formula(arg) for arg in formula.args]
        if isinstance(formula, L.And):
            kept = [p for p in parts if p is not None]
            return _combine(kept, lambda a, b: a & b) if kept else None
        if any(p is None for p in parts):
            return None
        return _combine(parts, lambda a, b: a | b)

    def compare(self, comparison: L.Compare):
        codac = self.codac
        difference = E.add(comparison.left, E.neg(comparison.right))
        if not E.free_vars(difference):
            return self.closed_comparison(comparison.relation, difference)
        difference = self.expr(difference)
        function = codac.AnalyticFunction([self.vector], difference)
        below = comparison.relation in ("<", "<=")
        allowed = codac.Interval(-codac.oo, 0) if below else codac.Interval(0, codac.oo)
        return codac.CtcInverse_Interval(function, allowed)

    def closed_comparison(self, relation: str, difference: E.Expr):
        """A comparison without variables: empty only when certainly false."""
        value = self.expr(difference)
        below = relation in ("<", "<=")
        false = value.lb() > 0 if below else value.ub() < 0
        return self.codac.CtcEmpty(self.dimension) if false else None

    def expr(self, expr: E.Expr):
        translated = self.shared.get(expr)
        if translated is None:
            translated = self.shared[expr] = self._translate(expr)
        return translated

    def _translate(self, expr: E.Expr):
        codac = self.codac
        if isinstance(expr, E.Num):
            return rational_interval(expr.value)
        if isinstance(expr, E.Pi):
            return codac.Interval.pi()
        if isinstance(expr, E.Var):
            if expr.name not in self.index:
                raise UnsupportedTheory(f"unknown variable {expr.name}")
            return self.vector[self.index[expr.name]]
        if isinstance(expr, E.Neg):
            return -self.expr(expr.operand)
        if isinstance(expr, E.Add):
            return _combine([self.expr(t) for t in expr.terms], lambda a, b: a + b)
        if isinstance(expr, E.Mul):
            # x*x as sqr(x): interval multiplication does not know both factors are one
            counts = Counter(expr.factors)
            factors = [self.expr(f) if n == 1 else self.power(E.Pow(f, E.Num(n)))
                       for f, n in counts.items()]
            return _combine(factors, lambda a, b: a * b)
        if isinstance(expr, E.Div):
            return self.expr(expr.numerator) / self.expr(expr.denominator)
        if isinstance(expr, E.Pow):
            return self.power(expr)
        if isinstance(expr, E.Apply):
            if not hasattr(codac, expr.func):
                raise UnsupportedTheory(f"the interval verifier has no `{expr.func}`")
            return function(expr.func, self.expr(expr.arg), self.rigorous)
        raise UnsupportedTheory(f"cannot translate {expr!r}")

    def power(self, expr: E.Pow):
        codac = self.codac
        base = self.expr(expr.base)
        exponent = expr.exponent
        if isinstance(exponent, E.Num) and exponent.value.denominator == 1:
            n = int(exponent.value)
            if n == 2:
                return codac.sqr(base)
            if n >= 0:
                return codac.pow(base, n)
            return 1 / codac.pow(base, -n)
        if isinstance(exponent, E.Num) and exponent.value == Fraction(1, 2):
            return codac.sqrt(base)
        return codac.exp(self.expr(exponent) * codac.log(base))


def _combine(items, join):
    result = items[0]
    for item in items[1:]:
        result = join(result, item)
    return result
