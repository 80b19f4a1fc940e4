"""The kernel's exact check of sum-of-squares refutations: what it accepts is a proof,
and nothing forged, rounded or tampered gets through."""
from fractions import Fraction as F

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.solvers import sos_refutation
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.evidence_json import refutation_from_json, refutation_json
from fossil_dsl.solvers.positivstellensatz import (Refutation, SumOfSquares, positive_semidefinite,
                                                  refutation_problem)

X, Y = E.Var("x"), E.Var("y")
STATES = ("x", "y")


def sq(e):
    return E.power(e, E.Num(F(2)))


NORM = E.add(sq(X), sq(Y))
# x in the unit disc, x != 0, and V = x^2 + y^2 <= 0: unsatisfiable
QUERY = L.conjunction(L.Compare("<=", NORM, E.Num(F(1))), L.Compare(">", NORM, E.ZERO),
                      L.negation(L.Compare(">", NORM, E.ZERO)))
# s0 = 0, multipliers: none for the disc, 1 for |x|^2 > 0, 1 for -(x^2+y^2) >= 0
ZERO_SQUARE = SumOfSquares(((1, 0), (0, 1)), ((F(0), F(0)), (F(0), F(0))))
HAND_MADE = Refutation((None, F(1), F(1)), ZERO_SQUARE)


def test_a_hand_made_refutation_is_accepted():
    assert refutation_problem(HAND_MADE, QUERY, STATES) is None


@pytest.mark.parametrize("forged, complaint", [
    (Refutation((None, F(1)), ZERO_SQUARE), "multipliers for 3"),
    (Refutation((None, F(1), F(2)), ZERO_SQUARE), "identity fails"),
    (Refutation((None, F(0), F(1)), ZERO_SQUARE), "no strict comparison"),
    (Refutation((None, F(-1), F(1)), ZERO_SQUARE), "negative"),
    (Refutation((None, F(1), F(1)), SumOfSquares(((1, 0), (0, 1)), ((F(-1), F(0)), (F(0), F(1))))),
     "not positive semidefinite"),
])
def test_forged_refutations_are_rejected(forged, complaint):
    assert complaint in refutation_problem(forged, QUERY, STATES)


def test_a_satisfiable_query_has_no_refutation_and_a_borrowed_one_fails():
    satisfiable = L.conjunction(L.Compare("<=", NORM, E.Num(F(1))), L.Compare(">", NORM, E.ZERO),
                                L.Compare(">=", X, E.ZERO))
    import time
    assert sos_refutation.refute(satisfiable, STATES, time.monotonic() + 10) is None
    assert refutation_problem(HAND_MADE, satisfiable, STATES) is not None


def test_the_engine_finds_a_refutation_the_kernel_accepts_and_its_file_form_round_trips():
    # dV/dt of V = x^2 + y^2 along x' = -x + x*y, y' = -y, on the unit disc
    x_dot, y_dot = E.add(E.neg(X), E.mul(X, Y)), E.neg(Y)
    change = E.add(E.mul(E.Num(F(2)), X, x_dot), E.mul(E.Num(F(2)), Y, y_dot))
    query = L.conjunction(L.Compare("<=", NORM, E.Num(F(1))), L.Compare(">", NORM, E.ZERO),
                          L.negation(L.Compare("<", change, E.ZERO)))
    import time
    found = sos_refutation.refute(query, STATES, time.monotonic() + 30)
    assert found is not None and refutation_problem(found, query, STATES) is None
    again = refutation_from_json(refutation_json(found, STATES))
    assert again == found
    # the same refutation for a larger disc (where the claim is false: at (1.5, 1.4),
    # dV/dt > 0) does not check
    wider = L.conjunction(L.Compare("<=", NORM, E.Num(F(9))), L.Compare(">", NORM, E.ZERO),
                          L.negation(L.Compare("<", change, E.ZERO)))
    assert refutation_problem(found, wider, STATES) is not None


