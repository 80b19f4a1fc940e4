"""Rounding multipliers: residuals s0 cannot hold are moved onto a multiplier's diagonal."""
from fractions import Fraction as F

from fossil_dsl.ir import polynomials as P
from fossil_dsl.solvers.gram_rounding import settled
from fossil_dsl.solvers.positivstellensatz import SumOfSquares, positive_semidefinite

Z, Z2, Z3, ONE = (1,), (2,), (3,), (0,)


def _square(entry):
    return SumOfSquares((Z,), ((F(entry),),))


def _total(squares, factors, extra):
    total = dict(extra)
    for square, factor in zip(squares, factors):
        total = P.add(total, P.multiply(square.polynomial(), factor))
    return total


def test_a_stray_cubic_residual_moves_onto_the_multiplier_whose_raise_cancels_it():
    """Two multipliers z^2 (1 - z) and z^2 (z - 1/2) cancel on z^3 up to a rounding of
    1e-12, which s0 over {1, z} (its products reach 1, z, z^2) cannot hold."""
    factors = [{ONE: F(1), Z: F(-1)}, {Z: F(1), ONE: F(-1, 2)}]
    squares = [_square(F(3)), _square(F(3) - F(1, 10 ** 12))]
    total = _total(squares, factors, {})
    assert total[Z3] == F(-1, 10 ** 12)
    found = settled(squares, factors, total, reach={ONE, Z, Z2})
    assert found is not None
    moved, new_total = found
    assert Z3 not in new_total or new_total[Z3] == 0
    assert new_total == _total(moved, factors, {})  # the total follows the raise
    assert all(positive_semidefinite(s.gram) for s in moved)
    assert moved[1].gram[0][0] == F(3)  # z - 1/2 has +z: its entry was raised by 1e-12


def test_a_residual_that_only_a_lowered_entry_could_cancel_is_not_settled():
    """(1 - z) z^2 adds -z^3 per unit raised: a residual of -1e-12 needs a lowering."""
    squares, factors = [_square(F(2))], [{ONE: F(1), Z: F(-1)}]
    total = {Z3: F(-1, 10 ** 12), Z2: F(2)}
    assert settled(squares, factors, total, reach={ONE, Z, Z2}) is None


def test_a_raise_whose_other_terms_leave_the_reach_is_not_taken():
    squares, factors = [_square(F(1))], [{Z: F(1), ONE: F(-1, 2)}]
    total = {Z3: F(-1, 10 ** 12)}
    assert settled(squares, factors, total, reach={ONE, Z}) is None  # z^2 not in reach
    moved, new_total = settled(squares, factors, total, reach={ONE, Z, Z2})
    assert moved[0].gram[0][0] == 1 + F(1, 10 ** 12)
    assert new_total == {Z2: -F(1, 2 * 10 ** 12)}


def test_nothing_stray_leaves_everything_as_it_was():
    factors = [{ONE: F(1)}]
    squares = [_square(F(1))]
    total = _total(squares, factors, {})
    assert settled(squares, factors, total, reach={ONE, Z, Z2}) == (squares, total)
