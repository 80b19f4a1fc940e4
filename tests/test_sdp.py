"""The semidefinite-program layer (solvers/sdp.py): a Gram block multiplied by a
constraint is built in floats, and must add exactly the terms the product of
Fractions added."""
from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.ir import polynomials as P
from fossil_dsl.solvers.sdp import Program

N = 3
monomial = st.tuples(*[st.integers(0, 2)] * N)
coefficient = st.fractions(min_value=-50, max_value=50, max_denominator=997)
polynomial = st.dictionaries(monomial, coefficient, min_size=1, max_size=6)


def _identity(times, sign: int, fast: bool) -> dict:
    program = Program(N)
    basis = P.monomials(N, 0, 2)
    if fast:
        program.gram(basis, times=times, sign=sign)
    else:
        program.gram(basis, lambda p: P.scale(P.multiply(p, times), sign))
    return program.identity


@settings(max_examples=40, deadline=None)
@given(polynomial, st.sampled_from([1, -1]))
def test_a_block_times_a_constraint_adds_the_same_terms_as_the_exact_product(times, sign):
    assert _identity(times, sign, fast=True) == _identity(times, sign, fast=False)


def test_the_terms_are_the_shifted_constraint_twice_off_the_diagonal():
    program = Program(2)
    entries = program.gram([(1, 0), (0, 1)], times={(1, 0): Fraction(3)}, sign=-1)
    assert [(i, j) for _, i, j in entries] == [(0, 0), (0, 1), (1, 1)]
    # x*x * 3x, 2 * x*y * 3x, y*y * 3x, each negated
    assert program.identity == {(0, (3, 0)): {0: -3.0}, (0, (2, 1)): {1: -6.0},
                                (0, (1, 2)): {2: -3.0}}


def _blocks(sizes: dict[int, int]) -> Program:
    """A program with `count` Gram blocks of each size (nothing else: only its cost)."""
    program = Program(3)
    for size, count in sizes.items():
        basis = P.monomials(3, 0, 8)[:size]
        for _ in range(count):
            program.gram(basis, lambda p: {})
    return program


def test_a_program_whose_iterations_cannot_fit_in_its_time_is_not_tried():
    # probe60/ae06's quartic reach program: its first iteration alone took 95 s
    reach = _blocks({84: 2, 56: 11, 10: 10, 4: 77})
    assert reach.too_costly(27.0)
    assert reach.solve({0: 1.0}, 27.0) is None  # at once, without Clarabel
    # probe56/u02's quartic region of attraction: 1.1 s an iteration
    region = _blocks({56: 1, 21: 27, 6: 166})
    assert not region.too_costly(30.0) and region.too_costly(1.0)