small = st.integers(-5, 5).map(F)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.lists(small, min_size=3, max_size=3), min_size=1, max_size=4))
def test_gram_products_are_positive_semidefinite(rows):
    """A^T A is PSD; subtracting more than its trace from a diagonal entry is not."""
    gram = [[sum(r[i] * r[j] for r in rows) for j in range(3)] for i in range(3)]
    assert positive_semidefinite(gram)
    trace = sum(gram[i][i] for i in range(3))
    broken = [row[:] for row in gram]
    broken[1][1] -= trace + 1
    assert not positive_semidefinite(broken)


def test_semidefinite_with_a_zero_pivot_and_asymmetric_matrices():
    assert positive_semidefinite([[F(0), F(0)], [F(0), F(1)]])
    assert not positive_semidefinite([[F(0), F(1)], [F(1), F(1)]])  # x^2 + 2xy... indefinite
    assert not positive_semidefinite([[F(1), F(0)], [F(1), F(1)]])  # not symmetric


def test_a_power_of_a_strict_comparison_refutes_and_round_trips():
    """|x|^2 > 0 and -(|x|^2)^2 >= 0: the term 1 * (|x|^2)^2 cancels the second."""
    from fossil_dsl.solvers.positivstellensatz import Power
    query = L.conjunction(L.Compare(">", NORM, E.ZERO),
                          L.Compare(">=", E.neg(E.power(NORM, E.Num(F(2)))), E.ZERO))
    good = Refutation((Power(F(1), 2), F(1)), ZERO_SQUARE)
    assert refutation_problem(good, query, STATES) is None
    assert refutation_from_json(refutation_json(good, STATES)) == good
    assert "power is below 1" in refutation_problem(Refutation((Power(F(1), 0), F(1)), ZERO_SQUARE),
                                                     query, STATES)
    assert refutation_problem(Refutation((F(1), F(1)), ZERO_SQUARE), query, STATES) is not None


def test_only_the_four_inequalities_are_read():
    """A comparison of another kind (were one ever built) is not read as an inequality:
    the query is then not refutable here at all."""
    odd = L.conjunction(L.Compare(">", NORM, E.ZERO), L.Compare("==", NORM, E.ZERO))
    assert "not a conjunction of polynomial comparisons" in refutation_problem(
        Refutation((F(1), F(1)), ZERO_SQUARE), odd, STATES)


def test_conjuncts_that_are_not_comparisons_are_left_out():
    """A disjunction among the conjuncts (x outside a box) gets no multiplier: refuting
    the comparisons alone refutes the whole query, which asks for more."""
    outside = L.disjunction(L.Compare(">=", E.Var("x0"), E.Num(F(1))),
                            L.Compare(">=", E.Var("x1"), E.Num(F(1))))
    query = L.conjunction(L.Compare(">", NORM, E.ZERO), outside,
                          L.Compare(">=", E.neg(NORM), E.ZERO))
    good = Refutation((F(1), F(1)), ZERO_SQUARE)
    assert refutation_problem(good, query, STATES) is None
    assert "2 multipliers for 1" in refutation_problem(
        good, L.conjunction(outside, L.Compare(">", NORM, E.ZERO)), STATES)
    assert "no comparison" in refutation_problem(good, outside, STATES)


def test_a_gram_matrix_polynomial_is_summed_in_place_to_the_same_polynomial():
    """SumOfSquares.polynomial accumulates its terms in place (P.accumulate); summed
    with P.add term by term it copied the whole sum at each term (40 s of d18's run)."""
    import random
    from fractions import Fraction
    from fossil_dsl.ir import polynomials as P
    from fossil_dsl.solvers.positivstellensatz import SumOfSquares
    rng = random.Random(4)
    monomials = tuple(P.monomials(3, 0, 2))
    gram = [[Fraction(rng.randint(-5, 5), rng.randint(1, 4)) for _ in monomials]
            for _ in monomials]
    gram = tuple(tuple((gram[i][j] + gram[j][i]) / 2 for j in range(len(monomials)))
                 for i in range(len(monomials)))  # symmetric, some entries cancel
    expected: dict = {}
    for a, row in zip(monomials, gram):
        for b, entry in zip(monomials, row):
            expected = P.add(expected, {P.times(a, b): entry})
    assert SumOfSquares(monomials, gram).polynomial() == expected
    total = {(1, 0, 0): Fraction(2)}
    P.accumulate(total, {(1, 0, 0): Fraction(-2), (0, 1, 0): Fraction(1, 3)})
    assert total == {(0, 1, 0): Fraction(1, 3)}  # a cancelled term is gone, not zero


