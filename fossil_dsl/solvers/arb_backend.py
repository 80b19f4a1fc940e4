"""A second refutation procedure for transcendental queries, on Arb's ball arithmetic
(python-flint), sharing no code with the interval verifier (codac/IBEX).

`fossilc recheck` re-proves each obligation with a procedure other than the one that
proved it in the run. For a query with sin or exp that the interval verifier proved,
the only other installed solver was CVC5, which seldom decides such queries: this
procedure is that other one. It bisects a box that the query itself bounds and refutes
each piece by enclosures: a box is refuted when some conjunct's comparison cannot
hold anywhere in it (Arb's enclosures contain every value of the expression there, and
a strict comparison is read as the non-strict one, which only enlarges the set). UNSAT
when every piece of the cover is refuted; otherwise UNKNOWN (never SAT: it looks for no
counterexamples).

The starting box comes from the query's own conjuncts: bounds `c <= x`, and
comparisons `sum a_i (x_i - c_i)^2 <= r` (a ball or ellipsoid with axis-parallel axes),
each worked out in exact rationals and rounded outwards. A variable no conjunct bounds
makes the answer UNKNOWN: the search covers bounded boxes only.
"""
from __future__ import annotations

import time
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.calculus import derivative
from fossil_dsl.solvers.api import Answer, Status
from fossil_dsl.solvers.arb_box import ABOVE, BELOW, starting_box

SMALLEST = 1e-12  # a box this narrow (relative to the start) that is not refuted: give up
TABLE_TERMS = 4  # a polynomial part with this many terms is evaluated as a table


class ArbBackend:
    name = "arb"

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop=None) -> Answer:
        import flint
        names = sorted(set(variables) | L.free_vars(formula))
        box = starting_box(formula, names)
        if box is None:
            return Answer(Status.UNKNOWN, reason="the query does not bound every variable")
        if any(lo > hi for lo, hi in box):  # bounds implied by conjuncts contradict
            return Answer(Status.UNSAT, solver=self.name)
        refuter = _Refuter(flint.arb, names)
        # negations moved inward once: the search meets the same comparison objects in
        # every box (their tables are kept by identity)
        formula = L.negations_inward(formula)
        return _search(refuter, formula, box, time.monotonic() + timeout, stop)


def _search(refuter, formula, start, deadline: float, stop) -> Answer:
    stack, boxes = [start], 0
    smallest = [SMALLEST * max(hi - lo, 1.0) for lo, hi in start]
    while stack:
        box = stack.pop()
        boxes += 1
        if boxes % 64 == 0 and (time.monotonic() > deadline
                                or (stop is not None and stop.is_set())):
            return Answer(Status.UNKNOWN, reason=f"timeout after {boxes} boxes, "
                          f"{len(stack) + 1} left to refute")
        if refuter.refutes(formula, box):
            continue
        widest = max(range(len(box)), key=lambda i: (box[i][1] - box[i][0]) / smallest[i])
        halves = _halves(box, widest)
        if halves is None or box[widest][1] - box[widest][0] < smallest[widest]:
            return Answer(Status.UNKNOWN, reason=f"a box of width "
                          f"{box[widest][1] - box[widest][0]:.3g} is not refuted (the query "
                          "may hold there)")
        stack += halves
    return Answer(Status.UNSAT, solver=ArbBackend.name)


def refuted_on(formula: L.Formula, names: Sequence[str], box, pieces: int) -> bool:
    """Whether no point of the box satisfies the formula, shown on at most `pieces`
    pieces, each bisected on its widest side: a count, not a clock, so the same call
    gives the same answer (solvers/cleared.py's proofs of a divisor's sign, which the
    kernel's check redoes)."""
    import flint
    refuter, stack = _Refuter(flint.arb, list(names)), [list(box)]
    for _ in range(pieces):
        if not stack:
            return True
        piece = stack.pop()
        if refuter.refutes(formula, piece):
            continue
        halves = _halves(piece, max(range(len(piece)), key=lambda i: piece[i][1] - piece[i][0])) \
            if piece else None  # (a constant has nothing to bisect)
        if halves is None:
            return False
        stack += halves
    return not stack


