"""Quadratic shapes for seeds: closed loops of the linearisation under several LQR
weightings, Lyapunov matrices P of a closed loop under which one sampled set lies as far
inside {x^T P x <= 1} as possible relative to another (a small semidefinite program),
and the smallest value of (x - c)^T P (x - c) on boxes, balls and their combinations
(the floors a seed's level must stay under). Used by the safety and reach-type seeds;
nothing here is trusted."""
from __future__ import annotations

import itertools
import math
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.linear import (MAX_CONDITION, as_array, closed_loop, lyapunov_matrix,
                                      separation)
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials
from fossil_dsl.ir import sets as S
from fossil_dsl.solvers.sdp import Program

GAINS = 8  # LQR weightings tried (the first: identities)
SDP_SAMPLES = 300  # of each sampled set, at most, in the separating program
LMI_MARGIN = 1e-3  # the program's decrease: A^T P + P A <= -this I (P's scale: 1 on I)
MAX_TRACE = 1e4  # keeps the program bounded where I is thin
WEIGHT_SPREAD = 1.0  # LQR weights drawn as 10^u, u uniform in [-spread, spread]
MAX_CORNER_STATES = 12  # a box's largest value is found over its 2^n corners up to this n


def lqr_gains(spec, controlled: bool, operating, rng, state=None):
    """(closed-loop A, K) for LQR with identity weights, then random diagonal ones."""
    tries = GAINS if controlled and len(spec.inputs) else 1
    n, m = len(spec.states), len(spec.inputs)
    for index in range(tries):
        weights = (None, None) if index == 0 else (
            np.diag(10 ** rng.uniform(-WEIGHT_SPREAD, WEIGHT_SPREAD, n)),
            np.diag(10 ** rng.uniform(-WEIGHT_SPREAD, WEIGHT_SPREAD, m)))
        found = closed_loop(spec, controlled, operating, *weights, state=state)
        if found is not None:
            yield found


def lqr_controllers(plan, operating: np.ndarray, rng, centre=None):
    """(input -> exact formula, -K) for each LQR gain (rounded to the digits the
    verifier sees), or one ({}, None) without inputs; with a `centre` c (an equilibrium
    for the inputs `operating`), u = -K (x - c) + operating."""
    spec = plan.spec
    if not spec.inputs:
        yield {}, None
        return
    for _, K in lqr_gains(spec, True, operating, rng, centre):
        gain = np.round(-K, plan.options.digits)
        yield exact_controller(spec, gain, set_point_bias(operating, gain, centre),
                               plan.options.digits)


def set_point_bias(operating: np.ndarray, gain: np.ndarray, centre=None) -> np.ndarray:
    """The bias b of u = gain x + b that holds the state at `centre` with the inputs
    `operating`, from the gain as rounded: the program's formula and the network set
    from it must agree to the last digit (probe70/at42: 1.686 against 1.687)."""
    return operating if centre is None else operating - gain @ centre


def exact_controller(spec, gain: np.ndarray, operating: np.ndarray, digits: int):
    """(input -> exact formula of u = gain x + operating, the gain rounded to `digits`
    decimals as the controller network holds it)."""
    gain = np.round(gain, digits)
    bias = np.round(operating, digits)
    return {u: E.add(*(E.mul(E.Num(_exact(w)), E.Var(s)) for w, s in zip(row, spec.states)),
                     E.Num(_exact(b)))
            for u, row, b in zip(spec.inputs, gain, bias)}, gain


def _exact(value: float) -> Fraction:
    return Fraction(str(float(value)))


def box_middle(region) -> np.ndarray | None:
    """The middle of the set's bounding box (None where it has none)."""
    box = None if region is None else region.bounding_box()
    return None if box is None else (np.asarray(box[0], float) + np.asarray(box[1], float)) / 2


def initial_middle(spec, inside) -> np.ndarray | None:
    """The middle of I's bounding box, else the mean of the points sampled in I (None
    where there are none)."""
    middle = box_middle(spec.property.role("initial"))
    if middle is not None:
        return middle
    if inside is None or not len(inside):
        return None
    return as_array(inside).mean(axis=0)


