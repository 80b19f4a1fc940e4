"""The sets of the reach programs (sos_reach.py) as constraint lists, g >= 0 on each
piece: I's members, D's faces and the part of D outside S, D outside G (and F), and for
RSWA the balls round the origin inside F that fix its level."""
from __future__ import annotations

import copy
from fractions import Fraction

import numpy as np

from fossil_dsl.engine.quadratic_shapes import box_middle
from fossil_dsl.engine.sos import Inexact, faces, interval_products, set_constraints, set_pieces
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.sets import Box, Complement
from fossil_dsl.plan.compile import Plan


def _constraints(region, states) -> list[P.Polynomial]:
    """The region's constraints, exactly: a program's condition on a larger set than
    "outside S" or "G" would ask for the wrong thing."""
    return set_constraints(region, states, exact=True)


class Pieces:
    """The constraint lists (g >= 0 on the piece) of every condition's sets; raises
    Inexact where a set is not described exactly."""

    def __init__(self, plan: Plan):
        spec, states = plan.spec, plan.states
        prop = spec.property
        self.domain = _constraints(spec.domain, states)
        self.initial = [interval_products(piece)
                        for piece in set_pieces(prop.role("initial"), states, exact=True)]
        unsafe = prop.role("unsafe")
        if prop.form == "reach":  # S is D
            outside_safe = []
        elif unsafe is not None and not isinstance(unsafe, Complement):  # S = D \ U
            outside_safe = [interval_products(piece + self.domain)
                            for piece in set_pieces(unsafe, states, exact=True)]
        else:  # S is a set of its own (`S until G`)
            outside_safe = self.outside(prop.role("safe"), states)
        self.boundary = self.faces() + outside_safe
        staying = prop.form == "reach and stay while avoid"
        goal = prop.role("final") if staying else prop.role("goal")
        self.outside_goal = self.outside(goal, states)
        self.goal = interval_products(_constraints(goal, states))
        final = prop.role("final")
        self.outside_final = self.outside(final, states) if final is not None and \
            not staying else None
        # RAR's B > 0 on D outside F puts {B <= 0} inside F: B's decay may be asked there
        self.final = None if self.outside_final is None else \
            _constraints(final, states) + self.domain
        self.stay = StayPieces(self, goal, plan) if staying else None

    def faces(self) -> list[list[P.Polynomial]]:
        return faces(self.domain)

    def outside(self, region, states) -> list[list[P.Polynomial]]:
        """D outside the region's interior: {g <= 0} within D, one piece per g."""
        return self._outside(_constraints(region, states))

    def _outside(self, constraints) -> list[list[P.Polynomial]]:
        return [[P.scale(g, -1)] + interval_products(self.domain) for g in constraints]

    def confined(self, box: list[P.Polynomial]) -> "Pieces":
        """The pieces for {V <= 0} inside a box B of D: V > 0 on D outside B's interior
        too, and V's decrease asked on B outside G only (the kernel asks it where V <= 0).
        A decrease on all of D can be out of reach where D holds states that leave it
        fast (probe71/au01: a radial orbit, D reaching 0.5 from the attracting centre)."""
        confined = copy.copy(self)
        confined.boundary = self.boundary + self._outside(box)
        confined.outside_goal = [piece + box for piece in self.outside_goal]
        return confined


class StayPieces:
    """For RSWA, balls round the closed loop's equilibrium c in F (the origin, else for a
    system without inputs the equilibrium Newton's method finds from the middle of F's
    box: a population at its capacity, probe70/at35), of a quarter and a half of the
    sampled distance from c to F's boundary: V < β on the inner one, V > β on F outside
    the outer one, and V decreases on D outside the inner one. With β fixed,
    F ∩ {V >= β} then lies where V decreases and ∂F has V > β. For a map, V(f(x)) < β
    on the inner ball too: a step from F ∩ {V <= β} then keeps V <= β."""

    def __init__(self, pieces: Pieces, final, plan: Plan):
        states = plan.states
        centre = _stay_centre(final, plan)
        reach = None if centre is None else _distance_to_boundary(final, plan, centre)
        if reach is None:
            raise Inexact("no equilibrium found inside F")
        inner, outer = (_ball(states, reach / 4, centre), _ball(states, reach / 2, centre))
        self.inner = [inner]
        self.decrease = [[P.scale(inner, -1)] + interval_products(pieces.domain)]
        self.above = [pieces.goal + [P.scale(outer, -1)]]


