"""An ellipsoid between I and D that the linearised closed loop keeps, with its state
feedback where there are inputs, as a seed for a region of attraction.

With Q = P^-1 and Y = K Q (u = K x), the classical linear matrix inequalities

    A Q + Q A^T + B Y + Y^T B^T + 2 a Q <= 0     (V = x^T P x decays at rate 2a; continuous)
    [[Q, (A Q + B Y)^T], [A Q + B Y, r^2 Q]] >= 0  (V(f(x)) <= r^2 V(x); maps)
    [[1, p^T], [p, Q]] >= 0 for each corner p of I's box   (I inside {V <= 1})
    Q >= r^2 I instead where I is a ball of radius r round the origin
    Q_ii <= s d_i^2                                (the ellipsoid inside s D, D a box or ball)
    a^T Q a <= s b^2       (and away from an unsafe half-space {a^T x >= b}, b > 0)
    [[g, Y], [Y^T, Q]] >= 0  (|u| bounded on the ellipsoid, so the nonlinear terms stay small)

are solved for the smallest s + w g (s alone without inputs; Clarabel, through
solvers/sdp.py). The decay may be asked of more pairs (A_i, B_i) as well, Jacobians at
other points of D (quadratic_roa.py: half way to each face): V then falls for every
loop of that polytopic inclusion, which keeps it falling where the nonlinearity bends
the field away from its linearisation (probe60/ae02, a ducted fan: no ellipsoid of the
linearisation alone had V falling at every sample; with the 12 Jacobians, one has).
Where s < 1, {V <= 1} holds I and lies inside D, and the LQR seeds' identity weights
may not manage that (a cart-pole's LQR ellipsoid is flat in one direction: every
sublevel set that holds I leaves D; a non-normal A's Lyapunov matrices are far from
round). Nothing here is trusted: the seed is checked on samples and verified
like any candidate.
"""
from __future__ import annotations

import functools
import itertools

import numpy as np

from fossil_dsl.ir import sets as S
from fossil_dsl.solvers.sdp import Program

# a (continuous time) and r (maps), the strongest feasible first: a margin in the decrease
# is what the verifier needs (a cart-pole's decrease with a = 0.1 was left UNKNOWN after
# 60 s; with a = 1, dV/dt <= -1.8 V on the samples)
DECAYS = (3.0, 1.0, 0.5, 0.3, 0.1)
CONTRACTIONS = (0.7, 0.85, 0.95, 0.98)
# only where none of those is feasible: linearisations that decay slowly (probe61/ag01, a
# two-link arm under PD: nothing at 0.1, s = 0.4 at 0.03)
SLOW_DECAYS = (0.03, 0.01)
SLOW_CONTRACTIONS = (0.995,)
# w: how much a small |u| counts against a small ellipsoid; the later ones where the
# earlier candidates fail: tanh-saturated inputs need |u| where tanh(u) is nearly u
# (probe58/ab04: |u| <= 1.6 on the first ellipsoid, V grows at samples, 0.8 on the
# second, certified; probe63/ak04: 1.1 on the second, tanh's sector [0.73, 1] lets V
# grow, 0.25 on the third, certified)
GAIN_WEIGHTS = (1e-3, 0.1, 1.0)
MAX_CORNERS = 256  # I's box in at most 8 states
SECONDS = 5.0  # for the solver
# s at most this: the sampled level between I and D needs room (with a = 1 a cart-pole's
# ellipsoid filled 95 % of D's box, and the level chosen from samples fell below I's
# corners: an iteration lost); else the feasible one with the smallest s
ROOM = 0.8
BISECTIONS = 3  # of the gap between the strongest feasible listed rate and the next


def ellipsoid(A: np.ndarray, B: np.ndarray, spec, discrete: bool,
              weight: float = GAIN_WEIGHTS[0]):
    """(P, K) with u = K x for the strongest rate whose s is at most ROOM (else the
    weakest feasible one), or None where the sets are not boxes or balls round the
    origin's neighbourhood, or the inequalities are infeasible, or s >= 1."""
    solve = _solver(A, B, spec, discrete, weight)
    return None if solve is None else _strongest(solve, discrete)


