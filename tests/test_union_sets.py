"""Unions of sets in the sum-of-squares programs (engine/sos.py `set_pieces`): a condition
asked on a union is asked on each member. Before session 70 a union was not a conjunction
of comparisons, so the region-of-attraction and reach programs gave up on it and the
barrier program asked B > 0 on all of D for a union U (infeasible)."""
import time
from pathlib import Path

import fossil_dsl
from fossil_dsl.engine import sos_reach, sos_roa
from fossil_dsl.engine.sos import set_pieces
from fossil_dsl.engine.sos_barrier import barrier
from fossil_dsl.plan.compile import compile_spec

SPECS = Path(__file__).resolve().parent.parent / "specs"
SWITCH = SPECS / "probe70/at23_two_boxes_of_initial_states_bistable_roa.fsl"
PAST_THRESHOLD = SPECS / "false/f104_bistable_switch_past_threshold_roa.fsl"

OBSTACLES = """\
state x, y
dynamics continuous {
    x' = y
    y' = -x - y + 0.1*x^3
}
domain box([-2, -2], [2, 2])
set init = ball([0, 0], 0.3)
set unsafe = ball([1, 1], 0.4) | ball([-1, -1], 0.4)
prove from init: always not unsafe
"""

REACH = """\
state x, y
dynamics continuous {
    x' = y
    y' = -x - y
}
domain box([-2, -2], [2, 2])
set a = box([0.8, -0.1], [1, 0.1])
set b = box([-1, -0.1], [-0.8, 0.1])
set init = a | (b | box([-0.1, 0.8], [0.1, 1]))
set unsafe = box([-2, 1.2], [2, 2]) | box([-2, -2], [2, -1.2])
set goal = ball([0, 0], 0.2)
prove from init: not unsafe until goal
"""


def test_a_union_of_unions_gives_one_piece_per_member():
    plan = compile_spec(fossil_dsl.loads(REACH))
    pieces = set_pieces(plan.spec.property.role("initial"), plan.states, exact=True)
    assert len(pieces) == 3 and all(len(piece) == 4 for piece in pieces)


def test_initial_states_on_both_sides_get_the_region_program():
    plan = compile_spec(fossil_dsl.load(SWITCH))
    assert sos_roa.search(plan, time.monotonic() + 60) is not None
    result = fossil_dsl.synthesise(fossil_dsl.load(SWITCH), timeout=60)
    assert result.certified and result.kernel.certified
    assert result.strategy.startswith("sum-of-squares")


def test_two_obstacles_get_the_barrier_program():
    plan = compile_spec(fossil_dsl.loads(OBSTACLES))
    assert barrier(plan, time.monotonic() + 30) is not None
    result = fossil_dsl.synthesise(fossil_dsl.loads(OBSTACLES), timeout=60)
    assert result.certified and result.strategy.startswith("sum-of-squares")


def test_reach_from_three_boxes_between_two_bands():
    plan = compile_spec(fossil_dsl.loads(REACH))
    assert sos_reach.search(plan, time.monotonic() + 30) is not None
    result = fossil_dsl.synthesise(fossil_dsl.loads(REACH), timeout=60)
    assert result.certified and result.kernel.certified


def test_a_member_past_the_threshold_is_not_certified():
    """f104: the second box holds (0.45, 0.45), above the saddle, from where the state
    switches to the high equilibrium outside D."""
    result = fossil_dsl.synthesise(fossil_dsl.load(PAST_THRESHOLD), timeout=30, max_iters=3)
    assert not result.certified
