"""The closed superset of a set's boundary that reach conditions are proved on
(logic.boundary_outer): it must contain every boundary point (else a condition "V > 0 on
∂S" could be proved while failing on ∂S), and for a domain minus a box it must not
contain the lines through the box's faces (else no V can separate I from the unsafe box
when the goal lies across one of those lines)."""
from __future__ import annotations

from fractions import Fraction
from itertools import product

from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.expr import Num, Var

STATES = ("x0", "x1")


def box(low, high, is_open=False) -> S.Box:
    return S.Box(tuple(Num(Fraction(v)) for v in low), tuple(Num(Fraction(v)) for v in high),
                 is_open)


def ball(centre, radius) -> S.Ball:
    return S.Ball(tuple(Num(Fraction(c)) for c in centre), Num(Fraction(radius)))


def at(formula: L.Formula, point) -> bool:
    values = {name: Num(Fraction(v)) for name, v in zip(STATES, point)}
    return L.truth(L.substitute(formula, values))


def on_boundary(region: S.SetExpr, point) -> bool:
    return at(L.boundary_outer(region.contains_formula(STATES)), point)


DOMAIN = box([-3, -3], [3, 3])
UNSAFE = box([-1, Fraction(3, 2)], [1, 3])


def test_domain_minus_a_box_is_exact():
    safe = S.Complement(UNSAFE, DOMAIN)
    for point in [(0, Fraction(3, 2)), (-1, 2), (1, Fraction(5, 2)), (3, 0), (0, -3),
                  (-3, 3)]:
        assert on_boundary(safe, point), point
    # the lines x0 = -1, x0 = 1 and x1 = 3/2 outside the box are no boundary of S
    for point in [(-1, 0), (1, -2), (-2, Fraction(3, 2)), (0, 0), (0, 2)]:
        assert not on_boundary(safe, point), point


def test_annulus_boundary_is_both_circles():
    annulus = S.Difference(ball([0, 0], 2), ball([0, 0], 1))
    for point in [(2, 0), (0, -2), (1, 0), (0, 1)]:
        assert on_boundary(annulus, point), point
    for point in [(Fraction(3, 2), 0), (0, 0), (3, 0)]:
        assert not on_boundary(annulus, point), point


# ---- every boundary point is kept: sets of boxes on the half-integer grid -----------
COORDINATE = st.integers(-4, 4).map(lambda k: Fraction(k, 2))


@st.composite
def boxes(draw):
    corners = [sorted((draw(COORDINATE), draw(COORDINATE))) for _ in STATES]
    low, high = zip(*corners)
    return box(low, high, is_open=draw(st.booleans()))


@st.composite
def regions(draw, depth=2):
    if depth == 0 or draw(st.booleans()):
        return draw(boxes())
    left, right = draw(regions(depth - 1)), draw(regions(depth - 1))
    kind = draw(st.sampled_from([S.Union, S.Intersection, S.Difference, "complement"]))
    return S.Complement(left, right) if kind == "complement" else kind(left, right)


def truly_on_boundary(region: S.SetExpr, point) -> bool:
    """For sets whose faces lie on the half-integer grid, and a grid point: near it the
    set is a union of open quadrants, open half-axes and the point, so the point is on
    the boundary exactly when these nine points do not all agree."""
    formula = region.contains_formula(STATES)
    step = Fraction(1, 8)
    memberships = {at(formula, (point[0] + a * step, point[1] + b * step))
                   for a, b in product((-1, 0, 1), repeat=2)}
    return len(memberships) == 2


@settings(max_examples=300, deadline=None)
@given(regions(), COORDINATE, COORDINATE)
def test_every_boundary_point_is_kept(region, x0, x1):
    if truly_on_boundary(region, (x0, x1)):
        assert on_boundary(region, (x0, x1))