def ellipsoids(A: np.ndarray, B: np.ndarray, spec, discrete: bool, vertices=(),
               between=None):
    """ellipsoid()'s (P, K) for each of GAIN_WEIGHTS (the first alone without inputs):
    the later ones keep |u| smaller on the ellipsoid (a saturating tanh(u) near u); each
    followed by the strongest feasible rate, found by bisection, where that is another
    (the nonlinear terms need the larger margin: probe65/ao10, a planar quadrotor, has V
    growing at samples of the ellipsoid at a = 0.1 and none at 0.15 or 0.2, where s is
    over ROOM). `vertices`, pairs (A_i, B_i) of Jacobians elsewhere in D, ask the same
    decay of each (a polytopic differential inclusion round the linearisation).
    `between`, (inner, outer), puts the ellipsoid between other sets than I and D
    (reach-avoid-remain's G and F)."""
    for weight in GAIN_WEIGHTS[:len(GAIN_WEIGHTS) if B.shape[1] else 1]:
        solve = _solver(A, B, spec, discrete, weight, tuple(vertices), between)
        found = None if solve is None else _strongest(solve, discrete)
        if found is not None:
            yield found
            stronger = _strongest_feasible(solve, discrete)
            if stronger is not None and not np.allclose(stronger[0], found[0]):
                yield stronger


def _solver(A, B, spec, discrete: bool, weight: float, vertices=(), between=None):
    """rate -> (P, K, s) or None, for the spec's sets (I and D, or `between`'s inner and
    outer set); None where they do not suit."""
    initial, outer = between or (spec.property.role("initial"), spec.domain)
    # an outer ball round the origin holds the ellipsoid exactly when Q <= s R^2 I (its
    # inscribed box asks sqrt(n) times less room: probe74/ax33's F)
    outer_radius = _ball_radius(outer) if between else None
    half_widths = np.full(len(A), np.inf) if outer_radius else _half_widths(outer, len(A))
    radius = _ball_radius(initial)
    corners = np.empty((0, len(A))) if radius else _corners(initial, len(A))
    if half_widths is None or corners is None:
        return None
    planes = [] if between else _unsafe_planes(spec)
    # (cached: the strongest feasible rate's search goes over the listed rates again)
    return functools.lru_cache(maxsize=None)(
        lambda rate: _solve(A, B, half_widths, corners, radius, discrete, rate, planes,
                            weight, vertices, outer_radius))


def _strongest(solve, discrete: bool):
    """(P, K) for the strongest listed rate whose s is at most ROOM, else the weakest
    feasible one; the slow rates only where no listed one is feasible."""
    for rates in _rate_lists(discrete):
        last = None
        for rate in rates:
            try:
                found = solve(rate)
            except (ValueError, np.linalg.LinAlgError):  # numerical trouble: no seed
                return None
            if found is not None and found[2] <= ROOM:
                return found[:2]
            last = found or last
        if last is not None:
            return last[:2]
    return None


def _rate_lists(discrete: bool) -> tuple[tuple, tuple]:
    """(the listed rates, the slow ones), strongest first."""
    return (CONTRACTIONS, SLOW_CONTRACTIONS) if discrete else (DECAYS, SLOW_DECAYS)


def _strongest_feasible(solve, discrete: bool):
    """(P, K) at the strongest rate with s < 1, to within BISECTIONS halvings of the gap
    between the listed rates, or None."""
    listed, slow = _rate_lists(discrete)
    rates = listed + slow
    try:
        first = next((i for i, rate in enumerate(rates) if solve(rate) is not None), None)
        if first is None:
            return None
        feasible, found = rates[first], solve(rates[first])
        infeasible = rates[first - 1] if first else None
        for _ in range(BISECTIONS if infeasible is not None else 0):
            middle = (feasible + infeasible) / 2
            result = solve(middle)
            feasible, infeasible, found = (middle, infeasible, result) if result \
                else (feasible, middle, found)
    except (ValueError, np.linalg.LinAlgError):
        return None
    return found[:2]


