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
ratio is kept. Nothing here is trusted: the seed is verified like any candidate, and
learning starts from it where it fails.
"""
from __future__ import annotations

import numpy as np

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.engine.linear import (MAX_CONDITION, as_array, closed_loop, holds_a_quadratic,
                                      is_linear, lyapunov_matrix, operating_point,
                                      quadratic_values, separation, set_linear,
                                      set_quadratic)
from fossil_dsl.ir import polynomials
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.solvers.sdp import Program
from fossil_dsl.plan.certificates.rwa import GAMMA

REACH_FORMS = ("reach while avoid", "reach", "reach and stay while avoid",
               "reach-avoid-remain")
GAINS = 8  # LQR weightings tried (the first: identities)
SDP_SAMPLES = 300  # of each sampled set, at most, in the separating program
LMI_MARGIN = 1e-3  # the program's decrease: A^T P + P A <= -this I (P's scale: 1 on I)
MAX_TRACE = 1e4  # keeps the program bounded where I is thin
WEIGHT_SPREAD = 1.0  # LQR weights drawn as 10^u, u uniform in [-spread, spread]
MIN_RATIO = 1.05  # the sampled boundary must lie this factor beyond the sampled I
DECREASE_MARGIN = 5.0  # the seed's linear decrease outside G: this many times γ


def candidates(plan, networks: dict, controller, samples: dict) -> list:
    """Seeds to try, best separated first: each a function that sets V (and B for RAR)
    and the controller. Empty where no seed applies."""
    if plan.spec.property.form not in REACH_FORMS or not _fits(plan, networks, controller):
        return []
    operating = operating_point(plan.spec)
    if operating is None or not _origin_in_goal(plan):
        return []
    rng = np.random.default_rng(plan.options.seed)
    discrete = plan.spec.time is TimeDomain.DISCRETE
    found = []
    for A, K in _gains(plan, controller is not None, operating, rng):
        barrier = _barrier_part(A, discrete, samples) if "B" in networks else None
        for ratio, P, level in _separations(A, discrete, samples.get("initial"),
                                            samples.get("boundary")):
            if ratio < MIN_RATIO:
                continue
            scale = _scale(P, A, discrete, level, samples.get("decrease"))
            # where no quadratic B separates G from D \ F, V and the controller are
            # still seeded and B is left to learning: such seeds come last
            rank = (barrier is not None or "B" not in networks,
                    ratio if barrier is None else min(ratio, barrier[0]))
            found.append((rank, (scale * P, scale * level), barrier, K))
    found.sort(key=lambda fit: fit[0], reverse=True)
    return [_setter(networks, controller, v_part, b_part, K, operating)
            for _, v_part, b_part, K in found]


def _setter(networks, controller, v_part, b_part, K, operating):
    def set_seed() -> None:
        set_quadratic(networks["V"], *v_part)
        if b_part is not None:
            set_quadratic(networks["B"], *b_part[1:])
        if controller is not None:
            set_linear(controller, -K, operating)
    return set_seed


def _fits(plan, networks: dict, controller) -> bool:
    n = len(plan.states)
    if "V" not in networks or not holds_a_quadratic(networks["V"], n):
        return False
    if "B" in networks and not holds_a_quadratic(networks["B"], n):
        return False
    return controller is None or is_linear(controller, len(plan.controller.inputs))


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


def _separations(A: np.ndarray, discrete: bool, inside, outside):
    """(ratio, P, level) of the Lyapunov matrix for Q = I and of the one that separates
    the sampled sets best, where they separate them."""
    for P in (lyapunov_matrix(A, discrete), separating_lyapunov(A, discrete, inside, outside)):
        if P is not None:
            ratio, level = separation(P, inside, outside)
            if level is not None:
                yield ratio, P, level


def _barrier_part(A: np.ndarray, discrete: bool, samples: dict):
    """(ratio, P', d) of the better matrix separating the sampled G and D \\ F by at
    least MIN_RATIO, or None."""
    found = [fit for fit in _separations(A, discrete, samples["barrier_initial"],
                                         samples["barrier_unsafe"]) if fit[0] >= MIN_RATIO]
    return max(found, key=lambda fit: fit[0], default=None)


def separating_lyapunov(A: np.ndarray, discrete: bool, inside, outside,
                        seconds: float = 2.0) -> np.ndarray | None:
    """P (largest eigenvalue 1) of a Lyapunov function of x' = Ax (x+ = Ax) whose
    sampled `inside` lies in {x^T P x <= 1} and `outside` in {x^T P x >= t}, t as large
    as possible: a semidefinite program (P, and W = -(A^T P + P A) - εI, both PSD)."""
    if inside is None or outside is None or not len(inside) or not len(outside):
        return None
    inside, outside = _thinned(as_array(inside)), _thinned(as_array(outside))
    n = len(A)
    program = Program(n)
    basis = polynomials.monomials(n, 1, 1)
    entries = program.gram(basis, of=lambda p: {})
    slack = program.gram(basis, of=lambda p: {})
    variable = {(i, j): v for v, i, j in entries}
    variable.update({(j, i): v for v, i, j in entries})
    change = _change_matrix(A, discrete)  # entries of the change's matrix, linear in P
    for (v, i, j), (w, _, _) in zip(entries, slack):
        row = {w: 1.0}
        for (k, l), weight in change[i][j].items():
            row[variable[k, l]] = row.get(variable[k, l], 0.0) + weight
        program.equalities.append((row, -LMI_MARGIN * (i == j)))
    t = program.scalar()
    for x in inside:
        program.at_most.append((_quadratic_row(x, entries), 1.0))
    for x in outside:
        row = {v: -c for v, c in _quadratic_row(x, entries).items()}
        row[t] = 1.0
        program.at_most.append((row, 0.0))
    program.at_most.append(({v: 1.0 for v, i, j in entries if i == j}, MAX_TRACE))
    x = program.solve({t: -1.0}, seconds)
    if x is None:
        return None
    P = program.matrix(x, entries, n)
    eigenvalues = np.linalg.eigvalsh(P)
    if eigenvalues[0] <= 0 or eigenvalues[-1] / eigenvalues[0] > MAX_CONDITION:
        return None
    return P / eigenvalues[-1]


def _change_matrix(A: np.ndarray, discrete: bool) -> list[list[dict]]:
    """For each (i, j): the entry (i, j) of A^T P + P A (A^T P A - P) as weights on P's
    entries (k, l)."""
    n = len(A)
    table = [[{} for _ in range(n)] for _ in range(n)]
    for i in range(n):
        for j in range(n):
            entry = table[i][j]
            if discrete:
                for k in range(n):
                    for l in range(n):
                        _add(entry, (k, l), A[k, i] * A[l, j])
                _add(entry, (i, j), -1.0)
            else:
                for k in range(n):
                    _add(entry, (k, j), A[k, i])
                    _add(entry, (i, k), A[k, j])
    return table


def _add(entry: dict, key: tuple[int, int], weight: float) -> None:
    key = (min(key), max(key))
    entry[key] = entry.get(key, 0.0) + weight


def _quadratic_row(x: np.ndarray, entries) -> dict[int, float]:
    return {v: x[i] * x[j] * (1.0 if i == j else 2.0) for v, i, j in entries}


def _thinned(points: np.ndarray) -> np.ndarray:
    return points[:: max(1, len(points) // SDP_SAMPLES)]


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
