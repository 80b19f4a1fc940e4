"""How much of the true region of attraction a certified region covers, measured apart
from the tool's own estimate (issue 25): on a 300 × 300 grid of D (2-state specs), each
point is simulated (RK4, step 0.005, 60 time units; a map: 12000 iterations) and counts as
in the basin if it ends within 1e-3 of the origin. Printed per result folder: the basin's
share of the grid, the certified region's, the share of the basin it covers, and the
number of its grid points that do not converge (0 for a sound certificate, up to the
simulation's accuracy).

    python benchmarks/roa_coverage.py RESULT_DIR...   (each written by `fossilc SPEC -o DIR`)
"""
from __future__ import annotations

import sys

import numpy as np

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.outputs.load import load_result
from fossil_dsl.outputs.region import converges
from fossil_dsl.outputs.simulate import in_region

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
    inside = in_region(result, points)
    # longer and finer than the tool's own estimate: 60 time units, step 0.005
    basin = in_domain & converges(result, points, steps=12000, horizon=60.0, near=1e-3)
    return (f"| {spec.name} | {basin.sum() / in_domain.sum():.3f} | "
            f"{inside.sum() / in_domain.sum():.3f} | "
            f"{(inside & basin).sum() / basin.sum():.3f} | {(inside & ~basin).sum()} |")


if __name__ == "__main__":
    print("| spec | basin / D | certified Ω / D | Ω covers of the basin | Ω points not converging |")
    print("|---|---|---|---|---|")
    for folder in sys.argv[1:]:
        print(measure(folder), flush=True)
