"""When the CEGIS loop changes course: a learner that brings no new counterexample is
restarted, as is one that leaves an undecided candidate unchanged, and a query gets less
time once another condition has failed at a point in the same iteration."""
from __future__ import annotations

from fossil_dsl.solvers.api import Status

STALL_ITERATIONS = 3  # iterations bringing no new counterexample before a restart
# seconds for a condition's query once another has failed at a point in the iteration: the
# learner has something to meet, and a slow query is better asked of a candidate that
# meets it (z24, seed 2: 53 s undecided after I and U had failed in 0.1 s)
AFTER_A_FAILURE = 10.0


def stalled(history) -> bool:
    """Whether each of the last STALL_ITERATIONS iterations failed only with
    counterexamples met before (since the last restart): the learner cannot meet them
    from where it is, and more of the same will not help."""
    if len(history) < STALL_ITERATIONS:
        return False
    seen: set = set()
    repeats = 0
    for record in history:
        found = _counterexamples(record)
        repeats = repeats + 1 if found and found <= seen else 0
        seen |= found
    return repeats >= STALL_ITERATIONS


def failed(verdicts) -> bool:
    return any(v.status is Status.SAT for v in verdicts)


def undecided_again(last_verified, candidate) -> bool:
    """Whether learning left the last candidate as it was, and none of its conditions
    failed at a point: its queries would be left undecided again (z24, seed 2: 61 s, then
    56 s for the same query), so the learner starts afresh instead."""
    return last_verified is not None and last_verified[0] == candidate and \
        not failed(last_verified[2])


def _counterexamples(record) -> frozenset:
    return frozenset((v.condition, v.counterexample) for v in record.verdicts
                     if v.status is Status.SAT)
