"""`synthesis { region: largest }`: once a region-of-attraction certificate is proved,
the largest level β for which the kernel proves every obligation again, so that
Ω = {x in D : V(x) <= β} is as large as this V allows.

β is searched between the proved level and the smallest sampled value of V on the
boundary of D (no larger β can satisfy V > β there), or, lower, the smallest value of V
at a sampled point of D where a condition fails in floating point (V not positive, not
decreasing, or, for a map, a step leaving D): such a level would only cost the kernel a
timeout. First just under that upper end (enough if proved), then by bisection. Each
candidate is judged by the kernel from scratch (the `judge` the caller passes); the answer is the last β it
certified, with that verdict. Nothing here proves anything.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Callable

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.engine.sampling import sample
from fossil_dsl.engine.trajectories import column, numeric_field
from fossil_dsl.ir import traversal
from fossil_dsl.ir.calculus import lie_derivative
from fossil_dsl.ir.sets import Boundary
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.kernel import Claim, Verdict

STEPS = 8  # bisection steps at most
NEAR_TOP = Fraction(99, 100)  # of the upper end: tried first, and enough if proved
SAMPLES = 4000  # points of ∂D for the upper end
DOMAIN_SAMPLES = 20000  # points of D where the conditions are evaluated
NEAR_ORIGIN = 1e-3  # of D's size: closer points are left to the kernel's lemma
DIGITS = 4  # significant digits of a candidate β (short rationals, quick queries)


@dataclass(frozen=True)
class LargestLevel:
    level: Fraction
    verdict: Verdict
    tried: tuple[tuple[Fraction, bool], ...]  # each candidate β and whether it was proved
    upper: Fraction  # the smallest sampled V on ∂D: no larger β can hold
    failing: Fraction | None = None  # the smallest V where a sampled point fails


def largest_level(claim: Claim, verdict: Verdict, judge: Callable[[Claim], Verdict],
                  deadline: float, seed: int = 0) -> LargestLevel:
    """The largest β proved, starting from the claim's (proved) one."""
    low = claim.levels["beta"]
    upper, failing = _upper(claim, seed), _failing_level(claim, seed)
    high = upper if failing is None else min(upper, failing)
    tried = []
    for step in range(STEPS + 1):
        if high <= low or time.monotonic() > deadline:
            break
        # a V shaped to the basin is often proved just under the upper end: one try there
        middle = _short(NEAR_TOP * high if step == 0 else (low + high) / 2, low, high)
        judged = judge(replace(claim, levels={**claim.levels, "beta": middle}))
        tried.append((middle, judged.certified))
        if judged.certified:
            low, verdict = middle, judged
        else:
            high = middle
        if high - low <= Fraction(1, 1000) * high or (step == 0 and judged.certified):
            break
    return LargestLevel(low, verdict, tuple(tried), upper, failing)


def _upper(claim: Claim, seed: int) -> Fraction:
    spec = claim.spec
    points = sample(Boundary(spec.domain), spec.states, SAMPLES, np.random.default_rng(seed),
                    spec.domain.bounding_box())
    values = np.asarray(evaluate(claim.functions["V"], state_env(spec.states, points)),
                        dtype=np.float64)
    return Fraction(float(np.min(values)))


def _failing_level(claim: Claim, seed: int) -> Fraction | None:
    """The smallest V at a sampled point of D (away from the origin) where V <= 0, V does
    not decrease, or a step of the map leaves D; None if there is none."""
    spec, states = claim.spec, claim.spec.states
    low, high = (np.array([float(v) for v in side]) for side in spec.domain.bounding_box())
    points = np.random.default_rng(seed).uniform(low, high, (DOMAIN_SAMPLES, len(states)))
    size = float(np.max(high - low))
    points = points[_inside(spec.domain, states, points)
                    & (np.linalg.norm(points, axis=1) > NEAR_ORIGIN * size)]
    field = [traversal.substitute(f, dict(claim.controller)) for f in spec.dynamics]
    V = claim.functions["V"]
    with np.errstate(all="ignore"):
        value = _values(V, states, points)
        if spec.time is TimeDomain.DISCRETE:
            image = numeric_field(field, states)(points)
            fails = ~_inside(spec.domain, states, image)
            change = np.where(fails, 0.0, _values(V, states, np.nan_to_num(image)) - value)
        else:
            change = _values(lie_derivative(V, states, field), states, points)
        bad = (~np.isfinite(change) | (change >= 0) | (value <= 0)) & np.isfinite(value)
    return Fraction(float(np.min(value[bad]))) if bad.any() else None


def _values(expr, states, points) -> np.ndarray:
    return column(evaluate(expr, state_env(states, points)), len(points))


def _inside(region, states, points) -> np.ndarray:
    return np.asarray(holds(region.contains_formula(states), state_env(states, points),
                            len(points)), dtype=bool)


def _short(value: Fraction, low: Fraction, high: Fraction) -> Fraction:
    """A rational with few digits strictly between low and high, near value."""
    for digits in range(DIGITS, 17):
        candidate = Fraction(f"{float(value):.{digits}g}")
        if low < candidate < high:
            return candidate
    return value