def _ball(states, radius: float, centre) -> P.Polynomial:
    """r^2 - |x - c|^2 (>= 0 on the ball), with r^2 and c short rationals."""
    square = Fraction(radius ** 2).limit_denominator(10 ** 6)
    offsets = [E.add(E.Var(s), E.Num(-Fraction(float(c)).limit_denominator(10 ** 6)))
               for s, c in zip(states, centre)]
    norm = E.add(*(E.power(o, E.Num(2)) for o in offsets))
    return P.add(P.constant(square, len(states)), P.scale(P.polynomial(norm, states), -1))


def _inside(region, plan: Plan, point) -> bool:
    from fossil_dsl.engine.evaluate import holds, state_env
    points = np.asarray(point, dtype=float).reshape(1, -1)
    return bool(holds(region.contains_formula(plan.states), state_env(plan.states, points),
                      1)[0])


def _stay_centre(final, plan: Plan) -> np.ndarray | None:
    """The origin where F holds it; else, without inputs, an equilibrium inside F."""
    origin = np.zeros(len(plan.states))
    if _inside(final, plan, origin):
        return origin
    middle = box_middle(final)
    if plan.spec.inputs or middle is None:
        return None
    from fossil_dsl.engine.linear import equilibrium
    found = equilibrium(plan.spec, middle)
    return found if found is not None and _inside(final, plan, found) else None


def _distance_to_boundary(region, plan: Plan, centre) -> float | None:
    """The smallest |x - c| over samples of the region's boundary (None where it is 0)."""
    from fossil_dsl.engine.sampling import sample
    from fossil_dsl.ir.sets import Boundary
    points = np.asarray(sample(Boundary(region), plan.states, 2000,
                               np.random.default_rng(plan.options.seed),
                               plan.spec.domain.bounding_box()), dtype=float)
    distance = float(np.linalg.norm(points - centre, axis=1).min()) if len(points) else 0.0
    return distance if distance > 0 else None


def set_point(plan: Plan) -> np.ndarray | None:
    """Where a controller should hold the state when G (F for RSWA) lies off the origin:
    the middle of G's box, where that is in G (a tank's level: probe70/at27); None where
    the origin is in G, or the middle is not."""
    prop = plan.spec.property
    goal = prop.role("final") if prop.form == "reach and stay while avoid" else prop.role("goal")
    middle = box_middle(goal)
    if middle is None or _inside(goal, plan, np.zeros(len(plan.states))):
        return None
    return middle if _inside(goal, plan, middle) else None


CONFINING_FACTORS = (1.5, 3.0)  # of the half-widths of the hull of I's and G's boxes


def confining_boxes(plan: Plan) -> list[list[P.Polynomial]]:
    """Boxes round I and G, inside D's box and smaller than it, as constraint lists
    (x - l >= 0, u - x >= 0 with short rationals); none where a box is missing."""
    prop = plan.spec.property
    boxes = [region.bounding_box() if region is not None else None
             for region in (prop.role("initial"), prop.role("goal"), plan.spec.domain)]
    if any(box is None for box in boxes):
        return []
    (il, iu), (gl, gu), (dl, du) = [(np.asarray(b[0], float), np.asarray(b[1], float))
                                    for b in boxes]
    low, high = np.minimum(il, gl), np.maximum(iu, gu)
    found = []
    for factor in CONFINING_FACTORS:
        middle, half = (low + high) / 2, factor * (high - low) / 2
        lower, upper = np.maximum(middle - half, dl), np.minimum(middle + half, du)
        if np.allclose(lower, dl) and np.allclose(upper, du):
            break
        found.append(_box_constraints(plan.states, lower, upper))
    return found


def _box_constraints(states, lower, upper) -> list[P.Polynomial]:
    """The box's constraints, its corners rounded to short rationals."""
    def short(values):
        return tuple(E.Num(Fraction(float(v)).limit_denominator(1000)) for v in values)
    return _constraints(Box(short(lower), short(upper)), states)