def _halves(box, i: int):
    """The box cut in two across side i (the upper half first, so the lower is taken
    next from a stack), or None where the side cannot be cut in floats."""
    lo, hi = box[i]
    middle = (lo + hi) / 2
    if not lo < middle < hi:
        return None
    return [box[:i] + [(middle, hi)] + box[i + 1:], box[:i] + [(lo, middle)] + box[i + 1:]]


class _Refuter:
    def __init__(self, arb, names):
        self.arb = arb
        self.names = names
        self.index = {name: i for i, name in enumerate(names)}
        self.gradients: dict[int, tuple] = {}  # id -> (comparison kept alive, tables)
        self.tables: dict[int, tuple] = {}  # id -> (expression kept alive, table or None)
        self.numbers: dict[int, tuple] = {}  # id -> (number kept alive, its ball)

    def refutes(self, formula: L.Formula, box) -> bool:
        """Whether no point of the box satisfies the formula (False: not shown)."""
        values = [self.arb(lo).union(self.arb(hi)) for lo, hi in box]
        self.box = box
        return self._refutes(formula, values, {})

    def _refutes(self, formula: L.Formula, values, memo) -> bool:
        if isinstance(formula, L.BoolConst):
            return not formula.value
        if isinstance(formula, L.Not):
            return self._refutes(L.negated_inward(formula.arg), values, memo)
        if isinstance(formula, L.And):
            return any(self._refutes(arg, values, memo) for arg in formula.args)
        if isinstance(formula, L.Or):
            return all(self._refutes(arg, values, memo) for arg in formula.args)
        if isinstance(formula, L.Compare) and formula.relation in BELOW + ABOVE:
            difference, gradient = self._difference(formula)
            value = difference.enclose(self, values, memo)
            if value is None:
                return False
            if not _excludes(value, formula.relation) and gradient is not None:
                value = self._mean_value(difference, gradient, values, memo)
            # the closure of the comparison's set: d <= 0 (or d >= 0) cannot hold
            return value is not None and _excludes(value, formula.relation)
        return False

    def _number(self, expr: E.Num):
        key = id(expr)
        if key not in self.numbers:
            self.numbers[key] = (expr, _rational(self.arb, expr.value))
        return self.numbers[key][1]

    def _table(self, expr: E.Expr):
        """A polynomial part of a larger expression (the gradient of V in dV/dt with sin
        in the field) as a coefficient table, evaluated at once; None for other parts."""
        if not isinstance(expr, (E.Add, E.Mul)):
            return None
        key = id(expr)
        if key not in self.tables:
            try:
                table = P.polynomial(expr, self.names)
            except ValueError:
                table = None
            self.tables[key] = (expr, None if table is None or len(table) < TABLE_TERMS
                                else _Table(self.arb, table, len(self.names)))
        return self.tables[key][1]

    def _mean_value(self, difference, gradient, values, memo):
        """d(c) + sum_i (∂d/∂x_i on the box) (x_i - c_i), c the box's centre (the mean
        value theorem; far tighter than d's own enclosure on small boxes where d's terms
        nearly cancel), or None where a part has no finite enclosure."""
        centre = [(lo + hi) / 2 for lo, hi in self.box]
        total = difference.enclose(self, [self.arb(c) for c in centre], {})
        if total is None:
            return None
        for slope_of, value, c in zip(gradient, values, centre):
            slope = slope_of.enclose(self, values, memo)
            if slope is None:
                return None
            total += slope * (value - self.arb(c))
        return total

    def _difference(self, formula: L.Compare):
        """(d, its gradient or None) for the comparison's left - right: as coefficient
        tables where d is a polynomial (quick to evaluate), else as expressions (None
        where d is not differentiable)."""
        key = id(formula)  # the formula is kept with its entry, so its id is not reused
        if key not in self.gradients:
            expr = E.add(formula.left, E.neg(formula.right))
            try:
                table = P.polynomial(expr, self.names)
                found = (_Table(self.arb, table, len(self.names)),
                         [_Table(self.arb, _partial(table, i), len(self.names))
                          for i in range(len(self.names))])
            except ValueError:
                try:
                    gradient = [_Tree(derivative(expr, name)) for name in self.names]
                except (E.ExprError, ValueError, KeyError, TypeError):
                    gradient = None
                found = (_Tree(expr), gradient)
            self.gradients[key] = (formula, found)
        return self.gradients[key][1]

    def enclose(self, expr: E.Expr, values, memo):
        """A ball holding every value of the expression on the box, or None where
        one is not computed (an unknown function)."""
        key = id(expr)
        if key not in memo:
            memo[key] = (expr, self._enclose(expr, values, memo))
        return memo[key][1]

    def _enclose(self, expr: E.Expr, values, memo):
        arb = self.arb
        table = self._table(expr)
        if table is not None:
            return table.enclose(self, values, memo)
        if isinstance(expr, E.Num):
            return self._number(expr)
        if isinstance(expr, E.Pi):
            return arb.pi()
        if isinstance(expr, E.Var):
            return values[self.index[expr.name]]
        parts = [self.enclose(child, values, memo) for child in E.children(expr)]
        if any(p is None for p in parts):
            return None
        if isinstance(expr, E.Neg):
            return -parts[0]
        if isinstance(expr, E.Add):
            return sum(parts[1:], parts[0])
        if isinstance(expr, E.Mul):
            return _product(expr.factors, parts)
        if isinstance(expr, E.Div):
            return parts[0] / parts[1]
        if isinstance(expr, E.Pow):
            return _power(arb, parts[0], expr.exponent, parts[1])
        if isinstance(expr, E.Apply):
            if expr.func == "abs":
                return _abs(arb, parts[0])
            method = getattr(parts[0], expr.func, None)
            return method() if method is not None else None
        return None


