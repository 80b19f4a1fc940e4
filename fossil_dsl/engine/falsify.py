"""A numeric search for a point of a verifier query: a counterexample found without a
solver, where bisection is slow to find one.

With 6 states, a query whose counterexamples fill a sliver (a reach certificate's
decrease failing just outside the goal ball) kept the interval procedure refuting boxes
elsewhere for the whole of its 60 s. Here: uniform points of the domain's box, the
best of them (by how far the query is from holding) moved downhill on that distance by
Adam, and the first point where the query holds in floating point is returned. Nothing
here proves anything: the point is a lead for the learner, as a delta-sat box's middle.
"""
from __future__ import annotations

import time

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status

DRAWN = 20_000  # uniform points of the box
MOVED = 128  # the best of them, moved downhill
STEPS = 60
STEP = 0.01  # Adam's rate, as a share of the box's width
PATIENCE = 20  # steps without a closer point before the search stops (most queries are
# unsatisfiable: there the distance settles within a few steps)
SLOW_QUERY = 5.0  # seconds: a condition whose query took longer is searched first after
# from this many states on, where the verifier is a delta-decision procedure, every query
# is searched first: there bisection is slow to find even a wide region of
# counterexamples (x12's boundary condition: 27 s); Z3 finds them at once on polynomial
# problems, where the search only cost time (row04, 8 states: 0.1 -> 0.8 s of verifying)
FIRST_FROM_STATES = 5
# a verifier not searched before gets this long first; with no answer by then, the
# search runs, then the verifier again with the time left (probe44/y06: Z3, CVC5 and the
# interval procedure left a failing decrease unanswered for the query's whole 60 s, and
# the search found a point in a second once they had)
FIRST_SLICE = 10.0
SOLVER = "numeric search"


class Falsifier:
    """Searches a condition's query for a point before the verifier (with FIRST_FROM_STATES
    states or more and a delta-decision verifier, or once the verifier has been slow on
    that condition), and after the verifier where it gave no answer."""

    def __init__(self, states, box, seed: int, bisecting: bool = True):
        self.states, self.box, self.seed = tuple(states), box, seed
        self.always_first = bisecting and len(self.states) >= FIRST_FROM_STATES
        self.slow: set[str] = set()

    def checked(self, name: str, query: L.Formula, budget: float, check) -> Answer:
        """The answer for the condition's query: searched before or after `check(seconds)`
        (the verifier), as the class says; a verifier that has not answered within
        FIRST_SLICE seconds is asked again, with the rest of the budget, if the search
        finds nothing."""
        if self.always_first or name in self.slow:
            return self.search(query) or check(budget)
        started = time.monotonic()
        given = min(budget, FIRST_SLICE)
        answer = check(given)
        seconds = time.monotonic() - started
        answer = self.after(name, query, answer, seconds)
        left = budget - (time.monotonic() - started)
        # only a verifier stopped by the slice (not one that gave up) is worth asking again
        if answer.status is Status.UNKNOWN and given < budget and seconds >= given and left > 1:
            return check(left)
        return answer

    def after(self, name: str, query: L.Formula, answer: Answer, seconds: float) -> Answer:
        if seconds > SLOW_QUERY:
            self.slow.add(name)
        if answer.status is Status.UNKNOWN:
            return self.search(query) or answer
        return answer

    def search(self, query: L.Formula) -> Answer | None:
        if self.box is None or not L.free_vars(query) <= set(self.states):
            return None
        point = witness(query, self.states, self.box, self.seed)
        if point is None:
            return None
        return Answer(Status.SAT, dict(zip(self.states, point)), solver=SOLVER,
                      reason="a point where the query holds in floating point")


def witness(query: L.Formula, states, box, seed: int) -> list[float] | None:
    """A point of the box where the query holds (in floating point), or None."""
    import torch
    generator = torch.Generator().manual_seed(seed)
    low = torch.tensor(box[0], dtype=torch.float64)
    high = torch.tensor(box[1], dtype=torch.float64)
    points = low + (high - low) * torch.rand(DRAWN, len(states), generator=generator,
                                             dtype=torch.float64)
    found = _holding(query, states, points)
    if found is not None:
        return found
    with torch.no_grad():
        distance = _distance(query, states, points)
    points = points[distance.argsort()[:MOVED]].clone().requires_grad_(True)
    optimiser = torch.optim.Adam([points], lr=STEP * float((high - low).max()))
    closest, since = float("inf"), 0
    for _ in range(STEPS):
        optimiser.zero_grad()
        distance = _distance(query, states, points)
        distance.sum().backward()
        optimiser.step()
        with torch.no_grad():
            points.clamp_(min=low, max=high)
        found = _holding(query, states, points.detach())
        if found is not None:
            return found
        nearest = float(distance.detach().min())
        since = 0 if nearest < closest else since + 1
        closest = min(closest, nearest)
        if since >= PATIENCE:
            return None
    return None


def _distance(query: L.Formula, states, points):
    """How far the query is from holding at each point (at most 0 where it holds), with
    undefined values (NaN) as far."""
    import torch
    from fossil_dsl.engine.loss import violation_of  # imports torch: runs that learn only
    value = torch.as_tensor(violation_of(query, state_env(states, points)),
                            dtype=torch.float64).expand(len(points))
    return torch.nan_to_num(value, nan=1e6, posinf=1e6).clamp(min=-1.0)


def _holding(query: L.Formula, states, points) -> list[float] | None:
    inside = holds(query, state_env(states, points), len(points))
    if not bool(inside.any()):
        return None
    return [float(v) for v in points[inside][0]]
