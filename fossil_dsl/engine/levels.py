"""The samples every condition starts with, and the levels (such as the β of a sublevel
set) chosen from the function's values on them. Shared by the learner (torch) and
verifier-only runs (numpy, no torch)."""
from __future__ import annotations

from fossil_dsl.engine.sampling import sample
from fossil_dsl.plan.compile import Plan


def initial_samples(plan: Plan, generator) -> dict:
    """Each condition's samples; conditions over the same set with the same count share
    theirs."""
    box = plan.spec.domain.bounding_box()
    drawn: dict = {}
    result = {}
    for condition in plan.conditions:
        count = plan.samples[condition.name]
        key = (condition.region.text(), count)
        if key not in drawn:
            drawn[key] = sample(condition.region, plan.states, count, generator, box)
        result[condition.name] = drawn[key]
    return result


LEVEL_SLACK = 0.02  # of the spread of the values `above`, kept below their sampled minimum


def level_value(above, below, margin: float):
    """A level under the values `above` and over the values `below` (halfway), or,
    without `below`, just under `above` (without `above`, just over `below`) by twice
    the margin or a fiftieth of their
    spread, whichever is more (then it is an array that keeps the gradient of the
    smallest value, when learning). The spread counts because samples miss the true
    minimum by more on larger sets and steeper functions: 4 states, V up to 300 on a
    sphere, and the sampled minimum was 0.08 above the true one."""
    if below is None:
        if not len(above):
            return 0.0
        spread = _number(above.max()) - _number(above.min())
        return above.min() - max(2 * margin, LEVEL_SLACK * spread)
    if above is None:  # the mirror image: just over the values `below`
        if not len(below):
            return 0.0
        spread = _number(below.max()) - _number(below.min())
        return below.max() + max(2 * margin, LEVEL_SLACK * spread)
    low = _number(above.min()) if len(above) else None
    return between(_number(below.max()) if len(below) else None, low)


def _number(value) -> float:
    return float(value.detach() if hasattr(value, "detach") else value)


def between(high: float | None, low: float | None) -> float:
    """A level above `high` and below `low` (halfway), or just beyond the one given."""
    if high is not None and low is not None:
        return (high + low) / 2
    if low is not None:
        return low - 0.01 * (abs(low) + 1e-3)
    if high is not None:
        return high + 0.01 * (abs(high) + 1e-3)
    return 0.0
