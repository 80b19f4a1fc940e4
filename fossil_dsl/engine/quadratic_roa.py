"""A region of attraction from the linearisation, the textbook way: V = x^T P x with P
from the Lyapunov equation of the linearised (with inputs, LQR-closed) system, and β
just over V's largest value on I, the smallest sublevel set that holds I: the smaller
Ω, the fewer states where dV/dt < 0 must hold. A (P, β) is a candidate where Ω lies in
D (worked out for a box or ball; failing that, for a box D, where the field points into
D on its faces: the kernel's variant) and V decreases at thousands of samples of Ω and
its shell {V = β}; the decrease asked of P is Q = I, then random diagonal weights.
The attempt is for `from I: stable` (no `region: largest`, which shapes V to the
simulated basin) and `from I: stable and always not U`, with B = V - β where Ω misses U
(Ω cannot be left, so {B <= 0} cannot either); for reach, RWA, RSWA and RAR, V = k (x^T P
x - β) falling by 10 γ at the samples (RSWA's level just inside F; RAR's B a sublevel set
just holding G, inside F, of the same quadratic or of its own: reach_shapes.py). A
learner whose level is halfway between I and ∂D, or whose margin is large against a
small V, misses such a pair (probe53/n01, an excitable neuron: the Lyapunov
equation's V holds at 1.05 times its largest value on I, fails at the halfway level).
Nothing here is trusted: V and β are proved like any candidate.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.ellipse_checks import (LEVEL_CUSHION, decreases, floats, level_between,
                                              quadratic)
from fossil_dsl.engine.reach_shapes import REMAIN_FORM, STAY_FORM, reach_formulas
from fossil_dsl.engine.remain_shapes import remain_shapes
from fossil_dsl.engine.sampling import sample
from fossil_dsl.engine.trajectories import numeric_field
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.sets import Intersection
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis

WEIGHTINGS = 6  # decreases Q asked of P for each gain: I, then random diagonal ones
WEIGHT_SPREAD = 1.0  # their entries 10^u, u uniform in [-spread, spread]
SIGNIFICANT = 6  # digits kept of P's entries
# the ellipsoid asked to decay for the Jacobians this far towards each face of D, too
# (after the linearisation's own): where the nonlinearity is strong on the ellipsoid
VERTEX_SHARE = 0.5
UNSAFE_SAMPLES = 2000  # of U within D (stable while avoid): V > β there
# stable while avoid takes B = V - β: Ω cannot be left, so it is a barrier where it misses U
FORMS = ("region of attraction", "stable while avoid")
# and reach (while avoid) takes V = k (x^T P x - β): Ω lies in S, and outside G (round the
# origin) V falls by at least γ once k is large enough
# and RAR's B = x^T P x - b: b just over its largest value on G, {B <= 0} inside F; RSWA
# V as for reach with F for G, β just inside F (reach_shapes.py)
REACH_FORMS = ("reach while avoid", "reach", REMAIN_FORM, STAY_FORM)


@dataclass(frozen=True)
class QuadraticFinding:
    formulas: dict  # "V" -> x^T P x, exact
    controller: dict  # input -> exact formula (empty without inputs)
    gain: np.ndarray | None
    operating: np.ndarray
    levels: dict  # "beta" -> Fraction
    seconds: float
    reaches_boundary: bool = False  # Ω meets ∂D: for the kernel's variant (inward_rules.py)

    def describe(self) -> str:
        control = " and a linear controller" if self.controller else ""
        return (f"the linearisation's quadratic V{control} on its smallest sublevel set "
                f"holding I, {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    return plan.certificate.form in FORMS and _default(plan)


def reaches(plan: Plan) -> bool:
    """For reach and RWA: tried after the reach program, which is quicker to a proof
    where it finds V (two quadratic candidates refuted first cost specs/discrete/d08 10 s)."""
    return plan.certificate.form in REACH_FORMS and _default(plan)


def _default(plan: Plan) -> bool:
    return (default_synthesis(plan) and not plan.options.largest_region
            and plan.spec.domain.bounding_box() is not None)


def candidates(plan: Plan, deadline: float):
    """QuadraticFindings that pass the sampled checks, in the order found."""
    from fossil_dsl.engine.linear import jacobians, operating_point  # imports torch
    started = time.monotonic()
    spec = plan.spec
    operating = operating_point(spec) if spec.inputs else np.zeros(0)
    found = None if operating is None else jacobians(spec, operating)
    if found is None:
        return
    rng = np.random.default_rng(plan.options.seed)
    discrete = spec.time is TimeDomain.DISCRETE
    closed_loop, field = None, None
    deferred, yielded = [], False  # Ω reaching ∂D: only where no Ω inside D passes
    for controller, gain, P, remain in _shapes(plan, *found, operating, rng):
        if time.monotonic() > deadline:
            break
        if controller is not closed_loop:  # (the weightings of one gain share it)
            closed_loop, field = controller, numeric_field(
                [traversal.substitute(f, controller) for f in spec.dynamics], plan.states)
        shape = None if P is None else _exact_shape(P)
        level, reaching = (None, False) if shape is None else _level(plan, shape)
        if level is None or not decreases(plan, field, shape, level, discrete, rng, reaching) \
                or not _misses_unsafe(plan, shape, level, rng):
            continue
        if plan.certificate.form in REACH_FORMS:
            found = reach_formulas(plan, field, shape, level, discrete, rng,
                                   None if remain is None else _exact_shape(remain))
            if found is not None:
                yielded = True
                yield QuadraticFinding(found[0], controller, gain, operating, found[1],
                                       time.monotonic() - started)
            continue
        V = quadratic(shape, plan.states)
        formulas = {"V": V} if plan.certificate.form == FORMS[0] else \
            {"V": V, "B": E.add(V, E.Num(-level))}
        finding = QuadraticFinding(formulas, controller, gain, operating, {"beta": level},
                                   time.monotonic() - started, reaching)
        if reaching:
            deferred.append(finding)
            continue
        yielded = True
        yield finding
    if not yielded:
        yield from deferred


def _shapes(plan: Plan, A: np.ndarray, B: np.ndarray, operating: np.ndarray, rng):
    """(controller, its gain, P, RAR's own P for B or None) in turn: the Lyapunov
    matrices of the first LQR gain's closed loop (identity weights), the ellipsoid
    between I and D that the linearisation keeps (ellipsoid_seed.py; where the LQR
    ellipsoids are flat, every sublevel set that holds I leaves D; with inputs, again
    with a smaller gain), RAR's ellipsoids between G and F (remain_shapes.py), then the
    other LQR gains' Lyapunov matrices."""
    from fossil_dsl.engine.ellipsoid_seed import ellipsoids
    from fossil_dsl.engine.linear import is_stable, lyapunov_matrix
    from fossil_dsl.engine.quadratic_shapes import exact_controller, lqr_controllers
    spec = plan.spec
    discrete = spec.time is TimeDomain.DISCRETE
    controllers = lqr_controllers(plan, operating, rng)
    for index, (controller, gain) in enumerate(controllers):
        closed = A if gain is None else A + B @ gain
        if is_stable(closed, discrete):  # (else no P: scipy warns of a centre's eigenvalues)
            for Q in _weightings(len(A), rng):
                yield controller, gain, lyapunov_matrix(closed, discrete, Q), None
        if index == 0:
            inputs = B if spec.inputs else np.zeros((len(A), 0))
            for P, K in itertools.chain(
                    ellipsoids(A, inputs, spec, discrete),
                    ellipsoids(A, inputs, spec, discrete, _vertices(spec, operating))):
                controller, gain = exact_controller(spec, K, operating, plan.options.digits) \
                    if spec.inputs else ({}, None)
                yield controller, gain, P, None
            yield from remain_shapes(plan, A, B, operating, _weightings(len(A), rng))


def _vertices(spec, operating: np.ndarray):
    """(A_i, B_i): the Jacobians at the points half way to D's faces along each axis
    (none for a linear field, or where D is not a box)."""
    from fossil_dsl.engine.linear import jacobians
    box = spec.domain.bounding_box()
    if box is None or all(map(traversal.is_affine, spec.dynamics)):
        return []
    found = []
    for i, (low, high) in enumerate(zip(*box)):
        for end in (low, high):
            point = np.zeros(len(spec.states))
            point[i] = VERTEX_SHARE * float(end)
            pair = jacobians(spec, operating, point)
            if pair is not None:
                found.append(pair)
    return found



def _weightings(n: int, rng):
    yield np.eye(n)
    for _ in range(WEIGHTINGS - 1):
        yield np.diag(10 ** rng.uniform(-WEIGHT_SPREAD, WEIGHT_SPREAD, n))


def _exact_shape(P: np.ndarray) -> list[list[Fraction]] | None:
    """P's entries rounded to SIGNIFICANT digits, symmetric; None where the rounded
    matrix is not positive definite."""
    shape = [[Fraction(f"{P[min(i, j), max(i, j)]:.{SIGNIFICANT}g}") for j in range(len(P))]
             for i in range(len(P))]
    return shape if np.linalg.eigvalsh(floats(shape))[0] > 0 else None



def _level(plan: Plan, shape) -> tuple[Fraction | None, bool]:
    """(β just over an upper bound of V on I, whether Ω = {V <= β} reaches ∂D): Ω inside
    D by the shapes' bounds, else reaching ∂D where the kernel's rule has a variant for
    it (an asymmetric box D, as for a shifted population, holds no ellipsoid round the
    origin that holds I: probe69/as10); else (None, False)."""
    from fossil_dsl.engine.quadratic_shapes import set_ceiling
    initial = plan.spec.property.role("initial")
    level = level_between(shape, initial, plan.spec.domain)
    if level is not None or plan.certificate.form not in FORMS \
            or plan.certificate.variant_conditions() is None:
        return level, False
    ceiling = set_ceiling(floats(shape), initial, np.zeros(len(shape)))
    return (None, False) if not ceiling else (Fraction(f"{ceiling * LEVEL_CUSHION:.3g}"), True)



def _misses_unsafe(plan: Plan, shape, level: Fraction, rng) -> bool:
    """V > β at samples of U within D (and above the bound worked out for U's shape,
    where there is one), or there is no U."""
    from fossil_dsl.engine.quadratic_shapes import set_floor
    unsafe = plan.spec.property.role("unsafe")
    if unsafe is None:
        return True
    P = floats(shape)
    floor = set_floor(P, unsafe, np.zeros(len(P)))
    if floor is not None and floor <= level:
        return False
    points = np.asarray(sample(Intersection(unsafe, plan.spec.domain), plan.states,
                               UNSAFE_SAMPLES, rng, plan.spec.domain.bounding_box()), float)
    points = points.reshape(-1, len(P))
    return bool(np.all(np.einsum("bi,ij,bj->b", points, P, points) > float(level)))





