"""The conic program of engine/basin.py, assembled for Clarabel: the coefficients c of V
(monomials of y = x / scale), a hinge h >= V - 1 on each basin sample, a slack t >= 0 on
each decrease point; linear rows for the sampled conditions (each divided by |y|^2, so
points near the origin weigh like the others) and two positive semidefinite cones for
V's quadratic part Q: Q >= e I and -(A^T Q + Q A) >= e I (Q - A^T Q A >= e I for a map). The program object supplies
`values`, `changes`, `basin_values`, `exponents` and `samples` (`basin`, `squared`,
`jacobian`)."""
from __future__ import annotations

import math
import time

import numpy as np

EPS = 1e-2  # decrease asked: dV/dt <= -EPS |y|^2 (1e-3 left failures between samples, vdp mu=3)
# for the quadratic part: a margin the kernel's Taylor lemma and the interval procedure
# can see near the excluded ball (with 1e-3, vdp mu=3's decrease there timed out)
LOCAL_EPS = 2e-2
DECREASE_WEIGHT = 100.0  # of a decrease slack against the coverage objective


def solve_conic(program, outside, decrease, deadline: float):
    """(c, decrease slacks) or None, from Clarabel: variables c, hinge h >= V - 1 on the
    basin, slack t >= dV/dt + eps|y|^2 on the decrease points."""
    import clarabel
    from scipy import sparse
    s = program.samples
    basin = s.basin
    m, nb, nd = len(program.exponents), len(basin), len(decrease)
    hinge = sparse.hstack([sparse.csr_matrix((nb, m)), sparse.eye(nb), sparse.csr_matrix((nb, nd))])
    slack = sparse.hstack([sparse.csr_matrix((nd, m + nb)), sparse.eye(nd)])
    on_c = lambda rows: sparse.hstack([sparse.csr_matrix(rows),
                                       sparse.csr_matrix((len(rows), nb + nd))])
    basin_values = program.basin_values
    # rows divided by |y|^2: points near the origin weigh like the others (unscaled, their
    # 1e-9 margins were below the solver's tolerance)
    per_basin = 1.0 / s.squared(basin)[:, None]
    per_decrease = 1.0 / s.squared(decrease)[:, None]
    # A z + s = b with s >= 0: each block is "A z <= b"
    blocks = [(on_c(basin_values) - hinge, np.ones(nb)),
              (-on_c(program.values(outside)), -np.ones(len(outside))),
              (-on_c(basin_values * per_basin), -np.full(nb, EPS)),
              (on_c(program.changes(decrease) * per_decrease) - slack, -np.full(nd, EPS)),
              (-hinge, np.zeros(nb)), (-slack, np.zeros(nd))]
    quadratic, cones_rows, cones_right = _local_cones(program, m + nb + nd)
    A = sparse.vstack([b for b, _ in blocks] + [cones_rows]).tocsc()
    right = np.concatenate([r for _, r in blocks] + [cones_right])
    rows = sum(len(r) for _, r in blocks)
    cones = [clarabel.NonnegativeConeT(rows)] + [clarabel.PSDTriangleConeT(quadratic)] * 2
    objective = np.concatenate([np.zeros(m), np.full(nb, 1.0 / max(nb, 1)),
                                np.full(nd, DECREASE_WEIGHT / max(nd, 1))])
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.time_limit = max(0.1, deadline - time.monotonic())
    solution = clarabel.DefaultSolver(sparse.csc_matrix((len(objective),) * 2), objective, A,
                                      right, cones, settings).solve()
    if str(solution.status) not in ("Solved", "AlmostSolved"):
        return None
    x = np.array(solution.x)
    return x[:m], x[m + nb:]


def _local_cones(program, count: int):
    """Rows for Q - e I >= 0 and -(A^T Q + Q A) - e I >= 0 (for a map Q - A^T Q A - e I
    >= 0; e = LOCAL_EPS; PSD, Clarabel's scaled upper triangles), with Q the quadratic
    part of V in c's coordinates."""
    n = program.samples.jacobian.shape[0]
    A = program.samples.jacobian
    index = {tuple(e): k for k, e in enumerate(program.exponents.tolist())}

    def q(i: int, j: int) -> dict[int, float]:
        exponent = tuple(int(k == i) + int(k == j) for k in range(n))
        return {index[exponent]: 1.0 if i == j else 0.5}
    Q = [[q(i, j) for j in range(n)] for i in range(n)]
    lyapunov = (_step_lyapunov(Q, A) if program.samples.discrete else
                [[_sum([_scaled(Q[k][j], -A[k, i]) for k in range(n)]
                       + [_scaled(Q[i][k], -A[k, j]) for k in range(n)])
                  for j in range(n)] for i in range(n)])
    rows, right = [], []
    for matrix in (Q, lyapunov):
        for j in range(n):
            for i in range(j + 1):
                factor = 1.0 if i == j else math.sqrt(2)
                row = np.zeros(count)
                for variable, weight in matrix[i][j].items():
                    row[variable] -= factor * weight
                rows.append(row)
                right.append(-LOCAL_EPS if i == j else 0.0)
    from scipy import sparse
    return n, sparse.csr_matrix(np.array(rows)), np.array(right)


def _step_lyapunov(Q, A) -> list[list[dict[int, float]]]:
    """Q - A^T Q A, entry by entry (a map's decrease at the origin)."""
    n = len(Q)
    return [[_sum([Q[i][j]] + [_scaled(Q[k][l], -A[k, i] * A[l, j])
                                for k in range(n) for l in range(n)])
             for j in range(n)] for i in range(n)]


def _scaled(entry: dict[int, float], factor: float) -> dict[int, float]:
    return {k: v * factor for k, v in entry.items()}


def _sum(entries) -> dict[int, float]:
    total: dict[int, float] = {}
    for entry in entries:
        for k, v in entry.items():
            total[k] = total.get(k, 0.0) + v
    return total
