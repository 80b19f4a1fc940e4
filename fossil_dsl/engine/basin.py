"""A Lyapunov function shaped to the simulated basin of attraction, for `region: largest`
(no inputs; continuous or discrete time): the first attempt of such a run.

Points of D are simulated; those whose trajectory stays in D and reaches the origin are
the basin's samples, the others (and samples of ∂D) lie outside any region that can be
certified in D. A polynomial V = sum c_a y^a (y = x scaled to the unit box, monomials of
degree 2..d) is then the solution of a conic program, linear in c:

    V >= 1                        on the samples outside the basin and on ∂D,
    V >= eps |y|^2                on the basin's samples,
    dV/dt <= -eps |y|^2           where V <= 1 at the samples that need it (see below;
                                  for a map, V(f(x)) - V(x) <= -eps |y|^2),
    Q >= e I, -(A^T Q + Q A) >= e I (Q - A^T Q A >= e I for a map)
                                  for V's quadratic part Q and the Jacobian A at the origin,
    minimise the mean of max(0, V - 1) over the basin's samples,

so {V <= 1} holds as much of the sampled basin as the degree allows. Decrease is asked
only where it is needed, found by rounds: after each solution, fresh samples with V <= 1
where it fails are added; a sample where the program cannot meet it (a positive slack,
as on a limit cycle) is moved outside. The quadratic conditions make the linearisation
prove the neighbourhood of the origin.

The result is a candidate, rounded to rationals: the kernel proves it (and the level
bisection of engine/region.py enlarges β) like any other. Nothing here proves anything.
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.basin_program import EPS, solve_conic
from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.engine.sampling import sample
from fossil_dsl.engine.trajectories import numeric_field, rk4_step
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.sets import Boundary
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan
from fossil_dsl.plan.certificates.roa import ROA_FORMS

DEGREES = (6, 8)  # of V, tried in turn; the one covering more of the sampled basin wins
# from 3 states on (a degree-6 program in 3 states took 20 s a round): lower degrees
DEGREES_MANY = (4, 6)
ENOUGH = 0.97  # a degree covering this share of the sampled basin is not raised
SAMPLES = 6000  # points of D's box, simulated
NEAR_ORIGIN = 1500  # more, at log-uniform radii, where the local shape is decided
BOUNDARY_SAMPLES = 1200
CHECK_SAMPLES = 40000  # fresh points where decrease is checked after each round
ADDED_PER_ROUND = 200
CLOUD, CLOUD_RADIUS = 20, 0.01  # points round a counterexample, and their spread (of the scale)
ROUNDS = 10
HORIZON, STEP = 30.0, 0.02  # simulated time units, RK4 step
ITERATES = 300  # of a map, simulated
ARRIVED = 1e-2  # of the scale: a trajectory this close to the origin has converged
STUCK = 1e-4  # a decrease slack (per |y|^2) above which the point is given up
SIGNIFICANT = 7  # digits kept of each coefficient


@dataclass(frozen=True)
class BasinFinding:
    formula: E.Expr
    degree: int
    coverage: float  # share of the sampled basin with V <= 1 and decrease on the checks
    rounds: int
    seconds: float

    def describe(self) -> str:
        return (f"V of degree {self.degree} shaped to the simulated basin (conic program, "
                f"{self.rounds} round{'s' if self.rounds != 1 else ''}; "
                f"{100 * self.coverage:.1f} % of the sampled basin "
                f"below level 1), {self.seconds:.2f} s")


def applies(plan: Plan) -> bool:
    spec = plan.spec
    return (plan.options.largest_region and plan.certificate.form in ROA_FORMS
            and not spec.inputs
            and plan.controller is None and spec.torch_dynamics is None
            and spec.synthesis.certificate is None and spec.synthesis.candidate is None
            and spec.domain.bounding_box() is not None and _jacobian(plan) is not None)


def shaped_lyapunov(plan: Plan, deadline: float) -> BasinFinding | None:
    """The best V over DEGREES (see BasinSearch.find), or None."""
    return BasinSearch(plan).find(deadline)


class BasinSearch:
    """The programs of one run: `find` a V, then `refine` it with points where a verifier
    found it failing (counterexample-guided, like the learning loop)."""

    def __init__(self, plan: Plan):
        self.samples = _Samples(plan, np.random.default_rng(plan.options.seed))
        self.best: tuple[_Program, tuple] | None = None
        self.started = time.monotonic()

    def find(self, deadline: float) -> BasinFinding | None:
        """The best V by the coverage its program reports (the first degree that covers
        ENOUGH: a lower degree is quicker to prove), or None."""
        for degree in DEGREES if len(self.samples.states) < 3 else DEGREES_MANY:
            if time.monotonic() > deadline:
                break
            program = _Program(self.samples, degree)
            found = program.solve(deadline)
            if found is not None and (self.best is None or found[1] > self.best[1][1]):
                self.best = (program, found)
            if self.best is not None and self.best[1][1] >= ENOUGH:
                break
        return self._finding()

    def refine(self, points: np.ndarray, deadline: float) -> BasinFinding | None:
        """The best program solved again with decrease asked at the points and round
        them (or None)."""
        if self.best is None or not len(points):
            return None
        program = self.best[0]
        program.require(_around(points, self.samples.scale, np.random.default_rng(0)))
        found = program.solve(deadline)
        self.best = (program, found) if found is not None else None
        return self._finding()

    def _finding(self) -> BasinFinding | None:
        if self.best is None:
            return None
        program, (coefficients, coverage, rounds) = self.best
        return BasinFinding(self.samples.formula(program.degree, coefficients), program.degree,
                            coverage, rounds, time.monotonic() - self.started)


def _around(points: np.ndarray, scale: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The points and a cloud round each (a counterexample is rarely alone)."""
    cloud = points[:, None, :] + CLOUD_RADIUS * scale * rng.normal(
        size=(len(points), CLOUD, points.shape[1]))
    return np.concatenate([points, cloud.reshape(-1, points.shape[1])])


