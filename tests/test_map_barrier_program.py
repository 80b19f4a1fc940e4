"""The barrier program for maps (engine/sos_barrier.py): B(f(x)) - B(x) <= -mu B(x) - e
with 0 < mu <= 1, so B(f(x)) <= (1 - mu) B(x) <= 0 wherever B(x) <= 0: the kernel's
invariance condition. probe68/ar12 (a discrete SIR model's peak) gave up after 25
iterations of learning before session 70."""
import time
from pathlib import Path

import fossil_dsl
from fossil_dsl.engine import sos
from fossil_dsl.engine.sos_barrier import MAP_DECAY_RATES, barrier
from fossil_dsl.plan.compile import compile_spec

SPECS = Path(__file__).resolve().parent.parent / "specs"
PEAK = SPECS / "probe68/ar12_discrete_sir_allen_peak_safety_3d.fsl"
OUTBREAK = SPECS / "false/f105_discrete_sir_outbreak_peak_safety_3d.fsl"

TANH_MAP = """\
state x, y
dynamics discrete {
    next(x) = 0.5*tanh(x) + 0.2*y
    next(y) = 0.5*y
}
domain box([-2, -2], [2, 2])
set init = box([-0.2, -0.2], [0.2, 0.2])
set unsafe = { x >= 1 }
prove from init: always not unsafe
"""


def test_every_decay_rate_keeps_the_sublevel_set_of_a_map():
    assert all(0 < mu <= 1 for mu in MAP_DECAY_RATES)


def test_the_discrete_sir_peak_is_certified_by_the_program():
    plan = compile_spec(fossil_dsl.load(PEAK))
    assert sos.applies(plan)
    finding = barrier(plan, time.monotonic() + 30)
    assert finding is not None and "B(f(x)) - B(x)" in finding.describe()
    result = fossil_dsl.synthesise(fossil_dsl.load(PEAK), timeout=120)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares")


def test_a_map_with_a_function_gets_no_program():
    """B(f(x)) of tanh's value is no polynomial in the states and a variable for it."""
    assert barrier(compile_spec(fossil_dsl.loads(TANH_MAP)), time.monotonic() + 10) is None


def test_an_outbreak_past_the_threshold_is_not_certified():
    """f105: from S = 0.95, I = 0.02 the map's outbreak peaks near I = 0.069 > 0.04."""
    plan = compile_spec(fossil_dsl.load(OUTBREAK))
    assert barrier(plan, time.monotonic() + 30) is None
    result = fossil_dsl.synthesise(fossil_dsl.load(OUTBREAK), timeout=30, max_iters=3)
    assert not result.certified