class _Tree:
    """An expression, enclosed node by node."""

    def __init__(self, expr: E.Expr):
        self.expr = expr

    def enclose(self, refuter: _Refuter, values, memo):
        return refuter.enclose(self.expr, values, memo)


class _Table:
    """A polynomial as (coefficient, exponents) rows: each power of each variable is
    enclosed once per box (even powers tightly), then the rows are summed."""

    def __init__(self, arb, table: dict, n: int):
        self.rows = [(_rational(arb, Fraction(c)), m) for m, c in table.items() if c]
        self.top = max((max(m) for m in table), default=0)
        self.zero = arb(0)

    def enclose(self, refuter: _Refuter, values, memo):
        powers = [[_integer_power(v, k) for k in range(self.top + 1)] for v in values]
        total = self.zero
        for coefficient, exponents in self.rows:
            term = coefficient
            for i, k in enumerate(exponents):
                if k:
                    term = term * powers[i][k]
            total = total + term
        return total


def _partial(table: dict, i: int) -> dict:
    """∂p/∂x_i of a polynomial table, exactly."""
    found = {}
    for exponents, c in table.items():
        if exponents[i]:
            lowered = exponents[:i] + (exponents[i] - 1,) + exponents[i + 1:]
            found[lowered] = found.get(lowered, 0) + Fraction(c) * exponents[i]
    return found


def _excludes(difference, relation: str) -> bool:
    return bool(difference > 0) if relation in BELOW else bool(difference < 0)


def _rational(arb, value: Fraction):
    return arb(value.numerator) / arb(value.denominator)


def _product(factors, parts):
    """x*x as a square (ball multiplication does not know both factors are one)."""
    result, seen = None, {}
    for factor, part in zip(factors, parts):
        # a variable by its name, anything else by identity (hashing a whole subtree
        # for every box cost more than the rest of the search)
        key = factor.name if isinstance(factor, E.Var) else id(factor)
        seen.setdefault(key, [part, 0])[1] += 1
    for part, count in seen.values():
        term = _integer_power(part, count)
        result = term if result is None else result * term
    return result


def _power(arb, base, exponent: E.Expr, exponent_value):
    if isinstance(exponent, E.Num) and exponent.value.denominator == 1:
        n = int(exponent.value)
        return _integer_power(base, n) if n >= 0 else 1 / _integer_power(base, -n)
    if isinstance(exponent, E.Num) and exponent.value == Fraction(1, 2):
        return base.sqrt()
    return (exponent_value * base.log()).exp()


def _integer_power(base, n: int):
    """base^n; for even n the ball of [min |x|^n, max |x|^n] (a ball round 0 would
    otherwise give a negative lower end)."""
    if n % 2 or n == 0:
        return base ** n
    low, high = base.abs_lower(), base.abs_upper()
    return (low ** n).union(high ** n)


def _abs(arb, value):
    return value.abs_lower().union(value.abs_upper())
