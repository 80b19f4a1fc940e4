"""Neutral formulas and expressions to codac's contractors (interval_backend.py).

A comparison becomes codac's forward-backward contractor of its difference, `and`/`or`
intersection/union of contractors; every number is an outward-rounded interval.
"""
from __future__ import annotations

from collections import Counter
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import function, rational_interval
from fossil_dsl.solvers.api import UnsupportedTheory


class Compiler:
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
        return combine(definitions + [contractor] + definitions[::-1], lambda a, b: a & b)

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
            return combine(kept, lambda a, b: a & b) if kept else None
        if any(p is None for p in parts):
            return None
        return combine(parts, lambda a, b: a | b)

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
            return combine([self.expr(t) for t in expr.terms], lambda a, b: a + b)
        if isinstance(expr, E.Mul):
            # x*x as sqr(x): interval multiplication does not know both factors are one
            counts = Counter(expr.factors)
            factors = [self.expr(f) if n == 1 else self.power(E.Pow(f, E.Num(n)))
                       for f, n in counts.items()]
            return combine(factors, lambda a, b: a * b)
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


def combine(items, join):
    """items[0] join items[1] join ... (codac's contractors and expressions)."""
    result = items[0]
    for item in items[1:]:
        result = join(result, item)
    return result
