"""`synthesis { region: largest }`: once a region-of-attraction certificate is proved,
the largest level β for which the kernel proves every obligation again, so that
Ω = {x in D : V(x) <= β} is as large as this V allows.

β is searched between the proved level and the smallest sampled value of V on the
boundary of D (no larger β can satisfy V > β there): first just under that upper end
(enough if proved), then by bisection. Each candidate is judged by
the kernel from scratch (the `judge` the caller passes); the answer is the last β it
certified, with that verdict. Nothing here proves anything.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Callable

import numpy as np

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.sampling import sample
from fossil_dsl.ir.sets import Boundary
from fossil_dsl.kernel import Claim, Verdict

STEPS = 8  # bisection steps at most
NEAR_TOP = Fraction(99, 100)  # of the upper end: tried first, and enough if proved
SAMPLES = 4000  # points of ∂D for the upper end
DIGITS = 4  # significant digits of a candidate β (short rationals, quick queries)


@dataclass(frozen=True)
class LargestLevel:
    level: Fraction
    verdict: Verdict
    tried: tuple[tuple[Fraction, bool], ...]  # each candidate β and whether it was proved
    upper: Fraction  # the smallest sampled V on ∂D: no larger β can hold


def largest_level(claim: Claim, verdict: Verdict, judge: Callable[[Claim], Verdict],
                  deadline: float, seed: int = 0) -> LargestLevel:
    """The largest β proved, starting from the claim's (proved) one."""
    low = claim.levels["beta"]
    high = upper = _upper(claim, seed)
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
    return LargestLevel(low, verdict, tuple(tried), upper)


def _upper(claim: Claim, seed: int) -> Fraction:
    spec = claim.spec
    points = sample(Boundary(spec.domain), spec.states, SAMPLES, np.random.default_rng(seed),
                    spec.domain.bounding_box())
    values = np.asarray(evaluate(claim.functions["V"], state_env(spec.states, points)),
                        dtype=np.float64)
    return Fraction(float(np.min(values)))


def _short(value: Fraction, low: Fraction, high: Fraction) -> Fraction:
    """A rational with few digits strictly between low and high, near value."""
    for digits in range(DIGITS, 17):
        candidate = Fraction(f"{float(value):.{digits}g}")
        if low < candidate < high:
            return candidate
    return value
