"""A starting point for reach-type certificates (reach, RWA, RSWA, RAR) from the
linearisation, where the origin is an equilibrium (of the closed loop) inside the goal.

V = s (x^T P x - c) with P a Lyapunov matrix of the closed loop meets every reach
condition near the origin: V <= 0 on I when c lies above x^T P x on I, V > 0 on the
boundary of the safe set when c lies below it there, and V decreases at a rate of at
least s times x^T Q x, which the scale s makes exceed the plan's γ outside the goal. For
RAR the barrier B = x^T P' x - d of the same closed loop separates G from D \\ F.

Which P fits is a question of shape: the ellipsoid {x^T P x <= c} must hold I and miss
the boundary of S. For each of several LQR weightings (which gain), a small
semidefinite program finds the Lyapunov matrix of that closed loop under which the
sampled boundary lies furthest out, relative to the sampled I; the pair with the largest
ratio is kept. An ellipsoid round the origin holds -x with x: where I lies on one side
and the unsafe set just as far on the other (a pendulum started at 0.5 rad that must not
reach -0.5), none fits, and with inputs the ellipsoid is moved towards I, round a point
c of G that the controller's bias makes the closed loop's equilibrium
(V = (x - c)^T P (x - c) - level). Nothing here is trusted: the seed is verified like
any candidate, and learning starts from it where it fails.
"""
from __future__ import annotations

import functools

import numpy as np

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.engine.linear import (as_array, holds_a_quadratic, is_linear,
                                      operating_point, quadratic_values, set_linear,
                                      set_quadratic)
from fossil_dsl.engine.sampling import sample
from fossil_dsl.engine.quadratic_shapes import (boundary_floor, box_middle, initial_middle,
                                               lqr_gains, separations)
from fossil_dsl.ir.sets import Boundary
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.certificates.rwa import GAMMA

REACH_FORMS = ("reach while avoid", "reach", "reach and stay while avoid",
               "reach-avoid-remain")
MIN_RATIO = 1.05  # the sampled boundary must lie this factor beyond the sampled I
DECREASE_MARGIN = 5.0  # the seed's linear decrease outside G: this many times γ


def candidates(plan, networks: dict, controller, samples: dict) -> list:
    """Seeds to try, best separated first: (True, a function that sets V (and B for RAR)
    and the controller) (every one preferred alike, see Learner.seed_from). Empty where
    no seed applies."""
    if plan.spec.property.form not in REACH_FORMS or not _fits(plan, networks, controller):
        return []
    in_goal = _origin_in_goal(plan)
    operating = operating_point(plan.spec) if in_goal else None
    movable = controller is not None and not _zero_at_origin(networks, controller)
    if operating is None and not movable:
        return []
    rng = np.random.default_rng(plan.options.seed)
    boundary = samples.get("boundary")
    if boundary is None:  # discrete time has no condition on ∂S; the ellipsoid must fit
        boundary = _boundary_samples(plan, rng)
    found = [] if operating is None else _fitting(
        plan, networks, samples, boundary, np.zeros(len(plan.states)), operating, rng)
    for centre in ([] if found or not movable
                   else _goal_centres(plan, samples.get("initial"), in_goal)):
        shifted = operating_point(plan.spec, centre)
        if shifted is not None:
            found = _fitting(plan, networks, samples, boundary, centre, shifted, rng)
        if found:
            break
    found.sort(key=lambda fit: fit[0], reverse=True)
    return [(True, _setter(networks, controller, v_part, b_part, K, operating, centre))
            for _, v_part, b_part, K, operating, centre in found]


def _fitting(plan, networks: dict, samples: dict, boundary, centre, operating, rng) -> list:
    """(rank, V's (P, level), B's part or None, K, u*, c) of each closed loop at c whose
    ellipsoid round c holds the sampled I and misses the sampled boundary of S."""
    discrete = plan.spec.time is TimeDomain.DISCRETE
    controlled = plan.controller is not None
    floor = functools.partial(boundary_floor, region=plan.spec.property.role("safe"),
                              centre=centre)
    shifted = {k: (None if v is None else as_array(v) - centre) for k, v in samples.items()}
    found = []
    for A, K in lqr_gains(plan.spec, controlled, operating, rng, centre if centre.any()
                          else None):
        barrier = _barrier_part(A, discrete, shifted) if "B" in networks else None
        for ratio, P, level in separations(A, discrete, shifted.get("initial"),
                                           as_array(boundary) - centre, floor=floor):
            if ratio < MIN_RATIO:
                continue
            scale = _scale(P, A, discrete, level, shifted.get("decrease"))
            # where no quadratic B separates G from D \ F, V and the controller are
            # still seeded and B is left to learning: such seeds come last
            rank = (barrier is not None or "B" not in networks,
                    ratio if barrier is None else min(ratio, barrier[0]))
            found.append((rank, (scale * P, scale * level), barrier, K, operating, centre))
    return found


