"""A starting point for safety barriers from a linearisation: B = (x - c)^T P (x - c) - d
round an equilibrium c of the closed loop (of the system, without inputs).

Near a stable equilibrium, the level sets of a Lyapunov function x^T P x of the
linearisation are crossed inwards only, so B meets the flow condition on its zero level
where the linear part dominates; B <= 0 on I and B > 0 on U where d lies between the
values of the quadratic there. Where the zero level also stays inside the domain (B > 0
on the sampled boundary of D), the kernel can prove the stronger guarantee that no
trajectory from I leaves D; such seeds are preferred.

The equilibrium is the origin where it is one, and, with inputs, the middle of I, held
by the controller's bias (u = u* - K (x - c) with f(c, u*) = 0); without inputs, the
equilibrium Newton's method finds from the middle of I. An ellipsoid round the origin
cannot hold an I that lies away from it without crossing a domain drawn round the sets.
Nothing here is trusted: every seed is verified like any candidate.
"""
from __future__ import annotations

import functools

import numpy as np

from fossil_dsl.engine.linear import (as_array, equilibrium, holds_a_quadratic, is_linear,
                                      operating_point, set_linear, set_quadratic)
from fossil_dsl.engine.quadratic_shapes import (SHAPES, floor_outside, initial_middle, lqr_gains,
                                               separations,
                                               set_ceiling, set_floor)
from fossil_dsl.engine.sampling import sample
from fossil_dsl.ir.sets import Boundary
from fossil_dsl.ir.spec import TimeDomain

BOUNDARY_SAMPLES = 1000  # of the boundary of D, to tell which seeds stay inside D
DECREASE_MARGINS = 4.0  # the seed's linear decrease on its zero level: this many margins


def candidates(plan, networks: dict, controller, samples: dict):
    """(preferred, set_seed) pairs, lazily: first the preferred ones (whose zero level
    the sampled boundary of D lies outside of), then the others; within each, the plain
    Lyapunov matrices before the separating ones, one LQR weighting at a time
    (identities first), the origin before the middle of I. None where no seed applies."""
    network = networks.get("B")
    if plan.spec.property.form != "safety" or network is None \
            or not holds_a_quadratic(network, len(plan.states)):
        return
    if controller is not None and not is_linear(controller, len(plan.controller.inputs)):
        return
    inside, unsafe = samples.get("initial"), samples.get("unsafe")
    if inside is None or unsafe is None:
        return
    inside, unsafe = as_array(inside), as_array(unsafe)
    boundary = _domain_boundary(plan)
    fenced = unsafe if boundary is None else np.concatenate([unsafe, boundary])
    discrete = plan.spec.time is TimeDomain.DISCRETE
    loops = sorted(_closed_loops(plan, network, controller, inside), key=lambda loop: loop[0])
    domain, unsafe_set = plan.spec.domain, plan.spec.property.role("unsafe")
    initial_set = plan.spec.property.role("initial")
    passes = ((fenced, domain, True), (unsafe, None, False)) if boundary is not None \
        else ((unsafe, None, True),)
    for outside, fence, preferred in passes:
        for shape in SHAPES:  # the plain Lyapunov matrix's surer decrease first
            for weighting, centre, operating, A, K in loops:
                floor = functools.partial(_floor, fence=fence, unsafe=unsafe_set, centre=centre)
                ceiling = functools.partial(set_ceiling, region=initial_set, centre=centre)
                for _, P, level in separations(A, discrete, inside - centre,
                                               outside - centre, (shape,), floor, ceiling):
                    scale = _scale(P, A, discrete, level, plan.options.margin)
                    yield preferred, _setter(network, controller, scale * P, scale * level,
                                             centre, K, operating)


def _floor(P, fence, unsafe, centre):
    """A lower bound of (x - c)^T P (x - c) on U (and on the boundary of D where the seed
    must stay inside it), or None."""
    if fence is None:
        return set_floor(P, unsafe, centre) if unsafe is not None else None
    return floor_outside(P, fence, unsafe, centre)


def _scale(P: np.ndarray, A: np.ndarray, discrete: bool, level: float, margin: float) -> float:
    """s such that the linearised change of s x^T P x on its level set x^T P x = level
    is at least DECREASE_MARGINS times the learner's margin (1 where it is already).
    P's scale is arbitrary, and a slow closed loop's P (largest eigenvalue 1) decreases
    by less than the margin that the learner asks of the flow condition."""
    change = A.T @ P @ A - P if discrete else A.T @ P + P @ A
    slowest = -np.linalg.eigvalsh((change + change.T) / 2)[-1]
    # on the level set |x|^2 >= level / (P's largest eigenvalue)
    decrease = slowest * level / np.linalg.eigvalsh(P)[-1]
    return max(1.0, DECREASE_MARGINS * margin / decrease) if decrease > 0 else 1.0


def _closed_loops(plan, network, controller, inside):
    """(weighting index, c, u*, A, K): the linearisation at each equilibrium c closed by
    the LQR gain K of each weighting."""
    for centre, operating in _equilibria(plan, network, controller, inside):
        rng = np.random.default_rng(plan.options.seed)
        gains = lqr_gains(plan.spec, controller is not None, operating, rng, centre)
        for index, (A, K) in enumerate(gains):
            yield index, centre, operating, A, K


def _setter(network, controller, P, level, centre, K, operating):
    def set_seed() -> None:
        set_quadratic(network, P, level, centre if centre.any() else None)
        if controller is not None:
            set_linear(controller, -K, operating + K @ centre)
    return set_seed


def _equilibria(plan, network, controller, inside):
    """(c, u*) for the origin and for the middle of I (with inputs: made equilibria by
    u*; without: the equilibria Newton's method reaches from them), each once."""
    spec = plan.spec
    n = len(plan.states)
    seen = []
    middle = initial_middle(spec, inside)
    for start in [np.zeros(n)] + ([] if middle is None else [middle]):
        if controller is not None:
            centre, operating = start, operating_point(spec, start)
        else:
            centre, operating = equilibrium(spec, start), np.zeros(len(spec.inputs))
        if centre is None or operating is None:
            continue
        if centre.any() and network.linears[0].bias is None:
            continue
        if controller is not None and controller.zero_at_origin \
                and (centre.any() or operating.any()):
            continue
        if any(np.allclose(centre, other) for other in seen):
            continue
        seen.append(centre)
        yield centre, operating


def _domain_boundary(plan) -> np.ndarray | None:
    domain = plan.spec.domain
    if domain.bounding_box() is None:
        return None
    rng = np.random.default_rng(plan.options.seed)
    points = sample(Boundary(domain), plan.states, BOUNDARY_SAMPLES, rng)
    return points if len(points) else None
