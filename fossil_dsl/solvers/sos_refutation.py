"""Sum-of-squares refutations: a decision procedure that only ever proves.

For a query that is a conjunction of polynomial comparisons h_j >= 0 (or > 0), find
multipliers with s0 + sum_j sigma_j h_j (+ c) = 0 (positivstellensatz.py states why
that proves the query unsatisfiable) by a semidefinite program (sdp.py), round them to
rationals, and absorb the rounding error into s0's Gram matrix exactly (an orthogonal
projection onto the Gram matrices that satisfy the identity: each entry feeds one
monomial, so each monomial's residual is spread evenly over its entries). The result is
checked exactly before it is returned: a refutation from here is a proof. `SosBackend`
answers UNSAT with it, and UNKNOWN otherwise (never SAT: it finds no counterexamples).
A query with elementary functions is refuted through its polynomial form
(positivstellensatz.polynomial_form).
"""
from __future__ import annotations

import math
import time
from fractions import Fraction
from typing import Sequence

import numpy as np

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import traversal
from fossil_dsl.ir import polynomials as P
from fossil_dsl.solvers.api import Answer, Status
from fossil_dsl.solvers.atom_facts import has_atoms, replaceable
from fossil_dsl.solvers.cleared import cleared
from fossil_dsl.solvers.gram_rounding import (MULTIPLIER_DECIMALS, decimal, projected,
                                             psd_square, settled)
from fossil_dsl.solvers.positivstellensatz import (CaseSplit, Evidence, Power, Product,
                                                  Refutation, cases, comparisons, conjuncts,
                                                  disjunction_branches, polynomial_form,
                                                  refutation_problem)
from fossil_dsl.solvers.refutation_plan import (independent_parts, opposite_bounds, restricted,
                                               variants, widened)
from fossil_dsl.solvers.sdp import Program

MAX_VARIABLES = 30_000  # beyond this a program is not tried (time, memory)
# for a query with elementary functions (tried first in the loop, on every query, most
# of which it cannot refute), small programs only: a 3-state map's invariance condition
# with sin and cos gave programs of 22 000 variables at 80 s each, another's of 1000 to
# 2600 variables 0.3 to 5.5 s each, none a refutation; the refutations found (4- and
# 6-state Lyapunov conditions with sin and tanh) are programs of a few hundred
ATOMS_MAX_VARIABLES = 1_000
# s0's Gram entries, at most, of a program with multipliers of raised degree (queries of
# degree up to 12 in 2 states, 6 in 3 or 4 in 4)
RAISED_MAX_ENTRIES = 1_000
# and only for polynomial queries (not the abstractions of sin, tanh, ..., tried on every
# query of the loop) of at least this degree: set relations (linear, quadratic) gain
# nothing from them, and in 7 states each such query took 2 s more, which spent the
# checker's 5 s for all of a spec's relations (probe48/c11 was refused as a bad spec)
RAISED_FROM_DEGREE = 4
POWERS = (1, 2)  # a strict comparison h > 0 enters as c h, else c h^2 (quartic decreases)


class SosBackend:
    name = "sum of squares (exact)"

    def check(self, formula: L.Formula, variables: Sequence[str], timeout: float,
              stop=None) -> Answer:
        found = refute(formula, variables, time.monotonic() + timeout)
        if found is None:
            return Answer(Status.UNKNOWN, reason="no sum-of-squares refutation found")
        return Answer(Status.UNSAT, solver=self.name, evidence=found)


def refute(query: L.Formula, states, deadline: float,
           atoms_limit: int = ATOMS_MAX_VARIABLES) -> Evidence | None:
    """A refutation of the query that checks exactly (see the module's text), or None;
    where the conjuncts without a disjunction are not refuted, one of the query's
    disjunctions case by case (a point on a box's boundary is on one of its faces).
    `atoms_limit`: the largest program tried for a query with elementary functions."""
    found = _refuted_conjunction(query, states, deadline, atoms_limit)
    if found is not None:
        return found
    for index in _disjunctions(query):
        split = _refuted_cases(query, states, index, deadline, atoms_limit)
        if split is not None or time.monotonic() > deadline:
            return split
    return None


MAX_CASES = 32  # disjuncts of a disjunction refuted case by case, at most


def _disjunctions(query: L.Formula) -> list[int]:
    """The indices of the query's conjuncts that are disjunctions of at most MAX_CASES
    disjuncts, fewest disjuncts first."""
    found = [(len(branches), index) for index, part in enumerate(conjuncts(query))
             if (branches := disjunction_branches(part)) is not None
             and len(branches) <= MAX_CASES]
    return [index for _, index in sorted(found)]


def _refuted_cases(query: L.Formula, states, index: int, deadline: float,
                   atoms_limit: int) -> CaseSplit | None:
    found = []
    for case in cases(query, index):
        refutation = _refuted_conjunction(case, states, deadline, atoms_limit)
        if refutation is None:
            return None
        found.append(refutation)
    split = CaseSplit(index, tuple(found))
    return split if refutation_problem(split, query, states) is None else None


