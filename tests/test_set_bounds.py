"""The box a semialgebraic set lies in (ir/set_bounds.py): besides `x <= c`, a sum of
squares bounded by a constant (`th^2 + w^2 <= 4`). probe70/at28's disc-shaped domain was
refused as unbounded before session 70."""
from fractions import Fraction
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import fossil_dsl
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.set_bounds import constraint_box

SPECS = Path(__file__).resolve().parent.parent / "specs"
STATES = ("x", "y")
x, y = E.Var("x"), E.Var("y")
small = st.fractions(min_value=Fraction(-3), max_value=Fraction(3), max_denominator=8)
weight = st.fractions(min_value=Fraction(1, 8), max_value=Fraction(4), max_denominator=8)


def _sum_of_squares(a, b, cx, cy, r):
    """a (x - cx)^2 + b (y - cy)^2 <= r, expanded as a user might write it."""
    left = E.add(E.mul(E.Num(a), E.power(E.add(x, E.Num(-cx)), E.Num(2))),
                 E.mul(E.Num(b), E.power(E.add(y, E.Num(-cy)), E.Num(2))))
    return L.Compare("<=", left, E.Num(r))


@settings(max_examples=60, deadline=None)
@given(a=weight, b=weight, cx=small, cy=small, r=weight)
def test_every_point_of_an_ellipse_lies_in_its_box_and_the_box_is_tight(a, b, cx, cy, r):
    box = constraint_box((_sum_of_squares(a, b, cx, cy, r),), STATES)
    assert box is not None
    angles = np.linspace(0, 2 * np.pi, 721)
    rx, ry = np.sqrt(float(r / a)), np.sqrt(float(r / b))
    px, py = float(cx) + rx * np.cos(angles), float(cy) + ry * np.sin(angles)
    assert box[0][0] <= px.min() and px.max() <= box[1][0]
    assert box[0][1] <= py.min() and py.max() <= box[1][1]
    assert box[1][0] - box[0][0] <= 2 * rx * (1 + 1e-6) + 1e-6


def test_cross_terms_and_missing_squares_give_no_box():
    cross = L.Compare("<=", E.add(E.power(x, E.Num(2)), E.power(y, E.Num(2)), E.mul(x, y)),
                      E.Num(4))
    assert constraint_box((cross,), STATES) is None
    linear_y = L.Compare("<=", E.add(E.power(x, E.Num(2)), y), E.Num(4))
    assert constraint_box((linear_y,), STATES) is None


def test_a_disc_cut_by_a_stop_is_a_domain_and_the_pendulum_is_certified_on_it():
    spec = fossil_dsl.load(SPECS / "probe70/at28_pendulum_semialgebraic_domain_stable.fsl")
    assert spec.domain.bounding_box()[0][0] == -1.5
    result = fossil_dsl.synthesise(spec, timeout=60)
    assert result.certified and result.kernel.certified
