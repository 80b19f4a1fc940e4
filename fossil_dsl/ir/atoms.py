"""Expressions as polynomials in the states and their atoms: each maximal subterm that is
not a polynomial operation (sin(x), exp(x - y), x / y, pi) becomes an indeterminate of
its own, the same one wherever the same subterm occurs.

Where a difference is the zero polynomial (or a number) over these indeterminates it is
zero (or that number) for every value the atoms take, so a comparison between such sides
is decided exactly: the derivative of a conserved quantity along the flow,
-2*(-sin(x))*y + 2*y*(-sin(x)), is 0, which a numerical procedure cannot show (its
enclosure of the sum is an interval round 0). Definedness is not touched: an atom that
is undefined somewhere (log, division) still has its own obligation.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P

_POLYNOMIAL_NODES = (E.Num, E.Var, E.Add, E.Mul, E.Neg)
# larger sides are left to the procedures: expanding a network's derivative over its
# atoms can take seconds, and a conserved quantity's derivative is small
MAX_NODES = 500


class AtomTable:
    """One indeterminate per distinct atom, shared by every expression given."""

    def __init__(self, states: Sequence[str]):
        self.states = list(states)
        self.atoms: dict[E.Expr, E.Var] = {}

    def polynomials(self, expressions) -> list[P.Polynomial]:
        """Each expression as a polynomial in the states, then the atoms (in order of
        first appearance)."""
        replaced = [_replace_atoms(e, self.states, self.atoms) for e in expressions]
        names = self.states + [v.name for v in self.atoms.values()]
        return [P.polynomial(e, names) for e in replaced]


def over_atoms(expr: E.Expr, states: Sequence[str]) -> tuple[P.Polynomial, list[E.Expr]]:
    """(the polynomial in states + atoms, the atoms in the order of their variables)."""
    table = AtomTable(states)
    return table.polynomials([expr])[0], list(table.atoms)


def folded(formula: L.Formula, states: Sequence[str]) -> L.Formula:
    """The formula with each comparison whose sides differ by a number (over the atoms)
    replaced by that number's comparison with 0 (then `L.truth` decides it)."""
    if isinstance(formula, L.Compare):
        difference = E.add(formula.left, E.neg(formula.right))
        if isinstance(difference, E.Num):
            return L.Compare(formula.relation, difference, E.ZERO)
        nodes = list(E.walk(difference))
        if len(nodes) > MAX_NODES or not any(_is_atom(n, states) for n in nodes):
            return formula  # (the solvers decide polynomials exactly)
        polynomial, _ = over_atoms(difference, states)
        if any(any(monomial) for monomial in polynomial):
            return formula
        value = next(iter(polynomial.values()), Fraction(0))  # the constant term, or 0
        return L.Compare(formula.relation, E.Num(value), E.ZERO)
    if isinstance(formula, L.And):
        return L.conjunction(*(folded(a, states) for a in formula.args))
    if isinstance(formula, L.Or):
        return L.disjunction(*(folded(a, states) for a in formula.args))
    if isinstance(formula, L.Not):
        return L.negation(folded(formula.arg, states))
    return formula


def _is_atom(node: E.Expr, states) -> bool:
    if isinstance(node, E.Var):
        return node.name not in states
    if isinstance(node, E.Div):
        return not isinstance(node.denominator, E.Num)
    if isinstance(node, E.Pow):
        exponent = node.exponent
        return not (isinstance(exponent, E.Num) and exponent.value.denominator == 1
                    and exponent.value >= 0)
    return not isinstance(node, _POLYNOMIAL_NODES)


def _replace_atoms(expr: E.Expr, states, atoms: dict) -> E.Expr:
    if _is_atom(expr, states):
        if expr not in atoms:
            atoms[expr] = E.Var(f"@atom{len(atoms)}")
        return atoms[expr]
    if isinstance(expr, E.Add):
        return E.Add(tuple(_replace_atoms(t, states, atoms) for t in expr.terms))
    if isinstance(expr, E.Mul):
        return E.Mul(tuple(_replace_atoms(f, states, atoms) for f in expr.factors))
    if isinstance(expr, E.Neg):
        return E.Neg(_replace_atoms(expr.operand, states, atoms))
    if isinstance(expr, E.Div):  # by a number
        return E.Div(_replace_atoms(expr.numerator, states, atoms), expr.denominator)
    if isinstance(expr, E.Pow):  # a natural power
        return E.Pow(_replace_atoms(expr.base, states, atoms), expr.exponent)
    return expr
