"""Reach and RWA with inputs toward a goal off the origin (a set point): the checker no
longer asks G to hold the origin (reaching G asks no equilibrium of the controller), and
the reach program fixes the controller's LQR gain at the middle of G's box with the
inputs that hold the state there (engine/reach_pieces.py `set_point`)."""
from pathlib import Path

import fossil_dsl

SPECS = Path(__file__).resolve().parent.parent / "specs"
TANK = SPECS / "probe70/at27_tank_level_setpoint_reach_ctrl.fsl"

UNCONTROLLABLE = """\
state x, y
input u
dynamics continuous {
    x' = -x
    y' = u
}
domain box([-1, -1], [1, 1])
set init = box([0.2, -0.1], [0.3, 0.1])
set goal = box([0.5, -0.2], [0.7, 0.2])
prove from init: eventually goal
"""


def test_a_set_point_goal_passes_the_checks():
    assert fossil_dsl.check_file(TANK).ok


def test_the_tank_is_filled_to_its_set_point():
    result = fossil_dsl.synthesise(fossil_dsl.load(TANK), timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares")
    controller = str(result.controller["u"])
    assert "h" in controller  # feedback on the level, round the pump flow 0.5 at h = 1


def test_a_goal_the_inputs_cannot_move_the_state_to_is_not_certified():
    """x decays to 0 whatever u does, so x never reaches 0.5."""
    result = fossil_dsl.synthesise(fossil_dsl.loads(UNCONTROLLABLE), timeout=20, max_iters=2)
    assert not result.certified


CAPACITY = SPECS / "probe70/at35_logistic_growth_to_capacity_rswa_raw.fsl"


def test_a_population_reaches_and_stays_round_its_capacity():
    """RSWA without inputs, F round the equilibrium (1, 1): the reach program's level
    balls are centred there (engine/reach_pieces.py `StayPieces`)."""
    result = fossil_dsl.synthesise(fossil_dsl.load(CAPACITY), timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares")


def test_a_band_the_population_passes_through_is_not_certified_to_hold_it():
    """F = x in [0.4, 0.6]: the population grows through it to its capacity 1."""
    passing = CAPACITY.read_text().replace("set final = box([0.8, 0.8], [1.2, 1.2])",
                                           "set final = box([0.4, 0.8], [0.6, 1.2])")
    result = fossil_dsl.synthesise(fossil_dsl.loads(passing), timeout=20, max_iters=2)
    assert not result.certified


def test_a_cascade_is_filled_with_the_gain_the_program_used():
    """probe70/at42: the controller's bias at the set point is computed from the rounded
    gain both where the program fixes it and where the network is set; before, they
    differed in the last digit (1.686 against 1.687) and the program's V was dropped."""
    spec = fossil_dsl.load(SPECS / "probe70/at42_level_control_corridor_rwa_ctrl.fsl")
    result = fossil_dsl.synthesise(spec, timeout=60)
    assert result.certified and result.strategy.startswith("sum-of-squares"), result.summary()