def _refuted_conjunction(query: L.Formula, states, deadline: float,
                         atoms_limit: int = ATOMS_MAX_VARIABLES) -> Refutation | None:
    abstract = has_atoms(query)
    if abstract and _least_abstracted_size(query, states) > atoms_limit:
        return None  # before abstracting and expanding: a tanh network's V has dozens
    query, states = polynomial_form(query, states)
    try:
        atoms = comparisons(query, states)
    except ValueError:
        return None
    for part, variables in independent_parts(atoms):
        variables = variables or tuple(range(len(states)))  # only constants: keep them all
        kept = restricted([atoms[i] for i in part], variables)
        for found in _candidates(kept, len(variables), abstract, deadline, atoms_limit):
            found = widened(found, part, len(atoms), variables, len(states))
            if refutation_problem(found, query, states) is None:
                return found
    return None


def _candidates(atoms, n: int, abstract: bool, deadline: float, atoms_limit: int):
    """The rounded solutions of the programs tried for these atoms, in order."""
    powers, limit = ((1,), atoms_limit) if abstract else (POWERS, MAX_VARIABLES)
    bounds = None if abstract else opposite_bounds(atoms)
    lows = (0, 1, 2) if not abstract and _origin_left_out(atoms, n) else (1, 2, 0)
    for power, low, pairs, raised, closed in variants(
            powers, bounds, _raise_worthwhile(abstract, n, atoms), lows,
            _closure_worthwhile(atoms)):
        if time.monotonic() > deadline or _smallest_size(n, atoms, power) > limit:
            return
        try:
            program = _RefutationProgram(n, atoms, low, power, pairs, raised, closed)
        except _Hopeless:
            continue
        if program.count > limit:
            if pairs:  # the products made it too large; the next program may not be
                continue
            return
        x = program.solve({program.interior: -1.0}, deadline - time.monotonic())
        found = program.exact(x) if x is not None else None
        if found is not None:
            yield found


def _raise_worthwhile(abstract: bool, n: int, atoms) -> bool:
    """Whether the programs with raised multipliers are tried: polynomial queries of
    degree RAISED_FROM_DEGREE or more whose raised s0 stays small."""
    degree = max((P.degree(h) for h, _ in atoms), default=0)
    return (not abstract and degree >= RAISED_FROM_DEGREE
            and _smallest_size(n, atoms, POWERS[0], 1) <= RAISED_MAX_ENTRIES)


def _origin_left_out(atoms, n: int) -> bool:
    """Whether the origin violates one of the comparisons (h(0) < 0). In a program with
    low 1 or 2, s0 and every multiplier vanish at the origin, so the identity there
    leaves only the strict comparisons' constants, which must cancel; such programs are
    made for conditions that hold up to the origin (the kernel's lemma near it). Where
    the origin violates the query, programs with constant terms come first: a 5-state
    map's reach decrease (probe49/e08) failed three low-1 and low-2 programs (11 s)
    before the low-0 one (12 s)."""
    zero = (0,) * n
    return any(h.get(zero, 0) < 0 for h, _ in atoms)