# ---- a disjunction among the conjuncts: refuted case by case --------------------------
def _on_the_unit_box_boundary_with_norm_at_most(bound):
    """x in [-1, 1]^2, on one of its four faces, and x^2 + y^2 <= bound: unsatisfiable
    for bound < 1 (every boundary point has norm at least 1), satisfiable for 1."""
    box = [L.Compare(rel, side, E.Num(F(value))) for side in (X, Y)
           for rel, value in ((">=", -1), ("<=", 1))]
    interior = L.conjunction(*(L.Compare(rel, side, E.Num(F(value))) for side in (X, Y)
                               for rel, value in ((">", -1), ("<", 1))))
    return L.conjunction(*box, L.negation(interior), L.Compare("<=", NORM, E.Num(bound)))


def test_a_query_with_a_disjunction_is_refuted_case_by_case_and_the_kernel_checks_the_cases():
    import time
    from fossil_dsl.solvers.positivstellensatz import CaseSplit
    query = _on_the_unit_box_boundary_with_norm_at_most(F(9, 10))
    found = sos_refutation.refute(query, STATES, time.monotonic() + 30)
    assert isinstance(found, CaseSplit) and len(found.cases) == 4  # the four faces
    assert refutation_problem(found, query, STATES) is None
    assert refutation_problem(refutation_from_json(refutation_json(found, STATES)), query,
                              STATES) is None
    # the same cases do not refute a satisfiable query; a case left out, or the split
    # named on a conjunct that is no disjunction, is refused
    satisfiable = _on_the_unit_box_boundary_with_norm_at_most(F(1))
    assert "case" in refutation_problem(found, satisfiable, STATES)
    assert sos_refutation.refute(satisfiable, STATES, time.monotonic() + 30) is None
    assert "refutations for 4 cases" in refutation_problem(
        CaseSplit(found.conjunct, found.cases[1:]), query, STATES)
    assert "not a disjunction" in refutation_problem(CaseSplit(0, found.cases), query, STATES)


def test_the_kernel_proves_a_six_state_boundary_condition_case_by_case():
    """V = |x|^2 > 0.9 on the boundary of [-1, 1]^6, the form of a region of attraction's
    "V > β on the boundary of D": twelve faces, each a small program."""
    from fossil_dsl.kernel.obligations import Obligation
    from fossil_dsl.kernel.prove import SUM_OF_SQUARES, discharge
    from fossil_dsl.solvers.positivstellensatz import CaseSplit
    states = tuple(f"x{i}" for i in range(6))
    xs = [E.Var(s) for s in states]
    box = [L.Compare(rel, v, E.Num(F(value))) for v in xs
           for rel, value in ((">=", -1), ("<=", 1))]
    interior = L.conjunction(*(L.Compare(rel, v, E.Num(F(value))) for v in xs
                               for rel, value in ((">", -1), ("<", 1))))
    norm = E.add(*(sq(v) for v in xs))
    query = L.conjunction(*box, L.negation(interior), L.Compare("<=", norm, E.Num(F(9, 10))))
    proof = discharge(Obligation("condition:boundary", "V > 0.9 on the boundary of D", query),
                      states, 30.0)
    assert proof.proved and proof.procedure == SUM_OF_SQUARES
    assert isinstance(proof.evidence, CaseSplit) and len(proof.evidence.cases) == 12


# x and y in the box [-1, 1]^2 with x^2 + y^2 > 2.5: unsatisfiable, but multipliers of the
# four linear bounds alone cannot show it at degree 2 (nothing there sees x^2 <= 1); the
# products of opposite bounds, (x + 1)(1 - x) >= 0 and (y + 1)(1 - y) >= 0, can
ONE = E.Num(F(1))
BOX_AND_FAR = L.conjunction(L.Compare("<=", E.neg(ONE), X), L.Compare("<=", X, ONE),
                            L.Compare("<=", E.neg(ONE), Y), L.Compare("<=", Y, ONE),
                            L.Compare(">", NORM, E.Num(F(5, 2))))


