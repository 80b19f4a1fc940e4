"""Sampled checks of a quadratic shape x^T P x (P as exact rationals, `shape`): its
sublevel set between two sets, its decrease at samples of a sublevel set and its shell,
the points of a set. Shared by the linearisation's candidates (quadratic_roa.py) and
the reach-type functions built from them (reach_shapes.py). Nothing here is trusted:
what passes is proved like any candidate.
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.evaluate import holds, state_env
from fossil_dsl.ir import expr as E

INSIDE, SHELL = 4000, 2000  # samples of Ω and of its boundary {V = β}
LEVEL_CUSHION = 1.01  # β over the largest V on I (an upper bound worked out for I's shape)


def quadratic(shape, states) -> E.Expr:
    """x^T P x, each product once."""
    return E.add(*(E.mul(E.Num(shape[i][j] * (1 if i == j else 2)),
                         E.power(E.Var(a), E.Num(2)) if i == j else E.mul(E.Var(a), E.Var(b)))
                   for i, a in enumerate(states) for j, b in enumerate(states)
                   if j >= i and shape[i][j]))


def floats(shape) -> np.ndarray:
    return np.array([[float(v) for v in row] for row in shape])


def level_between(shape, inner, outer) -> Fraction | None:
    """A level just over an upper bound of x^T P x on `inner` whose sublevel set lies
    inside `outer` by the shapes' bounds (else None)."""
    from fossil_dsl.engine.quadratic_shapes import boundary_floor, set_ceiling
    P, centre = floats(shape), np.zeros(len(shape))
    ceiling = set_ceiling(P, inner, centre)
    floor = boundary_floor(P, outer, centre)
    if ceiling is None or floor is None or not 0 < ceiling * LEVEL_CUSHION < floor:
        return None
    return Fraction(f"{ceiling * LEVEL_CUSHION:.3g}")


def decreases(plan, field, shape, level: Fraction, discrete: bool, rng,
               reaching: bool = False) -> bool:
    """V decreases (and, for a map, f(x) stays in D) at samples of Ω and of its shell;
    where Ω reaches ∂D, at those in D, and the field points into D on D's faces."""
    P = floats(shape)
    points = ellipsoid_points(P, float(level), rng)
    if reaching:
        from fossil_dsl.engine.quadratic_shapes import enters_box
        points = points[inside(plan, plan.spec.domain, points)]
        if not enters_box(plan.spec.domain, field, P, float(level), points):
            return False
    rates, image = change(field, P, points, discrete)
    if discrete and not np.all(inside(plan, plan.spec.domain, image)):
        return False
    return bool(np.all(rates < 0))


def change(field, P: np.ndarray, points: np.ndarray, discrete: bool):
    """(x^T P x's change at the points: its step for a map, else its derivative; the
    field's values there)."""
    with np.errstate(all="ignore"):
        image = field(points)
        if discrete:
            change = np.einsum("bi,ij,bj->b", image, P, image) - \
                np.einsum("bi,ij,bj->b", points, P, points)
        else:
            change = 2 * np.einsum("bi,ij,bj->b", points, P, image)
    return change, image


def inside(plan, region, points: np.ndarray) -> np.ndarray:
    env = state_env(plan.states, np.nan_to_num(points, nan=1e9))
    return np.asarray(holds(region.contains_formula(plan.states), env, len(points)), bool)


def ellipsoid_points(P: np.ndarray, level: float, rng) -> np.ndarray:
    """Uniform samples of {x^T P x <= level} and of its boundary (none at the origin)."""
    n = len(P)
    directions = rng.normal(size=(INSIDE + SHELL, n))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    radii = np.concatenate([rng.uniform(1e-6, 1, INSIDE) ** (1 / n), np.ones(SHELL)])
    # x = sqrt(level) L^-T u for P = L L^T maps the unit ball onto the ellipsoid
    L = np.linalg.cholesky(P)
    return math.sqrt(level) * np.linalg.solve(L.T, (radii[:, None] * directions).T).T
