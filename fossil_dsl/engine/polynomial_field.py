"""A vector field as polynomials for the sum-of-squares programs (sos_barrier.py,
sos_roa.py): f = N / Q with Q > 0 on D, in the states and, for a field with sin, tanh,
exp, ..., a variable per function application bounded by the facts it satisfies on D
(solvers/atom_facts.py). A condition such as -grad V . N - e|x|^2 >= 0, proved for
every value the facts allow, then holds for the true field (dV/dt = grad V . N / Q).

Nothing here is trusted: the programs' functions are proved like any candidate.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from fractions import Fraction

from fossil_dsl.engine.rational_field import over_one_denominator
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.plan.compile import Plan
from fossil_dsl.solvers.atom_facts import abstracted_terms, argument_range
from fossil_dsl.solvers.cleared import common_denominator
from fossil_dsl.solvers.positivstellensatz import comparisons


@dataclass(frozen=True)
class PolynomialField:
    variables: int  # the states, then a variable per function application
    numerators: list  # N, over all the variables
    denominator: P.Polynomial  # Q > 0 on D (1 for a polynomial field)
    facts: list  # g >= 0 over all the variables: what the applications satisfy on D
    # (celled_field) per cell of D's box, its bounds ((lo, hi) per state) and its sides
    # and facts (g >= 0 over all the variables): a condition is asked on each cell
    cells: tuple = ()

    def regions(self, piece: list[P.Polynomial]) -> list[list[P.Polynomial]]:
        """The constraints a condition with the field is asked under on a piece (over the
        states): the facts on D, else those of each cell that may meet the piece."""
        if not self.cells:
            return [self.facts]
        return [constraints for box, constraints in self.cells if _may_meet(box, piece)]


# cells of celled_field, at most: 8 x 8 in 2 states (probe77/ba11: a margin of 0.38 with
# the Taylor facts on each, none with 4 x 6, whose arguments' ranges are too wide)
MAX_CELLS = 64


def exact_field(plan: Plan, terms) -> PolynomialField | None:
    """The field `terms` (the spec's, or its closed loop) in polynomial form on D (see the
    module's text; exact, unlike surrogate.py's fitted stand-in); None where it has a
    function with no facts (log, sqrt) or a denominator of unknown sign."""
    spec, states = plan.spec, plan.states
    region = spec.domain.contains_formula(states)
    n = len(states)
    try:
        return PolynomialField(n, [P.polynomial(f, states) for f in terms], P.constant(1, n), [])
    except P.NotPolynomial:
        pass
    if all(traversal.is_arithmetic(f) for f in terms):
        found = over_one_denominator(terms, states, spec.domain.bounding_box(),
                                     plan.options.seed)
        return None if found is None else PolynomialField(n, found[0], found[1], [])
    found = _abstracted(terms, region, states)
    return None if found is None else PolynomialField(*found)


def celled_field(plan: Plan, terms) -> PolynomialField | None:
    """exact_field's form of a field with functions, with D's box cut into a grid of at
    most MAX_CELLS cells, each with the facts that hold on it (None where there is no
    such form or grid): an argument's range on a cell is narrow, where tanh, sin and
    cos are their Taylor polynomial within a small ε (solvers/taylor_facts.py) rather
    than a sector through the origin, which on D as a whole holds a tanh network's
    unstable linear part and the saturated map alike (probe77/ba11: no V for the
    sector, a quartic on 8 x 8 cells)."""
    states, domain = plan.states, plan.spec.domain
    box, whole = domain.bounding_box(), exact_field(plan, terms)
    parts = int(MAX_CELLS ** (1 / len(states)) + 1e-9)
    if box is None or whole is None or not whole.facts or parts < 2:
        return None
    cells = []
    for bounds in _grid(box, parts):
        cell = L.conjunction(*(L.Compare(relation, E.Var(s), E.Num(value))
                               for s, (lo, hi) in zip(states, bounds)
                               for relation, value in ((">=", lo), ("<=", hi))))
        found = _abstracted(terms, L.conjunction(domain.contains_formula(states), cell),
                            states)
        if found is None or found[1:3] != (whole.numerators, whole.denominator):
            return None
        sides = [P.polynomial(E.add(E.Var(s), E.Num(-lo)), states) for s, (lo, _) in
                 zip(states, bounds)] + [P.polynomial(E.add(E.Num(hi), E.neg(E.Var(s))),
                                                      states)
                                         for s, (_, hi) in zip(states, bounds)]
        cells.append((bounds, sides + found[3]))
    return replace(whole, cells=tuple(cells))


def _abstracted(terms, region: L.Formula, states):
    """(variables, N, Q, facts) of exact_field's form with the facts on `region`."""
    over = common_denominator(terms, region)
    if over is None:
        return None
    found = abstracted_terms([*over[0], over[1]], region, states)
    if found is None:
        return None
    expressions, facts, names = found
    try:
        *numerators, denominator = [P.polynomial(e, names) for e in expressions]
        constraints = [h for fact in facts for h, _ in comparisons(fact, names)]
    except ValueError:  # not polynomial after all (a function of a quotient, say)
        return None
    return len(names), numerators, denominator, constraints


def _grid(box, parts: int):
    """The cells of the box cut into `parts` equal pieces along each axis, as bounds."""
    axes = []
    for lo, hi in zip(*box):
        lo, hi = Fraction(lo), Fraction(hi)
        cuts = [lo + (hi - lo) * Fraction(k, parts) for k in range(parts + 1)]
        axes.append(list(zip(cuts, cuts[1:])))
    return itertools.product(*axes)


def _may_meet(bounds, piece: list[P.Polynomial]) -> bool:
    """False where some g >= 0 of the piece (over the states) is negative on the whole
    cell (exact bounds of g over the cell's box)."""
    names = [f"x{i}" for i in range(len(bounds))]
    cell = L.conjunction(*(L.Compare(relation, E.Var(name), E.Num(value))
                           for name, (lo, hi) in zip(names, bounds)
                           for relation, value in ((">=", lo), ("<=", hi))))
    for g in piece:
        found = argument_range(cell, P.to_expr(g, names))
        if found is not None and found[1] < 0:
            return False
    return True


def padded(constraints: list[P.Polynomial], n: int) -> list[P.Polynomial]:
    """The constraints over the first variables as polynomials in n variables."""
    return [{widened(m, n): c for m, c in g.items()} for g in constraints]


def widened(monomial: P.Monomial, n: int) -> P.Monomial:
    """The monomial over the first variables as one over n (exponent 0 for the rest)."""
    return monomial + (0,) * (n - len(monomial))
