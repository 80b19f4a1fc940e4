"""A starting point for reach-type certificates (reach, RWA, RSWA, RAR) from the
linearisation, where the origin is an equilibrium (of the closed loop) inside the goal.

V = s (x^T P x - c) with P a Lyapunov matrix of the closed loop meets every reach
condition near the origin: V <= 0 on I when c lies above x^T P x on I, V > 0 on the
boundary of the safe set when c lies below it there, and V decreases at a rate of at
least s times x^T Q x, which the scale s makes exceed the plan's γ outside the goal. For
RAR the barrier B = x^T P' x - d of the same closed loop separates G from D \\ F.

Which P fits is a question of shape: the ellipsoid {x^T P x <= c} must hold I and miss
the boundary of S. The seed therefore tries several LQR weightings (which gain) and
several decrease matrices Q (which P for that gain), and keeps the one whose sampled
I and boundary are furthest apart in the ratio of their values. Nothing here is trusted:
the seed is verified like any candidate, and learning starts from it where it fails.
"""
from __future__ import annotations

import numpy as np
import torch

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.engine.linear import (LEVEL_POSITION, _holds_a_quadratic, _is_linear,
                                      _set_linear, _set_quadratic, closed_loop,
                                      lyapunov_matrix, operating_point)
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.certificates.rwa import GAMMA

REACH_FORMS = ("reach while avoid", "reach", "reach and stay while avoid",
               "reach-avoid-remain")
GAINS = 8  # LQR weightings tried (the first: identities)
SHAPES = 24  # decrease matrices Q tried per gain (the first: I)
WEIGHT_SPREAD = 1.0  # LQR weights drawn as 10^u, u uniform in [-spread, spread]
MIN_RATIO = 1.05  # the sampled boundary must lie this factor beyond the sampled I
DECREASE_MARGIN = 5.0  # the seed's linear decrease outside G: this many times γ


def seed(plan, networks: dict, controller, samples: dict) -> bool:
    """Set V (and B for RAR) and the controller to the best fitting quadratic seed;
    whether it seeded."""
    if plan.spec.property.form not in REACH_FORMS or not _fits(plan, networks, controller):
        return False
    operating = operating_point(plan.spec)
    if operating is None or not _origin_in_goal(plan):
        return False
    rng = np.random.default_rng(plan.options.seed)
    best = None
    for A, K in _gains(plan, controller is not None, operating, rng):
        for fit in _shapes(A, plan.spec.time is TimeDomain.DISCRETE, samples, rng):
            if best is None or fit[0] > best[0]:
                best = (*fit, K)
    if best is None or best[0] < MIN_RATIO:
        return False
    _, v_part, b_part, K = best
    _set_quadratic(networks["V"], *v_part)
    if b_part is not None and "B" in networks:
        _set_quadratic(networks["B"], *b_part)
    if controller is not None:
        _set_linear(controller, -K, operating)
    return True


def _fits(plan, networks: dict, controller) -> bool:
    n = len(plan.states)
    if "V" not in networks or not _holds_a_quadratic(networks["V"], n):
        return False
    if "B" in networks and not _holds_a_quadratic(networks["B"], n):
        return False
    return controller is None or _is_linear(controller, len(plan.controller.inputs))


def _origin_in_goal(plan) -> bool:
    """Whether the origin lies in the set V must reach (where V need not decrease)."""
    prop = plan.spec.property
    goal = prop.role("goal") if prop.form != "reach and stay while avoid" \
        else prop.role("final")
    if goal is None:
        return False
    origin = np.zeros((1, len(plan.states)))
    return bool(holds(goal.contains_formula(plan.states), state_env(plan.states, origin), 1)[0])


def _gains(plan, controlled: bool, operating, rng):
    """(closed-loop A, K) for LQR with identity weights, then random diagonal ones."""
    tries = GAINS if controlled and len(plan.spec.inputs) else 1
    n, m = len(plan.states), len(plan.spec.inputs)
    for index in range(tries):
        weights = (None, None) if index == 0 else (
            np.diag(10 ** rng.uniform(-WEIGHT_SPREAD, WEIGHT_SPREAD, n)),
            np.diag(10 ** rng.uniform(-WEIGHT_SPREAD, WEIGHT_SPREAD, m)))
        found = closed_loop(plan.spec, controlled, operating, *weights)
        if found is not None:
            yield found


def _shapes(A: np.ndarray, discrete: bool, samples: dict, rng):
    """(ratio, (P, c) for V, (P', d) or None for B) for decrease matrices I and random
    positive definite ones."""
    n = len(A)
    for index in range(SHAPES):
        factor = np.eye(n) if index == 0 else rng.standard_normal((n, n))
        Q = factor @ factor.T + 0.1 * np.eye(n)
        P = lyapunov_matrix(A, discrete, Q / np.linalg.norm(Q, 2))
        if P is None:
            continue
        ratio, level = _separation(P, samples.get("initial"), samples.get("boundary"))
        if level is None:
            continue
        scale = _scale(P, A, discrete, level, samples.get("decrease"))
        v_part, b_part = (scale * P, scale * level), None
        if "barrier_initial" in samples:
            b_ratio, b_level = _separation(P, samples["barrier_initial"],
                                           samples["barrier_unsafe"])
            if b_level is None:
                continue
            ratio, b_part = min(ratio, b_ratio), (P, b_level)
        yield ratio, v_part, b_part


def _values(P: np.ndarray, points) -> np.ndarray:
    points = np.asarray(points.detach() if isinstance(points, torch.Tensor) else points,
                        dtype=np.float64)
    return np.einsum("bi,ij,bj->b", points, P, points)


def _separation(P: np.ndarray, inside, outside) -> tuple[float, float | None]:
    """(how many times the smallest x^T P x on `outside` exceeds the largest on
    `inside`, a level between them), or (0, None) where none separates them."""
    if inside is None or outside is None or not len(inside) or not len(outside):
        return 0.0, None
    high, low = _values(P, inside).max(), _values(P, outside).min()
    if not 0 < high < low:
        return 0.0, None
    return low / high, high + LEVEL_POSITION * (low - high)


def _scale(P: np.ndarray, A: np.ndarray, discrete: bool, level: float, points) -> float:
    """s such that the linearised change of s x^T P x is at most -DECREASE_MARGIN γ on
    the sampled S \\ G where x^T P x <= level (1 where no sample is there). The change
    is bounded by its smallest eigenvalue times the smallest |x|^2 sampled there: the
    samples seldom come as close to G as the verifier will."""
    if points is None or not len(points):
        return 1.0
    change = A.T @ P @ A - P if discrete else A.T @ P + P @ A
    inside = _values(P, points) <= level
    if not inside.any():
        return 1.0
    nearest = _values(np.eye(len(P)), points)[inside].min()
    slowest = -np.linalg.eigvalsh((change + change.T) / 2)[-1] * nearest
    return max(1.0, DECREASE_MARGIN * float(GAMMA) / slowest) if slowest > 0 else 1.0
