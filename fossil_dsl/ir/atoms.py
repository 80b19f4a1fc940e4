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

import math
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.ir.functions import FUNCTIONS

_POLYNOMIAL_NODES = (E.Num, E.Var, E.Add, E.Mul, E.Neg)
# larger sides are left to the procedures: expanding a network's derivative over its
# atoms can take seconds, and a conserved quantity's derivative is small
MAX_NODES = 500
MAX_TERMS = 2_000  # of an expansion (bounded before expanding)


class AtomTable:
    """One indeterminate per distinct atom, shared by every expression given. A division
    by a product of states' powers is a product with their inverses, indeterminates
    of their own that cancel against the states (x * x^-1 = 1): the Laurent polynomials
    are a ring, so a difference that is 0 there is 0 wherever it is defined (x' / x for
    x' = x (1 - y) is 1 - y: the derivative of log(x) in a Lotka-Volterra system)."""

    def __init__(self, states: Sequence[str]):
        self.states = list(states)
        self.atoms: dict[E.Expr, E.Var] = {}
        self.inverses: dict[str, E.Var] = {}

    def polynomials(self, expressions) -> list[P.Polynomial]:
        """Each expression as a polynomial in the states, the atoms (in order of first
        appearance) and the states' inverses."""
        replaced = [self._replace(e) for e in expressions]
        names = self.names()
        pairs = [(self.states.index(s), names.index(v.name)) for s, v in self.inverses.items()]
        return [_cancelled(P.polynomial(e, names), pairs) for e in replaced]

    def names(self) -> list[str]:
        return self.states + [v.name for v in self.atoms.values()] + \
            [v.name for v in self.inverses.values()]

    def expression(self, polynomial: P.Polynomial) -> E.Expr:
        """The polynomial as an expression in the states, with the atoms put back."""
        back = {v.name: atom for atom, v in self.atoms.items()}
        back.update({v.name: E.div(E.ONE, E.Var(state)) for state, v in self.inverses.items()})
        return traversal.substitute(P.to_expr(polynomial, self.names()), back)

    def _replace(self, expr: E.Expr) -> E.Expr:
        if isinstance(expr, E.Div):
            inverse = self._inverse(expr.denominator)
            if inverse is not None:
                return E.mul(self._replace(expr.numerator), inverse)
        if _is_atom(expr, self.states):
            if expr not in self.atoms:
                self.atoms[expr] = E.Var(f"@atom{len(self.atoms)}")
            return self.atoms[expr]
        if isinstance(expr, (E.Add, E.Mul, E.Neg, E.Pow)):
            return traversal.rebuild(expr, tuple(self._replace(c) for c in E.children(expr)))
        return expr

    def _inverse(self, denominator: E.Expr) -> E.Expr | None:
        """1 / denominator where it is a number or a product of states' natural powers."""
        if isinstance(denominator, E.Num):
            return E.Num(1 / denominator.value) if denominator.value != 0 else None
        if isinstance(denominator, E.Var) and denominator.name in self.states:
            name = denominator.name
            return self.inverses.setdefault(name, E.Var(f"@inverse:{name}"))
        if isinstance(denominator, E.Pow) and not _is_atom(denominator, self.states):
            base = self._inverse(denominator.base)
            return None if base is None else E.power(base, denominator.exponent)
        if isinstance(denominator, E.Mul):
            factors = [self._inverse(f) for f in denominator.factors]
            return None if None in factors else E.mul(*factors)
        return None


def _cancelled(polynomial: P.Polynomial, pairs) -> P.Polynomial:
    """x^a (x^-1)^b as x^(a-b) or (x^-1)^(b-a), for each (state, inverse) place pair."""
    terms = []
    for monomial, coefficient in polynomial.items():
        exponents = list(monomial)
        for state, inverse in pairs:
            common = min(exponents[state], exponents[inverse])
            exponents[state] -= common
            exponents[inverse] -= common
        terms.append({tuple(exponents): coefficient})
    return P.add(*terms)


def over_atoms(expr: E.Expr, states: Sequence[str]) -> tuple[P.Polynomial, list[E.Expr]]:
    """(the polynomial in states + atoms, the atoms in the order of their variables)."""
    table = AtomTable(states)
    return table.polynomials([expr])[0], list(table.atoms)


def expanded(expr: E.Expr, states: Sequence[str]) -> E.Expr | None:
    """The expression expanded as a polynomial over its atoms, or None: where it is not
    defined everywhere (an expansion can cancel x / x, and with it an obligation), or
    where the expansion could have more than MAX_TERMS terms."""
    nodes = set(E.walk(expr))
    if not all(_defined_everywhere(node, states) for node in nodes):
        return None
    atoms = {node for node in nodes if isinstance(node, E.Apply)}
    count = len(states) + len(atoms)
    if math.comb(count + traversal.degree(expr), count) > MAX_TERMS:
        return None
    table = AtomTable(states)
    return table.expression(table.polynomials([expr])[0])


def _defined_everywhere(node: E.Expr, states) -> bool:
    """A polynomial operation, a number or an application of a total function."""
    if isinstance(node, E.Apply):
        return FUNCTIONS[node.func].total
    return not _is_atom(node, states) or isinstance(node, (E.Pi, E.Var))


def folded(formula: L.Formula, states: Sequence[str]) -> L.Formula:
    """The formula with each comparison whose sides differ by a number (over the atoms)
    replaced by that number's comparison with 0 (then `L.truth` decides it)."""
    return L.map_comparisons(formula, lambda c: _folded_comparison(c, states))


def _folded_comparison(comparison: L.Compare, states: Sequence[str]) -> L.Compare:
    difference = E.add(comparison.left, E.neg(comparison.right))
    if isinstance(difference, E.Num):
        return L.Compare(comparison.relation, difference, E.ZERO)
    nodes = list(E.walk(difference))
    if len(nodes) > MAX_NODES or not any(_is_atom(n, states) for n in nodes):
        return comparison  # (the solvers decide polynomials exactly)
    polynomial, _ = over_atoms(difference, states)
    if any(any(monomial) for monomial in polynomial):
        return comparison
    value = next(iter(polynomial.values()), Fraction(0))  # the constant term, or 0
    return L.Compare(comparison.relation, E.Num(value), E.ZERO)


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
