"""A vector field as polynomials for the sum-of-squares programs (sos_barrier.py,
sos_roa.py): f = N / Q with Q > 0 on D, in the states and, for a field with sin, tanh,
exp, ..., a variable per function application bounded by the facts it satisfies on D
(solvers/atom_facts.py). A condition such as -grad V . N - e|x|^2 >= 0, proved for
every value the facts allow, then holds for the true field (dV/dt = grad V . N / Q).

Nothing here is trusted: the programs' functions are proved like any candidate.
"""
from __future__ import annotations

from dataclasses import dataclass

from fossil_dsl.engine.rational_field import over_one_denominator
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.plan.compile import Plan
from fossil_dsl.solvers.atom_facts import abstracted_terms
from fossil_dsl.solvers.cleared import common_denominator
from fossil_dsl.solvers.positivstellensatz import comparisons


@dataclass(frozen=True)
class PolynomialField:
    variables: int  # the states, then a variable per function application
    numerators: list  # N, over all the variables
    denominator: P.Polynomial  # Q > 0 on D (1 for a polynomial field)
    facts: list  # g >= 0 over all the variables: what the applications satisfy on D


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
    return PolynomialField(len(names), numerators, denominator, constraints)


def padded(constraints: list[P.Polynomial], n: int) -> list[P.Polynomial]:
    """The constraints over the first variables as polynomials in n variables."""
    return [{widened(m, n): c for m, c in g.items()} for g in constraints]


def widened(monomial: P.Monomial, n: int) -> P.Monomial:
    """The monomial over the first variables as one over n (exponent 0 for the rest)."""
    return monomial + (0,) * (n - len(monomial))