def _half_widths(domain, n: int) -> np.ndarray | None:
    """d with the box {|x_i| <= d_i} inside D (D a box, or a ball, holding the origin)."""
    while isinstance(domain, S.Named):
        domain = domain.value
    if isinstance(domain, S.Box):
        low, high = domain.bounding_box()
        d = np.minimum(-np.asarray(low, float), np.asarray(high, float))
    elif isinstance(domain, S.Ball):
        low, high = domain.bounding_box()
        centre = (np.asarray(low, float) + np.asarray(high, float)) / 2
        room = (np.asarray(high, float) - low)[0] / 2 - np.linalg.norm(centre)
        d = np.full(n, room / np.sqrt(n))
    else:
        return None
    return d if (d > 0).all() else None


def _ball_radius(initial) -> float | None:
    """r where I is a ball of radius r round the origin: it is inside {x^T Q^-1 x <= 1}
    exactly when Q >= r^2 I, where its box's corners (sqrt(n) times as far out: 2.6 times
    for w09's 7 states) would ask far more of the ellipsoid."""
    while isinstance(initial, S.Named):
        initial = initial.value
    if not isinstance(initial, S.Ball):
        return None
    low, high = (np.asarray(side, float) for side in initial.bounding_box())
    return None if np.any(low + high) else float(high[0])


def _unsafe_planes(spec) -> list[tuple[np.ndarray, float]]:
    """(a, b) for an unsafe set that is one half-space {a^T x >= b} missing the origin
    (a sampled sublevel set of a symmetric ellipsoid holding I can reach into it: a
    bound on x1 + x2 where I lies at x1 = x2 = 1.1); else none."""
    from fossil_dsl.engine.sos import Inexact, set_constraints
    from fossil_dsl.ir import polynomials as P
    unsafe = spec.property.role("unsafe")
    try:
        constraints = [] if unsafe is None else set_constraints(unsafe, spec.states, True)
    except Inexact:
        return []
    if len(constraints) != 1 or P.degree(constraints[0]) != 1:
        return []
    g, n = constraints[0], len(spec.states)  # g = a^T x - b >= 0 on U
    a = np.array([float(g.get(tuple(int(i == k) for i in range(n)), 0)) for k in range(n)])
    b = -float(g.get((0,) * n, 0))
    return [(a, b)] if b > 0 else []


def _corners(initial, n: int) -> np.ndarray | None:
    box = initial.bounding_box() if initial is not None else None
    if box is None or 2 ** n > MAX_CORNERS:
        return None
    return np.array(list(itertools.product(*zip(box[0], box[1]))), dtype=float)


