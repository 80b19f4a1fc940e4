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

from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.ir import traversal
from fossil_dsl.ir.spec import TimeDomain

SAMPLES = 4000  # points drawn uniformly in D's bounding box
STEPS = 4000  # integration steps (or iterations of a map)
CONVERGED = 1e-3  # of D's size: where a trajectory counts as at the origin


def region_report(result, found) -> dict:
    spec, states = result.plan.spec, result.plan.states
    low, high = (np.array([float(v) for v in side]) for side in spec.domain.bounding_box())
    points = np.random.default_rng(0).uniform(low, high, (SAMPLES, len(states)))
    env = state_env(states, points)
    in_domain = np.asarray(holds(spec.domain.contains_formula(states), env, SAMPLES), dtype=bool)
    values = np.asarray(evaluate(result.formulas["V"], env), dtype=np.float64)
    in_region = in_domain & (values <= float(found.level))
    size = float(np.max(high - low))
    converging = in_domain & converges(result, points, near=CONVERGED * size)
    box_volume = float(np.prod(high - low))
    basin = int(converging.sum())
    return {
        "method": "the largest level beta the kernel proves for V (bisection), with "
                  "every region-of-attraction obligation proved at it",
        "level": str(found.level), "level_upper_bound": float(found.upper),
        "levels_tried": [{"beta": str(b), "proved": ok} for b, ok in found.tried],
        "samples": SAMPLES, "samples_in_domain": int(in_domain.sum()),
        "share_of_domain": _share(in_region.sum(), in_domain.sum()),
        "volume": box_volume * float(in_region.mean()),
        "domain_volume": box_volume * float(in_domain.mean()),
        "simulated_basin_in_domain": basin,
        "basin_coverage": _share((in_region & converging).sum(), basin),
        "region_points_not_converging": int((in_region & ~converging).sum()),
        "simulation": f"{STEPS} steps of RK4 over 40 time units" if spec.time is
        TimeDomain.CONTINUOUS else f"{STEPS} iterations of the map",
    }


def _share(part, whole) -> float | None:
    return round(float(part) / float(whole), 4) if whole else None


def converges(result, points, steps: int = STEPS, horizon: float = 40.0,
              near: float = 1e-3) -> np.ndarray:
    """Where the closed loop's simulated trajectory ends within `near` of the origin:
    `steps` of RK4 over `horizon` time units, or `steps` iterations of a map."""
    closed = dict(result.controller)
    field = [traversal.substitute(f, closed) for f in result.plan.spec.dynamics]
    states = result.plan.states

    def step(x):
        env = state_env(states, x)
        return np.stack([np.broadcast_to(np.asarray(evaluate(f, env), dtype=np.float64),
                                         (len(x),)) for f in field], 1)

    x = points.copy()
    with np.errstate(all="ignore"):
        if result.plan.spec.time is TimeDomain.DISCRETE:
            for _ in range(steps):
                x = step(x)
        else:
            dt = horizon / steps
            for _ in range(steps):
                k1 = step(x)
                k2 = step(x + dt / 2 * k1)
                k3 = step(x + dt / 2 * k2)
                k4 = step(x + dt * k3)
                x = np.clip(x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4), -1e6, 1e6)
    return np.isfinite(x).all(1) & (np.linalg.norm(x, axis=1) < near)
