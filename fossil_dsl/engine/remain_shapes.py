"""Reach-avoid-remain's B from its own ellipsoid: the one between G and F that the
linearised loop keeps (ellipsoid_seed.py with G and F in place of I and D), and V from
the Lyapunov matrices of the same gain's closed loop.

V must hold I inside S, B must lie between G and F: one shape for both asks a round
ellipsoid of a loop whose Lyapunov matrices may be long and thin (probe74/ax33, a
sampled chain: no LQR shape has a level between G's ball of 0.2 and F's of 0.4, while
the program finds an invariant ellipsoid there at contraction 0.99). Nothing here is
trusted: both functions are checked on samples, then proved like any candidate.
"""
from __future__ import annotations

import numpy as np

from fossil_dsl.engine.reach_shapes import REMAIN_FORM
from fossil_dsl.ir.spec import TimeDomain


def remain_shapes(plan, A: np.ndarray, B: np.ndarray, operating: np.ndarray, weightings):
    """(controller, gain, P for V, P for B) for each ellipsoid between G and F: first
    that ellipsoid for V too, then the gain's Lyapunov matrices for each of
    `weightings` (the decreases Q asked)."""
    from fossil_dsl.engine.ellipsoid_seed import ellipsoids
    from fossil_dsl.engine.linear import is_stable, lyapunov_matrix
    from fossil_dsl.engine.quadratic_shapes import exact_controller
    spec = plan.spec
    if plan.certificate.form != REMAIN_FORM:
        return
    discrete = spec.time is TimeDomain.DISCRETE
    inputs = B if spec.inputs else np.zeros((len(A), 0))
    between = (spec.property.role("goal"), spec.property.role("final"))
    for P_B, K in ellipsoids(A, inputs, spec, discrete, between=between):
        controller, gain = exact_controller(spec, K, operating, plan.options.digits) \
            if spec.inputs else ({}, None)
        closed = A if gain is None else A + B @ gain
        yield controller, gain, P_B, P_B
        if is_stable(closed, discrete):
            for Q in weightings:
                yield controller, gain, lyapunov_matrix(closed, discrete, Q), P_B
