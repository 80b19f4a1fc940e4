"""How large a certified region of attraction is (`synthesis { region: largest }`):
its level, its share of D and its volume (area in 2-D) by sampling, and how much of the
simulated basin of attraction within D it covers.

All numbers here are estimates from samples and simulation; the region itself,
Ω = {x in D : V(x) <= β}, is what the kernel proved. A sampled point of Ω whose simulated
trajectory does not converge is reported (it would mean the simulation is too short or
too coarse: the proof says every trajectory from Ω converges).
"""
from __future__ import annotations

import numpy as np

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.outputs.simulate import closed_loop, in_region, rk4_step

SAMPLES = 4000  # points drawn uniformly in D's bounding box
STEPS = 4000  # integration steps (or iterations of a map)
ESCAPE = 1e6  # a coordinate this large: the path has diverged
CONVERGED = 1e-3  # of D's size: where a trajectory counts as at the origin


def region_report(result, found) -> dict:
    spec, states = result.plan.spec, result.plan.states
    low, high = (np.array([float(v) for v in side]) for side in spec.domain.bounding_box())
    points = np.random.default_rng(0).uniform(low, high, (SAMPLES, len(states)))
    in_domain = np.asarray(holds(spec.domain.contains_formula(states),
                                 state_env(states, points), SAMPLES), dtype=bool)
    inside = in_region(result, points)
    size = float(np.max(high - low))
    converging = in_domain & converges(result, points, near=CONVERGED * size)
    box_volume = float(np.prod(high - low))
    basin = int(converging.sum())
    return {
        "method": "the largest level beta the kernel proves for V (bisection), with "
                  "every region-of-attraction obligation proved at it",
        "level": str(found.level), "level_upper_bound": float(found.upper),
        "level_failing_sample": None if found.failing is None else float(found.failing),
        "levels_tried": [{"beta": str(b), "proved": ok} for b, ok in found.tried],
        "samples": SAMPLES, "samples_in_domain": int(in_domain.sum()),
        "share_of_domain": _share(inside.sum(), in_domain.sum()),
        "volume": box_volume * float(inside.mean()),
        "domain_volume": box_volume * float(in_domain.mean()),
        "simulated_basin_in_domain": basin,
        "basin_coverage": _share((inside & converging).sum(), basin),
        "region_points_not_converging": int((inside & ~converging).sum()),
        "simulation": f"{STEPS} steps of RK4 over 40 time units" if spec.time is
        TimeDomain.CONTINUOUS else f"{STEPS} iterations of the map",
    }


def _share(part, whole) -> float | None:
    return round(float(part) / float(whole), 4) if whole else None


def converges(result, points, steps: int = STEPS, horizon: float = 40.0,
              near: float = 1e-3) -> np.ndarray:
    """Where the closed loop's simulated trajectory ends within `near` of the origin:
    `steps` of RK4 over `horizon` time units, or `steps` iterations of a map."""
    field, x = closed_loop(result), points.copy()
    discrete = result.plan.spec.time is TimeDomain.DISCRETE
    escaped = np.zeros(len(points), bool)
    for _ in range(steps):
        with np.errstate(all="ignore"):
            x = field(x) if discrete else rk4_step(field, x, horizon / steps)
        # a path past the bound has diverged: it is marked for good, since held at the
        # bound it could drift back (x1' = -x1 + 2 x1^2 x2 with x2 -> 0 did)
        escaped |= ~np.isfinite(x).all(1) | (np.abs(x) > ESCAPE).any(1)
        x[escaped] = ESCAPE
    return ~escaped & (np.linalg.norm(x, axis=1) < near)