def _solve(A, B, d, corners, radius: float | None, discrete: bool, rate: float,
           planes=(), weight: float = GAIN_WEIGHTS[0], vertices=(),
           outer_radius: float | None = None):
    n, m = B.shape
    lmi = _Inequalities(n)
    Q = lmi.symmetric(n)  # positive semidefinite
    Y = [[({lmi.scalar(): 1.0}, 0.0) for _ in range(n)] for _ in range(m)]
    s, g = lmi.scalar(), lmi.scalar()
    for Ai, Bi in ((A, B), *vertices):
        _decay(lmi, Q, Y, Ai, Bi, discrete, rate)
    if radius:  # I is a ball round the origin: Q - r^2 I >= 0
        lmi.block(n, lambda i, j: _sum([Q[i][j], ({}, -radius ** 2 if i == j else 0.0)]))
    for p in corners:
        lmi.block(n + 1, lambda i, j, p=p: ({}, 1.0) if j == 0 else ({}, float(p[j - 1]))
                  if i == 0 else Q[i - 1][j - 1])
    lmi.block(m + n, lambda i, j: ({g: 1.0}, 0.0) if j < m and i == j else ({}, 0.0)
              if j < m else Y[i][j - m] if i < m else Q[i - m][j - m])
    if outer_radius:  # s R^2 I - Q >= 0
        lmi.block(n, lambda i, j: _sum([_scaled(Q[i][j], -1.0),
                                        ({s: outer_radius ** 2} if i == j else {}, 0.0)]))
    if not outer_radius:  # Q_ii <= s d_i^2
        for i in range(n):
            forms, _ = Q[i][i]
            lmi.at_most.append(({**forms, s: -float(d[i]) ** 2}, 0.0))
    for a, b in planes:  # a^T Q a - s b^2 <= 0
        lmi.at_most.append((_sum([_scaled(Q[i][j], a[i] * a[j]) for i in range(n)
                                  for j in range(n)] + [({s: -b ** 2}, 0.0)])[0], 0.0))
    # without inputs g bounds nothing: weighed, it would leave the program unbounded
    x = lmi.solve({s: 1.0, g: weight} if m else {s: 1.0}, SECONDS)
    if x is None or x[s] >= 1:
        return None
    Qv = np.array([[_value(Q[i][j], x) for j in range(n)] for i in range(n)])
    Yv = np.array([[_value(Y[l][j], x) for j in range(n)] for l in range(m)]).reshape(m, n)
    P = np.linalg.inv(Qv)
    return (P + P.T) / 2, Yv @ P, float(x[s])


def _decay(lmi, Q, Y, A, B, discrete: bool, rate: float) -> None:
    """The block that makes V = x^T Q^-1 x decay at `rate` along x' = (A + B K) x."""
    n, m = B.shape
    # C = A Q + B Y, entry by entry, as linear forms
    C = [[_sum([_scaled(Q[k][j], A[i, k]) for k in range(n)]
               + [_scaled(Y[l][j], B[i, l]) for l in range(m)]) for j in range(n)]
         for i in range(n)]
    if discrete:
        lmi.block(2 * n, lambda i, j: Q[i][j] if j < n else C[j - n][i] if i < n
                  else _scaled(Q[i - n][j - n], rate ** 2))
    else:
        lmi.block(n, lambda i, j: _scaled(_sum([C[i][j], C[j][i],
                                                _scaled(Q[i][j], 2 * rate)]), -1.0))


class _Inequalities(Program):
    """Linear matrix inequalities as positive semidefinite blocks whose entries equal
    linear forms ({variable: coefficient}, constant) of the variables."""

    def symmetric(self, n: int):
        """A positive semidefinite n x n variable, as forms Q[i][j]."""
        entries = self.gram(_basis(n), lambda p: {})
        Q = [[None] * n for _ in range(n)]
        for variable, i, j in entries:
            Q[i][j] = Q[j][i] = ({variable: 1.0}, 0.0)
        return Q

    def block(self, size: int, entry) -> None:
        """A positive semidefinite block whose (i, j) entry (i <= j) is entry(i, j)."""
        for variable, i, j in self.gram(_basis(size), lambda p: {}):
            forms, constant = entry(i, j)
            self.equalities.append(({variable: 1.0, **{v: -c for v, c in forms.items()}},
                                    constant))


def _basis(size: int):
    """`size` distinct monomials (only their count matters to a block without terms)."""
    return [tuple(int(k == i) for k in range(size)) for i in range(size)]


def _scaled(form, factor: float):
    forms, constant = form
    return {v: c * factor for v, c in forms.items()}, constant * factor


def _sum(forms):
    total: dict[int, float] = {}
    constant = 0.0
    for part, value in forms:
        for v, c in part.items():
            total[v] = total.get(v, 0.0) + c
        constant += value
    return total, constant


def _value(form, x) -> float:
    forms, constant = form
    return constant + sum(c * x[v] for v, c in forms.items())