CENTRE_SHARES = (0.5, 0.25)  # of G's extent from the origin towards I, in turn


def _goal_centres(plan, initial, from_origin: bool = True) -> list[np.ndarray]:
    """Points of G on the segment from the origin (else from the middle of G's box, and
    that middle first: a set point such as a tank's level) towards the middle of I (of its
    box: the samples' mean has stray components, and a pendulum's state with a velocity
    is no equilibrium for any input), at CENTRE_SHARES of the distance to G's boundary."""
    towards = initial_middle(plan.spec, initial)
    goal = _goal(plan)
    start = np.zeros(len(plan.states)) if from_origin else box_middle(goal)
    if towards is None or start is None or not np.linalg.norm(towards - start):
        return []
    steps = start + np.linspace(0.0, 1.0, 101)[:, None] * (towards - start)
    inside = holds(goal.contains_formula(plan.states), state_env(plan.states, steps),
                   len(steps))
    extent = int(np.argmin(inside)) if not inside.all() else len(steps)
    shares = CENTRE_SHARES if from_origin else (0.0,) + CENTRE_SHARES
    return [steps[int(share * (extent - 1))] for share in shares if extent > 2]


def _zero_at_origin(networks: dict, controller) -> bool:
    """Whether a network cannot hold a centre (no biases)."""
    return controller.zero_at_origin or any(
        networks[name].linears[0].bias is None for name in ("V", "B") if name in networks)


def _boundary_samples(plan, rng: np.random.Generator, count: int = 1000) -> np.ndarray:
    """Points of the boundary of the safe set (as the plan would sample it)."""
    import torch
    generator = torch.Generator().manual_seed(int(rng.integers(2 ** 31)))
    points = sample(Boundary(plan.spec.property.role("safe")), plan.states, count, generator,
                    plan.spec.domain.bounding_box())
    return as_array(points)


def _setter(networks, controller, v_part, b_part, K, operating, centre):
    at = centre if centre.any() else None

    def set_seed() -> None:
        set_quadratic(networks["V"], *v_part, centre=at)
        if b_part is not None:
            set_quadratic(networks["B"], *b_part[1:], centre=at)
        if controller is not None:
            set_linear(controller, -K, operating + K @ centre)
    return set_seed


def _fits(plan, networks: dict, controller) -> bool:
    n = len(plan.states)
    if "V" not in networks or not holds_a_quadratic(networks["V"], n):
        return False
    if "B" in networks and not holds_a_quadratic(networks["B"], n):
        return False
    return controller is None or is_linear(controller, len(plan.controller.inputs))


def _goal(plan):
    """The set V must reach (the final set of a reach-and-stay property)."""
    prop = plan.spec.property
    return prop.role("final") if prop.form == "reach and stay while avoid" \
        else prop.role("goal")


def _origin_in_goal(plan) -> bool:
    """Whether the origin lies in the set V must reach (where V need not decrease)."""
    goal = _goal(plan)
    if goal is None:
        return False
    origin = np.zeros((1, len(plan.states)))
    return bool(holds(goal.contains_formula(plan.states), state_env(plan.states, origin), 1)[0])


def _barrier_part(A: np.ndarray, discrete: bool, samples: dict):
    """(ratio, P', d) of the better matrix separating the sampled G and D \\ F by at
    least MIN_RATIO, or None."""
    found = [fit for fit in separations(A, discrete, samples["barrier_initial"],
                                         samples["barrier_unsafe"]) if fit[0] >= MIN_RATIO]
    return max(found, key=lambda fit: fit[0], default=None)


def _scale(P: np.ndarray, A: np.ndarray, discrete: bool, level: float, points) -> float:
    """s such that the linearised change of s x^T P x is at most -DECREASE_MARGIN γ on
    the sampled S \\ G where x^T P x <= level (1 where no sample is there). The change
    is bounded by its smallest eigenvalue times the smallest |x|^2 sampled there: the
    samples seldom come as close to G as the verifier will."""
    if points is None or not len(points):
        return 1.0
    change = A.T @ P @ A - P if discrete else A.T @ P + P @ A
    inside = quadratic_values(P, points) <= level
    if not inside.any():
        return 1.0
    nearest = quadratic_values(np.eye(len(P)), points)[inside].min()
    slowest = -np.linalg.eigvalsh((change + change.T) / 2)[-1] * nearest
    return max(1.0, DECREASE_MARGIN * float(GAMMA) / slowest) if slowest > 0 else 1.0