def test_opposite_bounds_enter_as_products_and_the_kernel_checks_them():
    import time
    found = sos_refutation.refute(BOX_AND_FAR, STATES, time.monotonic() + 30)
    assert found is not None and {(p.first, p.second) for p in found.products} == {(0, 1), (2, 3)}
    assert refutation_problem(found, BOX_AND_FAR, STATES) is None
    again = refutation_from_json(refutation_json(found, STATES))
    assert again == found and refutation_problem(again, BOX_AND_FAR, STATES) is None
    without = Refutation(found.multipliers, found.rest, found.constant)
    assert "identity fails" in refutation_problem(without, BOX_AND_FAR, STATES)


def test_forged_products_are_rejected():
    import time
    from dataclasses import replace
    found = sos_refutation.refute(BOX_AND_FAR, STATES, time.monotonic() + 30)
    product = found.products[0]
    elsewhere = replace(found, products=(replace(product, second=7),) + found.products[1:])
    assert "does not have" in refutation_problem(elsewhere, BOX_AND_FAR, STATES)
    size = len(product.square.monomials)
    negative = tuple(tuple(F(-1) if i == j else F(0) for j in range(size)) for i in range(size))
    indefinite = replace(found, products=(replace(product, square=replace(
        product.square, gram=negative)),) + found.products[1:])
    assert "not positive semidefinite" in refutation_problem(indefinite, BOX_AND_FAR, STATES)
    # a product of comparisons that are not the box's bounds: the identity no longer holds
    swapped = replace(found, products=(replace(product, first=0, second=2),) + found.products[1:])
    assert refutation_problem(swapped, BOX_AND_FAR, STATES) is not None


def test_a_query_away_from_the_origin_tries_constant_terms_first(monkeypatch):
    """A map's reach decrease outside the goal disc: V(f(x)) - V(x) > -1/100 for
    f(x) = x / 2, V = |x|^2, and |x|^2 >= 1/25. The origin violates the disc's
    exclusion, so programs with low 1 or 2 (every term vanishing at the origin but the
    strict comparison's constant 1/100) cannot hold there: the first program tried has
    constant terms, and it is the refutation."""
    import time
    step = E.mul(E.Num(F(-3, 4)), NORM)  # V(x / 2) - V(x)
    query = L.conjunction(L.Compare(">", step, E.Num(F(-1, 100))),
                          L.Compare(">=", NORM, E.Num(F(1, 25))),
                          L.Compare("<=", NORM, E.Num(F(1))))
    solved = []
    original = sos_refutation._RefutationProgram.solve
    def counted(program, *args):
        solved.append(program)
        return original(program, *args)
    monkeypatch.setattr(sos_refutation._RefutationProgram, "solve", counted)
    found = sos_refutation.refute(query, STATES, time.monotonic() + 30)
    assert found is not None and refutation_problem(found, query, STATES) is None
    assert len(solved) == 1



