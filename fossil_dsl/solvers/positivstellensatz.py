"""An exact check of a sum-of-squares refutation of an obligation: no solver, only
rational arithmetic.

The obligation's query must be a conjunction; each of its polynomial comparisons is read as
h_j(x) >= 0 or h_j(x) > 0 (h_j: one side minus the other). A refutation gives, in the
query's order, a multiplier for each comparison: none, a rational constant c >= 0 (or
c h^(m-1), making the term c h^m), or a sum of squares m(x)^T G m(x) (G rational and
positive semidefinite); and a sum of squares s0. It refutes the query when

    s0(x) + sum_j sigma_j(x) h_j(x) + sum_(i,k) sigma_ik(x) h_i(x) h_k(x) = 0 for every x
                                               (every coefficient cancels exactly)

(the sigma_ik are sums of squares for chosen pairs of comparisons, such as a box's
lower and upper bound on one state: h_i h_k >= 0 wherever both hold), and some strict
comparison h_k > 0 has a constant multiplier c_k > 0 (or c_k h_k^(m-1)),
or a constant c > 0 is added to the sum (the strict comparison 1 > 0). At a point where
the query held, every term would be >= 0 with sum 0, so every term 0; but c_k h_k^m > 0
(or c > 0).
So no point satisfies the query, and the obligation holds.

A query with a disjunction among its conjuncts, C and (B_1 or ... or B_k) (a point on
the boundary of a box is on one of its faces), is refuted case by case (CaseSplit): a
refutation of each C and B_i, the cases computed here from the query.

A query with elementary functions (sin, exp, ...) is first made polynomial by
atom_facts.py: a variable per function application, and facts each such value
satisfies; a refutation of that polynomial query refutes the query.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.rational import numerator
from fossil_dsl.ir.expr import Num, Var, add, neg
from fossil_dsl.solvers.atom_facts import abstracted, has_atoms
from fossil_dsl.solvers.cleared import cleared


@dataclass(frozen=True)
class SumOfSquares:
    """m(x)^T G m(x): monomials as exponent vectors, G as rows of rationals."""

    monomials: tuple[P.Monomial, ...]
    gram: tuple[tuple[Fraction, ...], ...]

    def polynomial(self) -> P.Polynomial:
        terms: P.Polynomial = {}
        for a, row in zip(self.monomials, self.gram):
            for b, entry in zip(self.monomials, row):
                if entry:
                    P.accumulate(terms, {P.times(a, b): entry})
        return terms


@dataclass(frozen=True)
class Power:
    """c h^(exponent - 1) as the multiplier of h: the term c h^exponent (for a strict
    h > 0 and c > 0 that term is > 0, as a constant multiplier's is)."""

    coefficient: Fraction
    exponent: int


Multiplier = Fraction | Power | SumOfSquares | None


@dataclass(frozen=True)
class Product:
    """sigma h_first h_second: a sum of squares times the product of two comparisons."""

    first: int
    second: int
    square: SumOfSquares


@dataclass(frozen=True)
class Refutation:
    multipliers: tuple[Multiplier, ...]  # one per comparison of the query, in order
    rest: SumOfSquares  # s0
    constant: Fraction = Fraction(0)  # c >= 0 added to the sum (the comparison 1 > 0)
    products: tuple[Product, ...] = ()


@dataclass(frozen=True)
class CaseSplit:
    """Refutations of the cases of the query's conjunct number `conjunct`, a disjunction:
    one per disjunct, in order (see `cases`)."""

    conjunct: int
    cases: tuple["Refutation | CaseSplit", ...]


@dataclass(frozen=True)
class SlabSplit:
    """Refutations of the query in slabs across the variable: with v <= e_1, with
    e_k <= v <= e_(k+1), ..., with v >= e_K (see `slabs`); one per slab, in order. Every
    point has v in some slab, so the query is refuted if every slab's piece is."""

    variable: str
    edges: tuple[Fraction, ...]  # increasing
    slabs: tuple["Refutation | CaseSplit", ...]


Evidence = Refutation | CaseSplit | SlabSplit


def disjunction_branches(formula: L.Formula) -> tuple[L.Formula, ...] | None:
    """The disjuncts of a disjunction (a negated conjunction pushed inward), else None."""
    if isinstance(formula, L.Not):
        formula = L.negated_inward(formula.arg)
    return tuple(formula.args) if isinstance(formula, L.Or) else None


def cases(query: L.Formula, index: int) -> list[L.Formula] | None:
    """C and B_i for each disjunct B_i of the query's conjunct number `index` (C: the
    other conjuncts); None where that conjunct is not a disjunction. The query holds at
    a point exactly when one of the cases does."""
    parts = conjuncts(query)
    if not 0 <= index < len(parts):
        return None
    branches = disjunction_branches(parts[index])
    if branches is None:
        return None
    return [L.conjunction(*parts[:index], branch, *parts[index + 1:]) for branch in branches]


def slabs(query: L.Formula, variable: str, edges: Sequence[Fraction]) -> list[L.Formula]:
    """The pieces a SlabSplit refutes: the query with v <= e_1, with e_k <= v <= e_(k+1)
    for each next edge, and with v >= e_K."""
    ends = [None, *edges, None]
    return [slab(query, variable, low, high) for low, high in zip(ends, ends[1:])]


def slab(query: L.Formula, variable: str, low: Fraction | None, high: Fraction | None):
    """The query with low <= v <= high (None: no bound on that side)."""
    v = Var(variable)
    return L.conjunction(query, *([] if low is None else [L.Compare(">=", v, Num(low))]),
                         *([] if high is None else [L.Compare("<=", v, Num(high))]))


def comparisons(query: L.Formula, states: Sequence[str]) -> list[tuple[P.Polynomial, bool]]:
    """(h, strict) for each comparison h >= 0 / h > 0 among the query's conjuncts;
    raises ValueError where one is not polynomial, or where there is none. A side with
    divisions by evidently positive polynomials (1 + z^2) gives h = N, the numerator of
    its form N / D over such a D: D > 0 everywhere, so h >= 0 exactly where N >= 0.

    Conjuncts that are not comparisons (a disjunction, such as "outside the unsafe box")
    are left out: a refutation of the other conjuncts proves that no point satisfies
    them, and so none satisfies the whole query."""
    found = []
    for atom in conjuncts(query):
        if isinstance(atom, L.Not) and isinstance(atom.arg, L.Compare) \
                and atom.arg.relation in NEGATED:
            inner = atom.arg
            atom = L.Compare(NEGATED[inner.relation], inner.left, inner.right)
        if not isinstance(atom, L.Compare):
            continue
        if atom.relation not in NEGATED:
            raise ValueError(f"not an inequality: {atom}")
        larger, smaller = (atom.left, atom.right) if atom.relation in (">", ">=") \
            else (atom.right, atom.left)
        found.append((numerator(add(larger, neg(smaller)), states),
                      atom.relation in ("<", ">")))
    if not found:
        raise ValueError("the query has no comparison among its conjuncts")
    return found


NEGATED = {"<": ">=", "<=": ">", ">": "<=", ">=": "<"}
# states from which a refutation is looked for before Z3 is asked: Z3's procedure grows
# exponentially with the variables (two balls in 8 dimensions: no answer in 5 s), the
# semidefinite program polynomially
BEFORE_Z3_FROM = 6


def conjuncts(query: L.Formula) -> list[L.Formula]:
    if isinstance(query, L.And):
        return [atom for arg in query.args for atom in conjuncts(arg)]
    return [query]


def polynomial_form(query: L.Formula, states: Sequence[str]) -> tuple[L.Formula, tuple]:
    """The query and its variables, its comparisons multiplied through the divisors whose
    signs Arb proves (cleared.py; the others are left to `comparisons`' form); a query
    with elementary functions as the polynomial query with a variable per function
    application and the facts every point of the query satisfies (atom_facts.py): a
    refutation of that one refutes the query."""
    query = cleared(query)
    if not has_atoms(query):
        return query, tuple(states)
    return abstracted(query, states)


def refutation_problem(refutation: Evidence, query: L.Formula,
                       states: Sequence[str]) -> str | None:
    """None if the refutation proves the query unsatisfiable; else what is wrong."""
    if isinstance(refutation, CaseSplit):
        return _case_split_problem(refutation, query, states)
    if isinstance(refutation, SlabSplit):
        return _slab_split_problem(refutation, query, states)
    query, states = polynomial_form(query, states)
    try:
        atoms = comparisons(query, states)
    except ValueError as exc:  # NotPolynomial is a ValueError too
        return f"the query is not a conjunction of polynomial comparisons ({exc})"
    if len(refutation.multipliers) != len(atoms):
        return f"{len(refutation.multipliers)} multipliers for {len(atoms)} comparisons"
    if any(not 0 <= i < len(atoms) for p in refutation.products for i in (p.first, p.second)):
        return "a product names a comparison the query does not have"
    squares = [refutation.rest] + [m for m in refutation.multipliers
                                   if isinstance(m, SumOfSquares)] \
        + [p.square for p in refutation.products]
    if not all(positive_semidefinite(s.gram) for s in squares):
        return "a Gram matrix is not positive semidefinite"
    if refutation.constant < 0:
        return "the constant is negative"
    total = P.add(refutation.rest.polynomial(), P.constant(refutation.constant, len(states)))
    for product in refutation.products:
        pair = P.multiply(atoms[product.first][0], atoms[product.second][0])
        total = P.add(total, P.multiply(product.square.polynomial(), pair))
    strict = refutation.constant > 0
    for (h, is_strict), multiplier in zip(atoms, refutation.multipliers):
        if multiplier is None:
            continue
        if isinstance(multiplier, SumOfSquares):
            total = P.add(total, P.multiply(multiplier.polynomial(), h))
            continue
        if isinstance(multiplier, Fraction):
            multiplier = Power(multiplier, 1)
        if multiplier.coefficient < 0 or multiplier.exponent < 1:
            return "a constant multiplier is negative, or a power is below 1"
        term = P.power(h, multiplier.exponent, len(states))
        total = P.add(total, P.scale(term, multiplier.coefficient))
        strict = strict or (is_strict and multiplier.coefficient > 0)
    if not strict:
        return "no strict comparison has a positive constant multiplier, and no constant"
    if total:
        return f"the identity fails: {len(total)} coefficients do not cancel"
    return None


def _case_split_problem(split: CaseSplit, query: L.Formula, states) -> str | None:
    found = cases(query, split.conjunct)
    if found is None:
        return f"conjunct {split.conjunct} of the query is not a disjunction"
    return _pieces_problem(found, split.cases, states, "case")


def _slab_split_problem(split: SlabSplit, query: L.Formula, states) -> str | None:
    if split.variable not in states:
        return f"the slabs are across {split.variable}, not a state"
    if any(low >= high for low, high in zip(split.edges, split.edges[1:])):
        return "the slabs' edges do not increase"
    return _pieces_problem(slabs(query, split.variable, split.edges), split.slabs, states,
                           "slab")


def _pieces_problem(pieces, refutations, states, kind: str) -> str | None:
    """None if each piece has its refutation (one each, in order)."""
    if len(pieces) != len(refutations):
        return f"{len(refutations)} refutations for {len(pieces)} {kind}s"
    for number, (piece, refutation) in enumerate(zip(pieces, refutations), 1):
        problem = refutation_problem(refutation, piece, states)
        if problem is not None:
            return f"{kind} {number}: {problem}"
    return None


def positive_semidefinite(gram: Sequence[Sequence[Fraction]]) -> bool:
    """Exactly: G symmetric, and the coefficients of its characteristic polynomial
    det(λI - G) = sum c_k λ^k alternate in sign, (-1)^(n-k) c_k >= 0. (The eigenvalues
    λ_i of a symmetric matrix are real; (-1)^n p(-μ) = prod (μ + λ_i) has coefficients
    >= 0 when every λ_i >= 0, and a positive root -λ_i, impossible with such
    coefficients, when some λ_i < 0.) The polynomial is computed in exact rationals by
    FLINT: 75 times quicker than Gaussian elimination on Python fractions, which took 4.8
    of a 44-by-44 refutation's 6.8 s."""
    import flint
    n = len(gram)
    if any(len(row) != n for row in gram):
        return False
    matrix = flint.fmpq_mat(n, n, [_fmpq(v) for row in gram for v in row])
    if any(matrix[i, j] != matrix[j, i] for i in range(n) for j in range(i)):
        return False
    coefficients = matrix.charpoly().coeffs()  # c_0, ..., c_n (c_n = 1)
    return all((c if (n - k) % 2 == 0 else -c) >= 0 for k, c in enumerate(coefficients))


def _fmpq(value):
    import flint
    value = Fraction(value)
    return flint.fmpq(value.numerator, value.denominator)
