"""Quadratic shapes for seeds: closed loops of the linearisation under several LQR
weightings, and Lyapunov matrices P of a closed loop under which one sampled set lies
as far inside {x^T P x <= 1} as possible relative to another (a small semidefinite
program). Used by the safety and reach-type seeds; nothing here is trusted."""
from __future__ import annotations

import numpy as np

from fossil_dsl.engine.linear import (MAX_CONDITION, as_array, closed_loop, lyapunov_matrix,
                                      separation)
from fossil_dsl.ir import polynomials
from fossil_dsl.solvers.sdp import Program

GAINS = 8  # LQR weightings tried (the first: identities)
SDP_SAMPLES = 300  # of each sampled set, at most, in the separating program
LMI_MARGIN = 1e-3  # the program's decrease: A^T P + P A <= -this I (P's scale: 1 on I)
MAX_TRACE = 1e4  # keeps the program bounded where I is thin
WEIGHT_SPREAD = 1.0  # LQR weights drawn as 10^u, u uniform in [-spread, spread]


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


def separations(A: np.ndarray, discrete: bool, inside, outside, shapes=None):
    """(ratio, P, level) of the Lyapunov matrix for Q = I and of the one that separates
    the sampled sets best (or of the `shapes` given), where they separate them."""
    for shape in shapes or SHAPES:
        P = shape(A, discrete, inside, outside)
        if P is not None:
            ratio, level = separation(P, inside, outside)
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