class _Samples:
    """The simulated samples, labelled, in scaled coordinates y = x / scale."""

    def __init__(self, plan: Plan, rng: np.random.Generator):
        spec, self.states = plan.spec, plan.states
        low, high = (np.array([float(v) for v in side]) for side in spec.domain.bounding_box())
        self.scale = np.maximum(np.abs(low), np.abs(high))
        self.field = numeric_field(spec.dynamics, self.states)
        self.discrete = spec.time is TimeDomain.DISCRETE
        self.jacobian = _jacobian(plan) * self.scale[None, :] / self.scale[:, None]
        self.in_domain = lambda x: np.asarray(holds(spec.domain.contains_formula(self.states),
                                                    state_env(self.states, x), len(x)), bool)
        n = len(self.states)
        near = self._near_origin(rng, NEAR_ORIGIN)
        points = rng.uniform(low, high, (SAMPLES, n))
        points = np.concatenate([points[self.in_domain(points)], near[self.in_domain(near)]])
        converging = self._converges(points)
        edge = sample(Boundary(spec.domain), self.states, BOUNDARY_SAMPLES, rng,
                      spec.domain.bounding_box())
        self.basin = points[converging]
        # the box's corners too: a face sampler rarely lands on one, and V dipped to 0.18
        # at a corner of the two-machine domain
        corners = np.array(list(itertools.product(*zip(low, high))))
        self.outside = np.concatenate([points[~converging], np.asarray(edge, float), corners])
        self.edge_checks = np.asarray(sample(Boundary(spec.domain), self.states,
                                             CHECK_SAMPLES // 4, rng,
                                             spec.domain.bounding_box()), float)
        # decrease is asked from the start near the origin (where the shape is decided and
        # a sparse grid misses failures), checked everywhere after each round
        self.decrease = near[self.in_domain(near) & self._converges(near)]
        checks = np.concatenate([rng.uniform(low, high, (CHECK_SAMPLES, n)),
                                 self._near_origin(rng, CHECK_SAMPLES // 4)])
        self.checks = checks[self.in_domain(checks)]

    def _near_origin(self, rng: np.random.Generator, count: int) -> np.ndarray:
        """Points at log-uniform radii (1e-3 to 0.3 of the scale) in random directions."""
        n = len(self.states)
        radii = np.exp(rng.uniform(math.log(1e-3), math.log(0.3), count))
        directions = rng.normal(size=(count, n))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        return radii[:, None] * directions * self.scale

    def _converges(self, points: np.ndarray) -> np.ndarray:
        """Where the simulated trajectory stays in D and ends near the origin."""
        x, kept = points.copy(), np.ones(len(points), bool)
        for _ in range(ITERATES if self.discrete else int(HORIZON / STEP)):
            x = np.clip(self.field(x) if self.discrete else rk4_step(self.field, x, STEP),
                        -1e6, 1e6)
            kept &= np.isfinite(x).all(1) & self.in_domain(np.nan_to_num(x, nan=1e6))
        return kept & (np.linalg.norm(x / self.scale, axis=1) < ARRIVED)

    def squared(self, x: np.ndarray) -> np.ndarray:
        return np.sum((x / self.scale) ** 2, axis=1)

    def formula(self, degree: int, coefficients: np.ndarray) -> E.Expr:
        """sum c_a (x / scale)^a as an exact polynomial in x, each coefficient rounded to
        SIGNIFICANT digits (short decimals)."""
        terms = {}
        for exponents, c in zip(P.monomials(len(self.states), 2, degree), coefficients):
            value = float(c) / float(np.prod(self.scale ** np.array(exponents)))
            rounded = Fraction(f"{value:.{SIGNIFICANT}g}")
            if rounded:
                terms[exponents] = rounded
        return P.to_expr(terms, self.states)


class _Program:
    """Rounds of the conic program for one degree."""

    def __init__(self, samples: _Samples, degree: int):
        self.samples, self.degree = samples, degree
        self.exponents = np.array(P.monomials(len(samples.states), 2, degree))
        self.outside = samples.outside
        self.decrease = samples.decrease
        self.near = np.ones(len(self.decrease), bool)  # never moved outside
        # the fixed samples' monomials, once (each round anew they took 21 s of a 57 s
        # search in 2 states)
        self.basin_values = self.values(samples.basin)
        self.check_points = np.concatenate([samples.basin, samples.checks])
        self.check_values = np.concatenate([self.basin_values, self.values(samples.checks)])
        self.check_changes = self.changes(self.check_points)
        self.edge_values = self.values(samples.edge_checks)

    def values(self, x: np.ndarray) -> np.ndarray:
        """Each monomial of y = x / scale at each point: shape [N, m]."""
        y = x / self.samples.scale
        return np.prod(y[:, None, :] ** self.exponents[None, :, :], axis=2)

    def changes(self, x: np.ndarray) -> np.ndarray:
        """d/dt of each monomial along the field at each point (for a map, its change
        over a step): shape [N, m]."""
        if self.samples.discrete:
            with np.errstate(all="ignore"):
                return np.nan_to_num(self.values(self.samples.field(x)) - self.values(x),
                                     nan=1e12, posinf=1e12, neginf=-1e12)
        y, dy = x / self.samples.scale, self.samples.field(x) / self.samples.scale
        total = np.zeros((len(x), len(self.exponents)))
        for i in range(y.shape[1]):
            lowered = self.exponents.copy()
            lowered[:, i] = np.maximum(lowered[:, i] - 1, 0)
            part = self.exponents[None, :, i] * np.prod(y[:, None, :] ** lowered[None], axis=2)
            total += part * dy[:, i:i + 1]
        return total

    def require(self, points: np.ndarray) -> None:
        """Decrease asked at these points from the next solution on."""
        self.decrease = np.concatenate([self.decrease, points])
        self.near = np.concatenate([self.near, np.zeros(len(points), bool)])

    def solve(self, deadline: float):
        """(coefficients, coverage, rounds) or None. Between rounds, points of the
        checks with V <= 1 where decrease fails are added, points of ∂D with V < 1 are
        added outside, and decrease points whose
        slack shows they cannot decrease are moved outside (never those near the origin)."""
        s = self.samples
        found = None
        for round_ in range(1, ROUNDS + 1):
            if time.monotonic() > deadline:
                break
            solved = solve_conic(self, self.outside, self.decrease, deadline)
            if solved is None:
                break
            c, slack = solved
            stuck = (slack > STUCK) & ~self.near
            self.outside = np.concatenate([self.outside, self.decrease[stuck]])
            self.decrease, self.near = self.decrease[~stuck], self.near[~stuck]
            failing = self._failing(c)
            low_edge = s.edge_checks[self.edge_values @ c < 1][:ADDED_PER_ROUND]
            self.outside = np.concatenate([self.outside, low_edge])
            found = (c, self._coverage(c), round_)
            if not len(failing) and not stuck.any() and not len(low_edge):
                break
            self.require(failing)
        return found

    def _failing(self, c) -> np.ndarray:
        """Points (basin samples first, then the checks) with V <= 1 where V <= 0 or
        decrease fails."""
        points = self.check_points
        v, dv = self.check_values @ c, self.check_changes @ c
        bad = (v <= 1) & ((dv > -EPS * self.samples.squared(points)) | (v <= 0))
        return points[bad][:ADDED_PER_ROUND]

    def _coverage(self, c) -> float:
        """Share of the basin's samples below the largest level at which every check
        point decreases."""
        checks = slice(len(self.basin_values), None)
        v, dv = self.check_values[checks] @ c, self.check_changes[checks] @ c
        failing = v[(dv >= 0) | (v <= 0)]
        level = min(1.0, float(failing.min()) if len(failing) else 1.0)
        return float(np.mean(self.basin_values @ c <= level))


def _jacobian(plan: Plan) -> np.ndarray | None:
    """df/dx at the origin (engine/linear.py), or None where it is not a finite number."""
    from fossil_dsl.engine.linear import jacobians  # imports torch: only when it applies
    found = jacobians(plan.spec)
    return None if found is None else found[0]
