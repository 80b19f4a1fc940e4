"""Reach-type functions from a quadratic shape x^T P x whose sublevel set Ω holds I
(quadratic_roa.py finds the shapes): for reach and RWA V = k (x^T P x - β) falling by
REACH_MARGIN γ at the samples of Ω outside G; for RAR also B = x^T P x - b, b just over
its largest value on G, {B <= 0} inside F (from its own shape where remain_shapes.py
gives one); for RSWA V as for RWA with F in place of G and the level β of V just inside
F's boundary, below which V falls too. Nothing here is trusted: the functions are proved
like any candidate.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np

from fossil_dsl.engine.ellipse_checks import (LEVEL_CUSHION, SHELL, change, decreases,
                                              ellipsoid_points, floats, inside,
                                              level_between, quadratic)
from fossil_dsl.engine.sampling import sample
from fossil_dsl.ir import expr as E
from fossil_dsl.ir.sets import Boundary

REMAIN_FORM = "reach-avoid-remain"
STAY_FORM = "reach and stay while avoid"
REACH_MARGIN = 10.0  # k makes V fall by this many times γ at the slowest sample of Ω \ G


def reach_formulas(plan, field, shape, level: Fraction, discrete: bool, rng,
                   remain=None) -> tuple[dict, dict] | None:
    """(functions, levels): {"V": V} (and RAR's "B", from `remain` where given; RSWA's
    level "beta") from the shape, or None where one fails its samples."""
    if plan.certificate.form == STAY_FORM:
        return _staying(plan, field, shape, level, discrete, rng)
    V = _reaching(plan, field, shape, level, discrete, rng)
    if V is None or plan.certificate.form != REMAIN_FORM:
        return None if V is None else ({"V": V}, {})
    B = _remaining(plan, field, shape if remain is None else remain, discrete, rng)
    return None if B is None else ({"V": V, "B": B}, {})


def _remaining(plan, field, shape, discrete: bool, rng):
    """RAR's B = x^T P x - b, b just over its largest value on G, where {B <= 0} lies in F
    and x^T P x falls at the samples of that set (and, for a map, each step from it
    lands in D); else None."""
    prop = plan.spec.property
    level = level_between(shape, prop.role("goal"), prop.role("final"))
    if level is None or not decreases(plan, field, shape, level, discrete, rng):
        return None
    return E.add(quadratic(shape, plan.states), E.Num(-level))


def _reaching(plan, field, shape, level: Fraction, discrete: bool, rng):
    """k (x^T P x - β) with V's change at most -REACH_MARGIN γ at the samples of Ω
    outside G, where G holds the origin and Ω (and, for a map, every step from it) lies
    in S at the samples; else None."""
    prop, P = plan.spec.property, floats(shape)
    safe, goal = prop.role("safe") or plan.spec.domain, prop.role("goal")
    if not inside(plan, goal, np.zeros((1, len(P))))[0]:
        return None  # V would have to fall by γ next to the equilibrium
    # V falls slowest next to G: its boundary's samples too
    edge = np.asarray(sample(Boundary(goal), plan.states, SHELL, rng,
                             plan.spec.domain.bounding_box()), float).reshape(-1, len(P))
    edge = edge[np.einsum("bi,ij,bj->b", edge, P, edge) <= float(level)]
    points = ellipsoid_points(P, float(level), rng)
    points = np.concatenate([points[~inside(plan, goal, points)], edge])
    rates, image = change(field, P, points, discrete)
    if not (np.all(inside(plan, safe, points)) and len(points) and np.all(rates < 0)):
        return None
    if discrete and not np.all(inside(plan, safe, image)):
        return None
    return _falling(plan, shape, level, rates)[1]


def _staying(plan, field, shape, level: Fraction, discrete: bool, rng):
    """RSWA's ({"V": k (x^T P x - level)}, {"beta": k (m - level)}), m just under x^T P x's
    least value on F's boundary, so that A = F ∩ {V <= β} is the ellipsoid {x^T P x <= m}:
    x^T P x falls at the samples of Ω and of F outside that ellipsoid, V by REACH_MARGIN γ
    outside it (and on its boundary), and Ω (for a map, each step from it) lies in S;
    else None."""
    from fossil_dsl.engine.quadratic_shapes import boundary_floor
    prop, P = plan.spec.property, floats(shape)
    safe, final = prop.role("safe") or plan.spec.domain, prop.role("final")
    floor = boundary_floor(P, final, np.zeros(len(P)))
    if floor is None or not 0 < floor < float(level):
        return None
    inner = Fraction(f"{floor / LEVEL_CUSHION:.3g}")
    in_final = np.asarray(sample(final, plan.states, SHELL, rng,
                                 plan.spec.domain.bounding_box()), float).reshape(-1, len(P))
    omega = ellipsoid_points(P, float(level), rng)
    edge = ellipsoid_points(P, float(inner), rng)[-SHELL:]  # {x^T P x = m}
    outer = np.concatenate([omega, in_final, edge])
    outer = outer[np.einsum("bi,ij,bj->b", outer, P, outer) >= float(inner)]
    rates, image = change(field, P, np.concatenate([outer, omega]), discrete)
    if not (len(outer) and np.all(inside(plan, safe, omega)) and np.all(rates < 0)):
        return None
    if discrete and not np.all(inside(plan, safe, image)):
        return None
    k, V = _falling(plan, shape, level, rates[:len(outer)])
    return {"V": V}, {"beta": k * (inner - level)}


def _falling(plan, shape, level: Fraction, rates) -> tuple[Fraction, E.Expr]:
    """(k, k (x^T P x - level)) with k such that V falls by REACH_MARGIN γ at the slowest
    of the rates."""
    from fossil_dsl.plan.certificates.rwa import GAMMA
    k = Fraction(f"{REACH_MARGIN * float(GAMMA) / float(-rates.max()):.3g}")
    scaled = [[k * entry for entry in row] for row in shape]
    return k, E.add(quadratic(scaled, plan.states), E.Num(-k * level))
