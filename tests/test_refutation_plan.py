"""A conjunction refuted part by part (solvers/refutation_plan.py): the parts that share no
variable are found, a part is refuted over its own variables only, and the refutation,
lifted back to the whole query, passes the kernel's exact check; a satisfiable query with
such parts still gets none."""
import time
from fractions import Fraction as F

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.positivstellensatz import (SumOfSquares, comparisons,
                                                  polynomial_form, refutation_problem)
from fossil_dsl.solvers.refutation_plan import independent_parts
from fossil_dsl.solvers.sos_refutation import refute

STATES = ("a", "b", "c", "d")
A, B, C, D = (E.Var(s) for s in STATES)


def _n(value) -> E.Num:
    return E.Num(F(value))


def _query(margin: F) -> L.Formula:
    """sin(a) + b c <= a - a^3/6 + a^5/120 - margin on a in [1, 1.1], b, c, d in
    [-1/20, 1/20]: d is bounded and nothing else. Unsatisfiable for margin 1/100 (the
    Taylor polynomial exceeds sin a by at most 2e-4 there, b c >= -1/400), satisfiable
    for margin -1/100."""
    bounds = [L.Compare(">=", A, _n(1)), L.Compare("<=", A, _n(F(11, 10)))]
    for v in (B, C, D):
        bounds += [L.Compare(">=", v, _n(F(-1, 20))), L.Compare("<=", v, _n(F(1, 20)))]
    taylor = E.add(A, E.mul(_n(F(-1, 6)), E.power(A, _n(3))),
                   E.mul(_n(F(1, 120)), E.power(A, _n(5))))
    left = E.add(E.apply("sin", A), E.mul(B, C))
    return L.conjunction(*bounds, L.Compare("<=", left, E.add(taylor, _n(-margin))))


def test_the_parts_are_the_groups_of_atoms_that_share_variables():
    x, y, z = (1, 0, 0), (0, 1, 0), (0, 0, 1)
    atoms = [({x: F(1)}, False), ({z: F(1), (0, 0, 0): F(1)}, False),
             ({x: F(1), y: F(1)}, True), ({(0, 0, 0): F(1)}, True)]
    assert independent_parts(atoms) == [([0, 2, 3], (0, 1)), ([1, 3], (2,))]
    assert independent_parts(atoms[:1]) == [([0], (0,))]


def test_a_state_bounded_and_nothing_else_does_not_spoil_the_refutation():
    query = _query(F(1, 100))
    found = refute(query, STATES, time.monotonic() + 60, 12_000)
    assert found is not None
    assert refutation_problem(found, query, STATES) is None
    poly_query, poly_states = polynomial_form(query, STATES)
    atoms = comparisons(poly_query, poly_states)
    d = poly_states.index("d")
    on_d = [i for i, (h, _) in enumerate(atoms) if any(m[d] for m in h)]
    assert len(on_d) == 2 and all(found.multipliers[i] is None for i in on_d)
    assert all(len(m) == len(poly_states) for m in found.rest.monomials)
    broken = type(found)(found.multipliers, SumOfSquares(found.rest.monomials[1:],
                                                         found.rest.gram[1:]),
                         found.constant, found.products)
    assert refutation_problem(broken, query, STATES) is not None


def test_a_satisfiable_query_with_an_independent_part_has_no_refutation():
    assert refute(_query(F(-1, 100)), STATES, time.monotonic() + 30, 12_000) is None
