"""Safety with inputs through the barrier program for the closed loop of an LQR gain
(engine/sos_controlled.py), and a set's complement as pieces (engine/sos.set_pieces).
probe72/av37 (four rooms, U outside a box round I) gave up after 25 iterations of
learning before session 72: no ellipsoid fits between the boxes."""
import time
from fractions import Fraction
from pathlib import Path

import fossil_dsl
from fossil_dsl.engine import sos_controlled
from fossil_dsl.engine.sos import set_pieces
from fossil_dsl.ir import polynomials as P
from fossil_dsl.plan.compile import compile_spec

SPECS = Path(__file__).resolve().parent.parent / "specs"
ROOMS = SPECS / "probe72/av37_sampled_four_room_heat_safety_ctrl_4d.fsl"
DRIFT = SPECS / "false/f116_sampled_rooms_unheated_drift_safety_ctrl_4d.fsl"


def value(polynomial, point) -> Fraction:
    return sum(c * eval_monomial(m, point) for m, c in polynomial.items())


def eval_monomial(monomial, point) -> Fraction:
    result = Fraction(1)
    for power, coordinate in zip(monomial, point):
        result *= Fraction(coordinate) ** power
    return result


def in_some_piece(pieces, point) -> bool:
    return any(all(value(g, point) >= 0 for g in piece) for piece in pieces)


def test_the_complement_of_a_box_is_one_piece_per_face():
    spec = fossil_dsl.load(ROOMS)
    pieces = set_pieces(spec.property.role("unsafe"), compile_spec(spec).states)
    assert len(pieces) == 8
    assert in_some_piece(pieces, ["1.6", "0", "0", "0"])
    assert in_some_piece(pieces, ["0", "0", "-2", "1"])
    assert not in_some_piece(pieces, ["1.4", "-1.4", "1", "0"])  # inside the box
    assert not in_some_piece(pieces, ["3.5", "0", "0", "0"])  # outside D


def test_four_rooms_are_certified_by_the_closed_loop_program():
    plan = compile_spec(fossil_dsl.load(ROOMS))
    assert sos_controlled.applies(plan)
    finding = sos_controlled.search(plan, time.monotonic() + 30)
    assert finding is not None and finding.degree == 4 and finding.controller
    result = fossil_dsl.synthesise(fossil_dsl.load(ROOMS), timeout=120)
    assert result.certified and result.kernel.certified, result.summary()
    assert "for an LQR gain" in result.strategy
    assert result.kernel.strengthened == "never leaves D"  # B > 0 on D's faces as well


def test_a_room_no_heater_reaches_is_not_certified():
    plan = compile_spec(fossil_dsl.load(DRIFT))
    assert sos_controlled.search(plan, time.monotonic() + 30) is None
    result = fossil_dsl.synthesise(fossil_dsl.load(DRIFT), timeout=30, max_iters=3)
    assert not result.certified