def separations(A: np.ndarray, discrete: bool, inside, outside, shapes=None, floor=None,
                ceiling=None):
    """(ratio, P, level) of the Lyapunov matrix for Q = I and of the one that separates
    the sampled sets best (or of the `shapes` given), where they separate them; with a
    `floor` (P -> a lower bound of x^T P x on the outside set, or None), the samples'
    smallest value is lowered to it, and with a `ceiling` (an upper bound on the inside
    set) their largest is raised to it."""
    for shape in shapes or SHAPES:
        P = shape(A, discrete, inside, outside)
        if P is not None:
            ratio, level = separation(P, inside, outside, floor(P) if floor else None,
                                      ceiling(P) if ceiling else None)
            if level is not None:
                yield ratio, P, level


def plain_lyapunov(A: np.ndarray, discrete: bool, inside, outside) -> np.ndarray | None:
    """The Lyapunov matrix for Q = I (the sets play no part): the surest decrease."""
    return lyapunov_matrix(A, discrete)


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


SHAPES = (plain_lyapunov, separating_lyapunov)


def floor_outside(P: np.ndarray, inner, outer, centre: np.ndarray) -> float | None:
    """A lower bound (or, for a box, the computed minimum) of (x - c)^T P (x - c) where
    the ellipsoid {(x - c)^T P (x - c) <= t} would leave `inner` (a convex set round c,
    through its boundary) or meet `outer`; None where a shape is not one worked out
    here. Sampled sets miss the corners of a box in 4 or more dimensions, where an
    ellipsoid chosen on samples alone was seen to cross the domain's boundary."""
    parts = [boundary_floor(P, inner, centre) if inner is not None else math.inf,
             set_floor(P, outer, centre) if outer is not None else math.inf]
    return None if any(p is None for p in parts) else min(parts)


def boundary_floor(P: np.ndarray, region, centre: np.ndarray) -> float | None:
    """The smallest value of the quadratic on the boundary of a box or ball that holds
    the centre (from below), of their intersections and differences; else None."""
    region = _unnamed(region)
    if isinstance(region, S.Difference):
        return floor_outside(P, region.left, region.right, centre)
    if isinstance(region, S.Complement):  # D minus the operand
        return floor_outside(P, region.domain, region.operand, centre)
    if isinstance(region, S.Intersection):
        parts = [boundary_floor(P, side, centre) for side in (region.left, region.right)]
        return None if None in parts else min(parts)
    bounds = _numbers(region) if isinstance(region, (S.Box, S.Ball)) else None
    if bounds is None:
        return None
    if isinstance(region, S.Box):
        low, high = bounds
        if not np.all((low <= centre) & (centre <= high)):
            return None
        spread = np.diag(np.linalg.inv(P))  # the ellipsoid's extent along axis i: sqrt(t s_i)
        return float(min(np.minimum(centre - low, high - centre) ** 2 / spread))
    if isinstance(region, S.Ball):
        middle, radius = bounds
        gap = radius - np.linalg.norm(centre - middle)
        return float(np.linalg.eigvalsh(P)[0] * gap ** 2) if gap > 0 else None
    return None


def set_floor(P: np.ndarray, region, centre: np.ndarray) -> float | None:
    """The smallest value of the quadratic on a box (a convex program solved
    numerically), a ball (from below), the outside of a ball within the domain (its
    sphere), and unions of these; else None."""
    region = _unnamed(region)
    if isinstance(region, S.Union):
        parts = [set_floor(P, side, centre) for side in (region.left, region.right)]
        return None if None in parts else min(parts)
    if isinstance(region, S.Complement):
        return boundary_floor(P, region.operand, centre)
    bounds = _numbers(region) if isinstance(region, (S.Box, S.Ball)) else None
    if bounds is None:
        return None
    if isinstance(region, S.Box):
        return _box_minimum(P, centre, *bounds)
    if isinstance(region, S.Ball):
        return _ball_minimum(P, np.asarray(bounds[0], float) - centre, bounds[1])
    return None


