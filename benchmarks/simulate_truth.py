"""Does a spec's property look true? Simulate trajectories from sampled initial states.

    python benchmarks/simulate_truth.py specs/literature/*.fsl

For dev suites of true properties: a spec whose simulation shows a violation is not a
fair test of the tool. Evidence, not proof: RK4 (continuous time, dt = 0.01) or the map
itself, from 2000 random initial states of I (of D for `prove stable`). With inputs, the
closed loop uses the LQR gain of the linearisation (engine/linear.py): a property that
holds for it is one a controller can achieve.
"""
from __future__ import annotations

import sys

import numpy as np
import sympy
import torch

import fossil_dsl
from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.engine.linear import local_certificate
from fossil_dsl.engine.sampling import sample
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.ir.symbolic import to_sympy

SAMPLES, DT, SECONDS, STEPS = 2000, 0.01, 60.0, 2000
CONVERGED = 1e-2


def closed_loop(spec):
    symbols = {s: sympy.Symbol(s) for s in (*spec.states, *spec.inputs)}
    field = [to_sympy(f, symbols) for f in spec.dynamics]
    if spec.inputs:
        found = local_certificate(spec, controlled=True)
        if found is None:
            return None
        gain = found[1]
        controls = {symbols[u]: -sum(float(gain[i, j]) * symbols[s]
                                     for j, s in enumerate(spec.states))
                    for i, u in enumerate(spec.inputs)}
        field = [f.subs(controls) for f in field]
    function = sympy.lambdify([symbols[s] for s in spec.states], field, "numpy")
    return lambda x: np.stack([np.broadcast_to(np.asarray(v, dtype=float), x[:, 0].shape)
                               for v in function(*x.T)], axis=1)


def member(region, states, points: np.ndarray) -> np.ndarray:
    if region is None:
        return np.zeros(len(points), dtype=bool)
    env = state_env(states, torch.as_tensor(points))
    return holds(region.contains_formula(states), env, len(points)).numpy()


def trajectories(spec, start: np.ndarray, alive: np.ndarray):
    """The states after each step; a trajectory that has left D (alive False) is
    frozen at the origin, where it can neither blow up nor count."""
    field = closed_loop(spec)
    if field is None:
        raise ValueError("the linearisation is not stabilisable")
    x = start.copy()
    discrete = spec.time is TimeDomain.DISCRETE
    steps = STEPS if discrete else int(SECONDS / DT)
    for _ in range(steps):
        if discrete:
            x = field(x)
        else:
            k1 = field(x)
            k2 = field(x + DT / 2 * k1)
            k3 = field(x + DT / 2 * k2)
            k4 = field(x + DT * k3)
            x = x + DT / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        x[~alive] = 0.0
        yield x


def verdict(spec) -> str:
    states, prop = spec.states, spec.property
    generator = torch.Generator().manual_seed(0)
    start_set = prop.role("initial") or spec.domain
    box = spec.domain.bounding_box()
    start = sample(start_set, states, SAMPLES, generator, box).numpy()
    unsafe, goal = prop.role("unsafe"), prop.role("goal") or prop.role("final")
    safe = prop.role("safe") or spec.domain
    stable = prop.form in ("stability", "region of attraction", "stable while avoid")
    # RAR: once in G, in F for ever; RSWA: in F at the end
    remain = prop.role("final") if prop.form == "reach-avoid-remain" else None
    settle = prop.role("final") if prop.form == "reach and stay while avoid" else None
    alive = np.ones(len(start), dtype=bool)  # inside D (or S) so far
    reached = member(goal, states, start)
    for x in trajectories(spec, start, alive):
        if not np.isfinite(x[alive]).all():
            return "violated: a trajectory blows up inside the domain"
        # Before `alive` is updated: for safety, S is the complement of U, so a state that
        # enters U also leaves S and would otherwise be frozen before it counts.
        if (member(unsafe, states, x) & alive & ~reached).any():
            return "violated: a trajectory enters the unsafe set"
        if remain is not None and (reached & ~member(remain, states, x)).any():
            return "violated: a trajectory leaves F after reaching G"
        alive &= member(safe, states, x)
        if stable and not alive.all():
            return "violated: a trajectory leaves the domain"
        reached |= member(goal, states, x) & alive
    if stable and not (np.linalg.norm(x, axis=1) < CONVERGED).all():
        return f"violated: {int((np.linalg.norm(x, axis=1) >= CONVERGED).sum())} " \
               "trajectories do not converge to the origin"
    if settle is not None and not member(settle, states, x).all():
        return "violated: a trajectory is outside F at the end"
    if goal is not None and not reached.all():
        return f"violated: {int((~reached).sum())} trajectories never reach the goal"
    return "looks true"


def main(paths) -> int:
    bad = 0
    for path in paths:
        spec = fossil_dsl.load(path)
        try:
            found = verdict(spec)
        except ValueError as error:
            found = f"no evidence: {error}"  # no LQR gain to simulate with
        bad += not found.startswith("looks")
        print(f"{spec.name}: {found}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
