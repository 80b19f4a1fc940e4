"""The seed for stable-type properties (stability, ROA, SWA): the linearisation's quadratic
Lyapunov function and, with inputs, its LQR gain, for several LQR weightings
(safety and reach-type seeds: safety_seed.py, reach_seed.py). Nothing here is trusted: a
seed is rounded and verified like any candidate."""
from __future__ import annotations

import itertools

import numpy as np

from fossil_dsl.engine.ellipsoid_seed import ellipsoid
from fossil_dsl.engine.linear import (STABLE_FORMS, holds_a_quadratic, is_linear, jacobians,
                                      lyapunov_matrix, separation, set_linear, set_quadratic)
from fossil_dsl.engine.networks import Network
from fossil_dsl.engine.quadratic_shapes import boundary_floor, lqr_gains, set_ceiling
from fossil_dsl.ir.spec import TimeDomain


def candidates(plan, networks: dict[str, Network], controller: Network | None,
               samples: dict | None = None):
    """Seeds for a stable-type property where the networks can hold them exactly, as
    (preferred, set_seed) pairs for Learner.seed_from: V = x^T P x and the controller
    -K x, for the LQR gain with identity weights first and then the reach seeds' random
    weightings (with a controller: the identity weights' gain can leave I outside every
    sublevel set on which V decreases, as for the Moore-Greitzer model, where others
    do not); for stable while avoid, also the barrier B = x^T P x - c with c between its
    values on the sampled I and U (a sublevel set of V is mapped into itself, so it is a
    barrier wherever it holds I and misses U). Safety and reach-type seeds:
    safety_seed.py, reach_seed.py."""
    network = networks.get("V")
    if plan.spec.property.form not in STABLE_FORMS or network is None \
            or not holds_a_quadratic(network, len(plan.states)):
        return []
    if controller is not None and not is_linear(controller, len(plan.controller.inputs)):
        return []
    return _seeds(plan, networks, controller, samples)


def _seeds(plan, networks, controller, samples):
    """One at a time: the weightings after the first are solved only when it fails.
    For a region of attraction, after the identity weights and before the others, the
    ellipsoid between I and D that the linearised closed loop keeps
    (ellipsoid_seed.py), with its own gain."""
    discrete = plan.spec.time is TimeDomain.DISCRETE
    rng = np.random.default_rng(plan.options.seed)
    gains = lqr_gains(plan.spec, controller is not None, None, rng)
    for A, K in itertools.islice(gains, 1):  # the identity weights
        yield from _lqr_seed(plan, networks, controller, samples, A, K, discrete)
    yield from _ellipsoid_seed(plan, networks, controller, samples, discrete)
    for A, K in gains:
        yield from _lqr_seed(plan, networks, controller, samples, A, K, discrete)


def _lqr_seed(plan, networks, controller, samples, A, K, discrete: bool):
    for decrease in _decreases(K):
        P = lyapunov_matrix(A, discrete, decrease)
        if P is not None:
            P = P * _margin_scale(P, A, discrete, plan.options.margin)
            yield _has_room(plan, P), _quadratic_setter(networks, controller, samples, P, K)


def _decreases(K: np.ndarray | None) -> list[np.ndarray | None]:
    """The decreases asked of P along the closed loop, in turn: with a gain, first
    I + K^T K, which for the identity weights makes P the Riccati solution (LQR's own
    Lyapunov function, which keeps decreasing when the input's gain changes by a factor
    of 1/2 to infinity: u enters as cos(th) u for a pendulum on a cart, probe49/e09,
    where V for I alone rose by up to 0.75 |x|^2 on D, scaled to largest eigenvalue 1,
    and the Riccati V falls by at least 0.043 |x|^2), then I."""
    return [None] if K is None else [np.eye(K.shape[1]) + K.T @ K, None]


MARGIN_CUSHION = 4.0  # times the learner's margin that the seed's linear part keeps


def _margin_scale(P: np.ndarray, A: np.ndarray, discrete: bool, margin: float) -> float:
    """The factor (at least 1) that lifts x^T P x and its linear decrease above the
    learner's margins (V >= m|x|^2, change <= -m|x|^2): P has largest eigenvalue 1, so an
    ill-conditioned P misses them, the learner trains on, and the valid seed is lost (a
    4-state map with one torque, probe48/c12: P's eigenvalues 0.004 to 1, and after one
    step of training V was indefinite and the gain 2 500). V's scale does not matter to
    any property's conditions."""
    decrease = P - A.T @ P @ A if discrete else -(A.T @ P + P @ A)
    least = min(np.linalg.eigvalsh(P)[0], np.linalg.eigvalsh((decrease + decrease.T) / 2)[0])
    return max(1.0, MARGIN_CUSHION * margin / least) if least > 0 else 1.0


def _has_room(plan, P: np.ndarray) -> bool:
    """Whether some sublevel set of x^T P x holds I and lies inside D, where both bounds
    are worked out (else True: the samples decide). Samples of a box's boundary in 6
    states miss the directions where an LQR ellipsoid leaves D (z09's three carts: the
    identity weights' ellipsoid, satisfied on every sample, crossed D's face)."""
    initial = plan.spec.property.role("initial")
    if initial is None:
        return True
    centre = np.zeros(len(P))
    ceiling = set_ceiling(P, initial, centre)
    floor = boundary_floor(P, plan.spec.domain, centre)
    return ceiling is None or floor is None or ceiling < floor


def _ellipsoid_seed(plan, networks, controller, samples, discrete: bool):
    found = jacobians(plan.spec) if plan.spec.property.form != "stability" else None
    if found is None:
        return
    A, B = found
    found = ellipsoid(A, B if controller is not None else np.zeros((len(A), 0)), plan.spec,
                      discrete)
    if found is not None:
        P, gain = found
        yield True, _quadratic_setter(networks, controller, samples, P, -gain)


def _quadratic_setter(networks, controller, samples, P: np.ndarray, K):
    def set_seed() -> None:
        set_quadratic(networks["V"], P)
        if controller is not None:
            set_linear(controller, -K)
        barrier = networks.get("B")
        if barrier is not None and samples and holds_a_quadratic(barrier, len(P)):
            _, level = separation(P, samples.get("barrier_initial"),
                                  samples.get("barrier_unsafe"))
            if level is not None:
                set_quadratic(barrier, P, level)
    return set_seed