def _closure_worthwhile(atoms) -> bool:
    """Whether a strict comparison would get a multiplier that is not a constant if it
    were read as h >= 0 (its degree is at least 2 below the query's)."""
    top = max(2, max(P.degree(h) for h, _ in atoms))
    return any(strict and 2 * ((top + 1) // 2) - P.degree(h) >= 2 for h, strict in atoms)


def _least_abstracted_size(query: L.Formula, states) -> int:
    """_smallest_size for the query's polynomial form, estimated from its expressions as
    they are, divisions cleared (no expansion): a variable per distinct application, and
    the syntactic degree bound with each application counted as degree 1."""
    sides = [side for c in L.comparisons(cleared(query)) for side in (c.left, c.right)]
    replaced = {node for side in sides for node in E.walk(side) if replaceable(node)}
    return _gram_entries(len(states) + len(replaced), max(map(traversal.degree, sides)))


def _smallest_size(n: int, atoms, power: int, raised: int = 0) -> int:
    """The entries of s0's Gram matrix alone (a lower bound on the program's size, known
    before building it: building a program of 700 000 variables took 9 s)."""
    return _gram_entries(n, max(P.degree(h) * (power if strict else 1) for h, strict in atoms)
                         + 2 * raised)


def _gram_entries(n: int, degree: int) -> int:
    """The entries of a symmetric Gram matrix over the monomials of n variables up to
    half of max(2, degree), rounded up."""
    size = math.comb(n + (max(2, degree) + 1) // 2, n)
    return size * (size + 1) // 2


class _RefutationProgram(Program):
    """s0 + sum_j sigma_j h_j + sum_(i,k) sigma_ik h_i h_k = 0: sigma_j SOS for non-strict
    h_j >= 0, constants c_k >= 0 for strict h_k > 0 with sum c_k = 1, sigma_ik SOS for
    the `pairs`; s0 = m^T (Q + tI) m with Q >= 0, and t (at most 1) as large as possible,
    so that s0's Gram matrix survives rounding."""

    def __init__(self, n: int, atoms: list[tuple[P.Polynomial, bool]], low: int, power: int,
                 pairs: list[tuple[int, int]] = (), raised: int = 0, closed: bool = False):
        super().__init__(n)
        if closed:  # h > 0 read as h >= 0: sound, h > 0 implies it
            atoms = [(h, False) for h, _ in atoms]
        self.atoms = [(P.power(h, power, n) if strict else h, strict) for h, strict in atoms]
        self.power = power
        top = max(2, max(P.degree(h) for h, _ in self.atoms))
        half = (top + 1) // 2 + raised
        self.multipliers: list = []
        for h, strict in self.atoms:
            room = (2 * half - P.degree(h)) // 2
            if not strict and room >= low:
                basis = P.monomials(n, low, room)
                self.multipliers.append(("square", basis,
                                         self.gram(basis, times=h)))
            elif strict or P.low_degree(h) >= 2 * low:  # s0 keeps no term below 2 low
                c = self.scalar()
                self.add_term(c, h)
                self.at_most.append(({c: -1.0}, 0.0))  # c >= 0
                self.multipliers.append(("constant", c))
            else:
                self.multipliers.append(("none",))
        self.products = []
        for i, k in pairs:
            h = P.multiply(atoms[i][0], atoms[k][0])
            room = (2 * half - P.degree(h)) // 2
            if room >= low:
                basis = P.monomials(n, low, room)
                self.products.append((i, k, basis,
                                      self.gram(basis, times=h), h))
        strict = [m[1] for m, (_, s) in zip(self.multipliers, atoms) if s]
        self.constant_term = None
        if low == 0:  # the comparison 1 > 0 (s0 and the multipliers have constant terms)
            self.constant_term = self.scalar()
            self.add_term(self.constant_term, P.constant(1, n))
            self.at_most.append(({self.constant_term: -1.0}, 0.0))
            strict.append(self.constant_term)
        if not strict:
            raise _Hopeless()
        self.equalities.append(({c: 1.0 for c in strict}, 1.0))
        self.basis = cancellable(P.monomials(n, low, half), {m for _, m in self.identity})
        self.rest = self.gram(self.basis)
        self.interior = self.scalar()
        self.add_term(self.interior, {P.times(m, m): Fraction(1) for m in self.basis})
        self.at_most.append(({self.interior: 1.0}, 1.0))

    def exact(self, x) -> Refutation | None:
        multipliers, squares, factors, total = [], [], [], {}
        for (h, strict), multiplier in zip(self.atoms, self.multipliers):
            if multiplier[0] == "constant":
                c = max(Fraction(0), decimal(x[multiplier[1]], MULTIPLIER_DECIMALS))
                multipliers.append(Power(c, self.power) if strict and self.power > 1 else c)
                total = P.add(total, P.scale(h, c))
            elif multiplier[0] == "square":
                multipliers.append(multiplier)  # replaced by its rounded square below
                squares.append(psd_square(multiplier[1], self.matrix(x, multiplier[2],
                                                                     len(multiplier[1]))))
                factors.append(h)
            else:
                multipliers.append(None)
        squares += [psd_square(basis, self.matrix(x, entries, len(basis)))
                    for _, _, basis, entries, _ in self.products]
        factors += [h for *_, h in self.products]
        if any(square is None for square in squares):
            return None
        for square, h in zip(squares, factors):
            total = P.add(total, P.multiply(square.polynomial(), h))
        constant = Fraction(0)
        if self.constant_term is not None:
            constant = max(Fraction(0), decimal(x[self.constant_term], MULTIPLIER_DECIMALS))
            total = P.add(total, P.constant(constant, self.n))
        reach = {P.times(a, b) for a in self.basis for b in self.basis}
        if (settled_ := settled(squares, factors, total, reach)) is None:
            return None
        squares, total = settled_
        G = self.matrix(x, self.rest, len(self.basis)) + x[self.interior] * np.eye(len(self.basis))
        rest = projected(self.basis, G, P.scale(total, -1))
        if rest is None:
            return None
        rounded = iter(squares)
        multipliers = [next(rounded) if isinstance(m, tuple) else m for m in multipliers]
        products = [Product(i, k, next(rounded)) for i, k, *_ in self.products]
        return Refutation(tuple(multipliers), rest, constant, tuple(products))


def cancellable(basis: list[P.Monomial], support: set[P.Monomial]) -> list[P.Monomial]:
    """The monomials m of s0's Gram basis whose square s0 can hold: m^2 is a term the
    rest of the identity can have (`support`), or a product of two other monomials kept.
    Any other m has a zero diagonal entry in every solution, hence a zero row (the Gram
    matrix is PSD), so dropping it loses nothing, and s0 + tI can then have t > 0: a
    cart-pole's decrease with cos abstracted (probe49/e09) had w^4 in the basis with
    nothing to cancel it, which forced t = 0. Repeated, as each drop removes products."""
    kept = list(basis)
    while True:
        products = {P.times(a, b) for i, a in enumerate(kept) for b in kept[i + 1:]}
        pruned = [m for m in kept if P.times(m, m) in support or P.times(m, m) in products]
        if len(pruned) == len(kept):
            return kept
        kept = pruned


class _Hopeless(Exception):
    """No strict comparison to refute with (and no constant in this basis)."""