def test_monomials_whose_square_nothing_cancels_leave_s0s_basis():
    """x^4 + 1 - w x <= 0 with |w| <= 1 (w stands for a function's value, bounded only
    linearly): no term of the identity holds w^4, so w^2's diagonal entry in s0's Gram
    matrix is 0 in every solution and s0 + tI had t = 0, which no rounding survives.
    Without w^2 (and what it alone cancelled) the first program is a refutation."""
    from fossil_dsl.solvers.positivstellensatz import comparisons
    w = E.Var("w")
    h = E.add(E.power(X, E.Num(F(4))), E.Num(F(1)), E.neg(E.mul(w, X)))
    query = L.conjunction(L.Compare("<=", h, E.ZERO), L.Compare("<=", w, E.Num(F(1))),
                          L.Compare(">=", w, E.Num(F(-1))))
    states = ("x", "w")
    program = sos_refutation._RefutationProgram(2, comparisons(query, states), 0, 1)
    assert (0, 2) not in program.basis and (2, 0) in program.basis
    x = program.solve({program.interior: -1.0}, 20)
    assert x[program.interior] > 0.5
    found = program.exact(x)
    assert found is not None and refutation_problem(found, query, states) is None
    # the pruning itself: kept where the rest of the identity has m^2, or m^2 is a
    # product of two other kept monomials; repeated until nothing more goes
    basis = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]
    assert sos_refutation.cancellable(basis, {(0, 0), (4, 0), (2, 0)}) == [(0, 0), (1, 0),
                                                                           (2, 0)]
    assert sos_refutation.cancellable(basis, {(0, 0), (4, 0), (0, 4)}) == [
        (0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]


def test_a_strict_comparison_gets_a_polynomial_multiplier_in_the_closure_program():
    """x > 1 and -x^3 >= 0: with a constant multiplier for x - 1 every identity is odd
    of degree 3 (no refutation); read as x - 1 >= 0 it takes (2 + x^2)(x - 1) - x^3 +
    (x - 1)^2 + 1 = 0, a proof that even the closure is empty. Checked exactly; without
    the closure's program nothing is found."""
    import time
    query = L.conjunction(L.Compare(">", X, E.Num(F(1))),
                          L.Compare(">=", E.neg(E.power(X, E.Num(F(3)))), E.ZERO))
    found = sos_refutation.refute(query, ("x",), time.monotonic() + 20)
    assert found is not None and refutation_problem(found, query, ("x",)) is None
    assert found.constant > 0


def test_without_the_closure_program_the_cubic_query_is_not_refuted(monkeypatch):
    import time
    monkeypatch.setattr(sos_refutation, "_closure_worthwhile", lambda atoms: False)
    query = L.conjunction(L.Compare(">", X, E.Num(F(1))),
                          L.Compare(">=", E.neg(E.power(X, E.Num(F(3)))), E.ZERO))
    assert sos_refutation.refute(query, ("x",), time.monotonic() + 20) is None


def _by_elimination(gram) -> bool:
    """The reference: symmetric Gaussian elimination on fractions (no negative pivot,
    a zero pivot only with a zero row), the check used before FLINT's polynomial."""
    n = len(gram)
    a = [[F(v) for v in row] for row in gram]
    if any(a[i][j] != a[j][i] for i in range(n) for j in range(i)):
        return False
    for k in range(n):
        if a[k][k] < 0 or (a[k][k] == 0 and any(a[k][k + 1:])):
            return False
        for i in range(k + 1, n):
            if a[k][k] and a[i][k]:
                ratio = a[i][k] / a[k][k]
                a[i][k + 1:] = [x - ratio * y for x, y in zip(a[i][k + 1:], a[k][k + 1:])]
    return True


@settings(max_examples=300, deadline=None)
@given(rows=st.lists(st.lists(st.fractions(-3, 3, max_denominator=7), min_size=5,
                              max_size=5), min_size=1, max_size=7),
       shift=st.fractions(-1, 1, max_denominator=10 ** 30), where=st.integers(0, 4))
def test_the_characteristic_polynomial_agrees_with_elimination(rows, shift, where):
    # A^T A (often of low rank: PSD with zero eigenvalues) moved by a tiny or large
    # rational on one diagonal entry: on both sides of the PSD boundary
    gram = [[sum(r[i] * r[j] for r in rows) for j in range(5)] for i in range(5)]
    gram[where][where] += shift * shift * shift
    assert positive_semidefinite(gram) == _by_elimination(gram)


def test_the_smallest_negative_eigenvalue_is_seen():
    # [[1, 1], [1, 1 - 1e-40]] has det -1e-40: indefinite; with + it is definite
    tiny = F(1, 10 ** 40)
    assert not positive_semidefinite([[F(1), F(1)], [F(1), 1 - tiny]])
    assert positive_semidefinite([[F(1), F(1)], [F(1), 1 + tiny]])
    assert positive_semidefinite([])
    assert not positive_semidefinite([[F(1), F(0)], [F(0)]])  # not square
