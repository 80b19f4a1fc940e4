"""A barrier by sum-of-squares programming for safety with inputs: the controller is
fixed beforehand to an LQR gain of the linearisation (rounded as the verifier will see
it; u = -K x + u* round the operating input u*), and the barrier program
(sos_barrier.py) is solved for the closed loop, first with B > 0 on D's faces as well
(so that the kernel can prove "never leaves D", the guarantee without D's qualifier),
then without. The first B found is handed on with its controller; nothing here is
trusted: both are proved like any candidate and controller.

Where I and U are boxes close together no ellipsoid fits between them (a 4-room heater,
I = [-1, 1]^4 inside U's complement [-1.5, 1.5]^4: every ellipsoid holding I's corners
reaches 2 along some axis), so a learned quadratic B cannot exist; the program's
quartic B can (the sum of x_i^4 bounds the max norm within 4^(1/4)).
"""
from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import numpy as np

from fossil_dsl.engine.sos_barrier import DEGREES, barrier
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.plan.compile import Plan, default_synthesis

CONTROLLERS = 2  # LQR weightings tried, at most
# B's margin, at least: learning certifies most specs with inputs in 3-5 s, and B's of
# margin near 1e-7 were refuted or took 20 s to prove (barrierbench bb35, bb43,
# probe44/y13); av37's B has margin 0.1
MIN_MARGIN = 1e-4


@dataclass(frozen=True)
class ControlledBarrier:
    formula: E.Expr  # B, exact
    function: str
    degree: int
    margin: float
    condition: str
    seconds: float
    controller: dict  # input -> exact formula
    gain: np.ndarray  # -K, rounded
    operating: np.ndarray
    stand_in: int = 0

    def describe(self) -> str:
        return (f"sum-of-squares programming (Clarabel): B of degree {self.degree} for an "
                f"LQR gain of the linearisation, {self.condition}, {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    """Safety with inputs, the default templates and the default (linear) controller."""
    return (plan.certificate.form == "safety" and bool(plan.spec.inputs)
            and plan.controller is not None and default_synthesis(plan))


def search(plan: Plan, deadline: float, degrees=None) -> ControlledBarrier | None:
    """The first B (of twice one of `degrees`) found for a closed loop, with its
    controller; None where there is none by the deadline."""
    from fossil_dsl.engine.linear import operating_point  # imports torch
    from fossil_dsl.engine.quadratic_shapes import lqr_controllers
    started = time.monotonic()
    spec = plan.spec
    operating = operating_point(spec)
    if operating is None:
        return None
    rng = np.random.default_rng(plan.options.seed)
    loops = lqr_controllers(plan, operating, rng)
    for _, (controller, gain) in zip(range(CONTROLLERS), loops):
        if time.monotonic() > deadline:
            return None
        closed = [traversal.substitute(f, controller) for f in spec.dynamics]
        found = barrier(plan, deadline, closed, MIN_MARGIN, True, degrees) \
            or barrier(plan, deadline, closed, MIN_MARGIN, False, degrees)
        if found is not None:
            return ControlledBarrier(found.formula, "B", found.degree, found.margin,
                                     found.condition, time.monotonic() - started,
                                     controller, gain, operating)
    return None


# quadratic B's take milliseconds; quartic and sextic ones up to 30 s (probe44/y13: 28 s),
# where the learning loop's first iteration is often the proof: tried in between
quadratic = functools.partial(search, degrees=DEGREES[:1])
higher = functools.partial(search, degrees=DEGREES[1:])
