"""A barrier round a repelling equilibrium in U, for safety in continuous time.

Where U holds an equilibrium c whose linearisation A has every eigenvalue in the right
half plane (an unstable focus or node, which orbits leave), a Lyapunov matrix P of the
time-reversed linearisation (-A) makes (x - c)^T P (x - c) grow along the flow near c, so
B = d - (x - c)^T P (x - c) decreases there; with d between the quadratic's values on U
and on I (sampled), B > 0 on U and B <= 0 on I. The Hopf normal form with I an annulus
round its unstable origin and U the hole (probe52/m03) has no other candidate: an
ellipsoid round a stable point that holds I holds the hole, and the learner's banded
flow condition sees B's small values at c, where dB/dt = 0, as violations.

The formula is rounded to rationals and proved like any candidate: nothing is trusted.
"""
from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.linear import equilibrium, jacobians
from fossil_dsl.engine.quadratic_shapes import separations, set_ceiling
from fossil_dsl.engine.sampling import sample
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.sets import Intersection
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis
from fossil_dsl.solvers.gram_rounding import decimal

SAMPLES = 1000  # of I and of U within D
DECIMALS = 6  # kept of P's entries, d and c


@dataclass(frozen=True)
class RepellingFinding:
    formula: E.Expr  # B, exact
    centre: np.ndarray
    seconds: float

    def describe(self) -> str:
        where = ", ".join(f"{v:g}" for v in self.centre)
        return (f"a barrier round the repelling equilibrium ({where}) from the reversed "
                f"linearisation's Lyapunov matrix, {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    spec = plan.spec
    return (plan.certificate.form == "safety" and spec.time is TimeDomain.CONTINUOUS
            and not spec.inputs and default_synthesis(plan))


def candidates(plan: Plan):
    """Findings, the plain Lyapunov matrix's first, for each repelling equilibrium."""
    started = time.monotonic()
    rng = np.random.default_rng(plan.options.seed)
    spec, states = plan.spec, plan.states
    box = spec.domain.bounding_box()
    initial = _points(spec.property.role("initial"), states, rng, box)
    unsafe_set = Intersection(spec.property.role("unsafe"), spec.domain)
    unsafe = _points(unsafe_set, states, rng, box)
    if not len(initial) or not len(unsafe):
        return
    for centre in _equilibria(spec, unsafe):
        found = jacobians(spec, None, centre)
        if found is None or np.linalg.eigvals(found[0]).real.min() <= 0:
            continue
        ceiling = functools.partial(set_ceiling, region=spec.property.role("unsafe"),
                                    centre=centre)
        for _, matrix, level in separations(-found[0], False, unsafe - centre,
                                            initial - centre, ceiling=ceiling):
            yield RepellingFinding(_formula(matrix, level, centre, states), centre,
                                   time.monotonic() - started)


def _points(region, states, rng, box) -> np.ndarray:
    try:
        return np.asarray(sample(region, states, SAMPLES, rng, box), dtype=float)
    except ValueError:  # no box to sample in
        return np.zeros((0, len(states)))


def _equilibria(spec, unsafe: np.ndarray):
    """The equilibria Newton's method reaches from the origin and from U's samples'
    mean, each once."""
    seen = []
    for start in (np.zeros(len(spec.states)), unsafe.mean(axis=0)):
        centre = equilibrium(spec, start)
        if centre is not None and not any(np.allclose(centre, c) for c in seen):
            seen.append(centre)
            yield np.round(centre, DECIMALS)


def _formula(matrix: np.ndarray, level: float, centre: np.ndarray, states) -> E.Expr:
    """d - (x - c)^T P (x - c), with P scaled to largest entry 1 and every number rounded."""
    scale = np.abs(matrix).max()
    n = len(states)
    shifted = [P.add({tuple(int(k == i) for k in range(n)): Fraction(1)},
                     P.constant(-decimal(centre[i], DECIMALS), n)) for i in range(n)]
    terms = [P.constant(decimal(level / scale, DECIMALS), n)]
    for i in range(n):
        for j in range(n):
            weight = decimal(matrix[i, j] / scale, DECIMALS)
            if weight:
                terms.append(P.scale(P.multiply(shifted[i], shifted[j]), -weight))
    return P.to_expr(P.add(*terms), states)