def set_ceiling(P: np.ndarray, region, centre: np.ndarray) -> float | None:
    """An upper bound of (x - c)^T P (x - c) on a box (its largest value, at a corner),
    a ball, their unions and intersections; else None. Samples of a box in 4 or more
    dimensions miss its corners, where a level chosen on them alone can leave part of
    the initial set outside the seed's sublevel set."""
    region = _unnamed(region)
    if isinstance(region, (S.Union, S.Intersection)):
        parts = [set_ceiling(P, side, centre) for side in (region.left, region.right)]
        if isinstance(region, S.Union):
            return None if None in parts else max(parts)
        known = [p for p in parts if p is not None]  # each side holds the intersection
        return min(known) if known else None
    bounds = _numbers(region) if isinstance(region, (S.Box, S.Ball)) else None
    if bounds is None:
        return None
    if isinstance(region, S.Box):
        low, high = bounds
        if len(low) > MAX_CORNER_STATES:
            return None
        corners = np.array(list(itertools.product(*zip(low, high)))) - centre
        return float(np.einsum("bi,ij,bj->b", corners, P, corners).max())
    middle, radius = bounds
    offset = middle - centre
    reach = math.sqrt(offset @ P @ offset) + radius * math.sqrt(np.linalg.eigvalsh(P)[-1])
    return float(reach ** 2)


def _box_minimum(P, centre, low, high, steps: int = 500) -> float:
    """min of (x - c)^T P (x - c) over the box, by projected gradient steps of 1 / (2
    λmax(P)) from the point of the box nearest c (a convex problem; scipy.optimize
    would cost 0.6 s of import for this)."""
    x = np.clip(centre, low, high)
    if np.allclose(x, centre):
        return 0.0
    step = 0.5 / np.linalg.eigvalsh(P)[-1]
    for _ in range(steps):
        moved = np.clip(x - step * 2 * P @ (x - centre), low, high)
        if np.allclose(moved, x, rtol=0, atol=1e-12):
            break
        x = moved
    return float((x - centre) @ P @ (x - centre))


def _ball_minimum(P, middle, radius: float, halvings: int = 100) -> float:
    """min of y^T P y over the ball |y - m| <= r (λmin(P) times the gap squared was too
    low for a flat P: probe73/aw30's seed was refused beside an obstacle it missed). On
    the sphere, P y = μ (m - y) at the minimum: y = μ (P + μ)^-1 m, whose distance from
    m falls and whose value rises as μ grows; μ by bisection in the eigenbasis of P."""
    if np.linalg.norm(middle) <= radius:
        return 0.0
    eigenvalues, basis = np.linalg.eigh(P)
    z = basis.T @ middle

    def distance(mu: float) -> float:
        return float(np.sqrt(np.sum((eigenvalues / (eigenvalues + mu) * z) ** 2)))
    low, high = 0.0, 1.0
    while distance(high) > radius:
        low, high = high, 2 * high
    for _ in range(halvings):
        middle_mu = (low + high) / 2
        low, high = (middle_mu, high) if distance(middle_mu) > radius else (low, middle_mu)
    y = low / (eigenvalues + low) * z  # just outside the ball: its value is below the min
    return float(np.sum(eigenvalues * y ** 2))


def _unnamed(region):
    while isinstance(region, S.Named):
        region = region.value
    return region


def _numbers(region):
    """A box's (low, high) or a ball's (centre, radius) as floats, from its bounding box
    (None where it has none)."""
    box = region.bounding_box()
    if box is None:
        return None
    low, high = (np.asarray(side, dtype=float) for side in box)
    if isinstance(region, S.Box):
        return low, high
    return (low + high) / 2, float(np.min(high - low)) / 2


def enters_box(box_set, field, P: np.ndarray, level: float, points: np.ndarray) -> bool:
    """The field points into the box at the sample points of {x^T P x <= level} moved
    onto each of its faces (those still in the sublevel set)."""
    low, high = box_set.bounding_box()
    for i, end, side in ((i, end, side) for i in range(len(P))
                         for end, side in ((low[i], 1.0), (high[i], -1.0))):
        face = points.copy()
        face[:, i] = end
        face = face[np.einsum("bi,ij,bj->b", face, P, face) <= level]
        with np.errstate(all="ignore"):
            if len(face) and not np.all(side * field(face)[:, i] > 0):
                return False
    return True
