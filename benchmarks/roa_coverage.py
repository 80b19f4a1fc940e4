"""How much of the true region of attraction a certified region covers, measured apart
from the tool's own estimate (issue 25): on a 300 × 300 grid of D (2-state specs), each
point is simulated (RK4, step 0.005, 60 time units; a map: 3000 iterations) and counts as
in the basin if it ends within 1e-3 of the origin. Printed per result folder: the basin's
share of the grid, the certified region's, the share of the basin it covers, and the
number of its grid points that do not converge (0 for a sound certificate, up to the
simulation's accuracy).

    python benchmarks/roa_coverage.py RESULT_DIR...   (each written by `fossilc SPEC -o DIR`)
"""
from __future__ import annotations

import sys

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.ir import traversal
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.outputs.load import load_result

GRID = 300


def measure(folder: str) -> str:
    result = load_result(folder, judge_again=False)
    spec, states = result.plan.spec, result.plan.states
    low, high = (np.array([float(v) for v in side]) for side in spec.domain.bounding_box())
    axes = [np.linspace(low[i], high[i], GRID) for i in range(2)]
    points = np.stack([a.reshape(-1) for a in np.meshgrid(*axes, indexing="xy")], 1)
    env = state_env(states, points)
    in_domain = np.asarray(holds(spec.domain.contains_formula(states), env, len(points)),
                           dtype=bool)
    beta = float(result.levels["beta"])
    in_region = in_domain & (np.asarray(evaluate(result.formulas["V"], env)) <= beta)
    basin = in_domain & _converges(result, points)
    return (f"| {spec.name} | {basin.sum() / in_domain.sum():.3f} | "
            f"{in_region.sum() / in_domain.sum():.3f} | "
            f"{(in_region & basin).sum() / basin.sum():.3f} | {(in_region & ~basin).sum()} |")


def _converges(result, points) -> np.ndarray:
    field = [traversal.substitute(f, dict(result.controller)) for f in result.plan.spec.dynamics]
    states = result.plan.states

    def step(x):
        env = state_env(states, x)
        return np.stack([np.broadcast_to(np.asarray(evaluate(f, env), dtype=np.float64),
                                         (len(x),)) for f in field], 1)

    x = points.copy()
    with np.errstate(all="ignore"):
        if result.plan.spec.time is TimeDomain.DISCRETE:
            for _ in range(3000):
                x = step(x)
        else:
            dt = 0.005
            for _ in range(12000):
                k1 = step(x)
                k2 = step(x + dt / 2 * k1)
                k3 = step(x + dt / 2 * k2)
                k4 = step(x + dt * k3)
                x = np.clip(x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4), -1e6, 1e6)
    return np.isfinite(x).all(1) & (np.linalg.norm(x, axis=1) < 1e-3)


if __name__ == "__main__":
    print("| spec | basin / D | certified Ω / D | Ω covers of the basin | Ω points not converging |")
    print("|---|---|---|---|---|")
    for folder in sys.argv[1:]:
        print(measure(folder), flush=True)
