"""Formulas equivalent to a row of the property table prove that row: `always not U and
eventually G` is reach-avoid-remain with F the safe set; `eventually (G and always F)`
and `eventually always F` are RAR and RSWA with the domain as the safe set and no
avoided set; `always not U and eventually always F` is RSWA (F and U are disjoint)."""
from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import pytest

import fossil_dsl
from fossil_dsl import check_text
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.atoms import folded

SPECS = Path(__file__).resolve().parent.parent / "specs"

HEADER = """\
state x, y
dynamics continuous {
    x' = -x + y
    y' = -x - y
}
domain box([-2, -2], [2, 2])
set I = ball([1, 0], 0.2)
set U = ball([-1.5, -1.5], 0.2)
set G = ball([0, 0], 0.3)
set F = ball([0, 0], 0.5)
set S = ~U
set V = ball([1.5, -1.5], 0.2)
"""


def checked(prove: str):
    return check_text(HEADER + f"prove {prove}\n")


def property_of(prove: str):
    result = checked(prove)
    assert result.ok, result.render()
    return result.spec.property


def inside(region, x: str, y: str) -> bool:
    point = {"x": E.Num(Fraction(x)), "y": E.Num(Fraction(y))}
    decided = L.truth(folded(L.substitute(region.contains_formula(("x", "y")), point), ()))
    assert decided is not None
    return decided


@pytest.mark.parametrize("prove", [
    "from I: eventually G and always not U",
    "from I: always not U and eventually G",
    "from I: always S and eventually G",
    "from I: not eventually U and eventually G",
])
def test_avoid_for_ever_and_reach_is_reach_avoid_remain_in_the_safe_set(prove):
    prop = property_of(prove)
    assert prop.form == "reach-avoid-remain"
    final = prop.role("final")
    assert inside(final, "0", "0") and inside(final, "1.5", "1.5")
    assert not inside(final, "-1.5", "-1.5")  # U's centre
    assert inside(prop.role("unsafe"), "-1.5", "-1.5")


def test_eventually_reach_and_remain_has_the_domain_as_safe_set_and_nothing_to_avoid():
    prop = property_of("from I: eventually (G and always F)")
    assert prop.form == "reach-avoid-remain"
    assert prop.role("safe") == prop.role("domain")
    assert inside(prop.role("final"), "0.4", "0") and not inside(prop.role("final"), "1", "0")
    for corner in (("2", "2"), ("0", "0"), ("-2", "1")):
        assert not inside(prop.role("unsafe"), *corner)


@pytest.mark.parametrize("prove", ["from I: eventually always F",
                                   "from I: always not U and eventually always F"])
def test_settling_for_ever_is_reach_and_stay(prove):
    prop = property_of(prove)
    assert prop.form == "reach and stay while avoid"
    assert inside(prop.role("final"), "0.4", "0") and not inside(prop.role("final"), "1", "0")


@pytest.mark.parametrize("prove, form", [
    ("from I: always not U and always not V", "safety"),
    ("from I: not eventually U and not eventually V", "safety"),
    ("from I: always not U and stable and always not V", "stable while avoid"),
    ("from I: always not V and eventually G and always not U", "reach-avoid-remain"),
    ("from I: always not V and eventually always F and always not U",
     "reach and stay while avoid"),
])
def test_avoiding_each_set_for_ever_is_avoiding_their_union(prove, form):
    """`always A and always B` is `always (A and B)`: both obstacles become one U."""
    prop = property_of(prove)
    assert prop.form == form
    unsafe = prop.role("unsafe")
    assert inside(unsafe, "-1.5", "-1.5") and inside(unsafe, "1.5", "-1.5")
    assert not inside(unsafe, "0", "0") and not inside(unsafe, "1.5", "1.5")


def test_the_merged_property_keeps_the_words_the_user_wrote():
    prop = property_of("from I: always not U and always not V")
    assert "always not U" in prop.text and "always not V" in prop.text


def test_a_goal_that_touches_the_avoided_set_is_refused_with_a_witness():
    result = checked("from I: always not U and eventually (U or G)")
    assert not result.ok
    assert "goal" in result.render() and "12:" in result.render()


@pytest.mark.parametrize("prove", ["from I: stable and eventually G",
                                   "from I: always eventually G",
                                   "from I: not U until eventually G",
                                   "from I: (not U until G) and always not V"])
def test_formulas_with_no_certificate_stay_errors(prove):
    result = checked(prove)
    assert not result.ok and "unsupported property" in result.render()


@pytest.mark.parametrize("name", ["probe73/aw01_pendulum_reach_never_obstacle.fsl",
                                  "probe73/aw02_map_reach_then_remain.fsl",
                                  "probe73/aw03_cart_eventually_settle_ctrl.fsl"])
def test_equivalent_forms_are_certified_end_to_end(name):
    result = fossil_dsl.synthesise(fossil_dsl.load(SPECS / name), timeout=120)
    assert result.certified, result.reason
    roles = result.to_json()["property"]["roles"]  # how the letters were filled in
    assert {"initial", "safe", "unsafe", "final"} <= roles.keys()
    if name.endswith("aw01_pendulum_reach_never_obstacle.fsl"):
        assert roles["final"] == roles["safe"] == "~U"


@pytest.mark.parametrize("name", ["false/f118_pendulum_swing_through_obstacle.fsl",
                                  "false/f119_center_never_settles.fsl"])
def test_false_equivalent_forms_are_not_certified(name):
    result = fossil_dsl.synthesise(fossil_dsl.load(SPECS / name), timeout=20)
    assert not result.certified


def test_reach_avoid_remain_beside_an_obstacle_is_the_linearisations_ellipse():
    """probe73/aw30: the ellipse holding I misses U; the floor of x^T P x on U's ball was
    λmin(P) gap^2 before session 73, below the ellipse's level, and the seed refused."""
    spec = fossil_dsl.load(SPECS / "probe73/aw30_map_reach_avoid_never.fsl")
    result = fossil_dsl.synthesise(spec, timeout=60)
    assert result.certified and "linearisation" in result.strategy


def test_two_limits_written_as_two_nots_are_certified_end_to_end():
    """probe74/ax04: `not eventually hot and not eventually cold`, refused as an
    unsupported property before session 74; now safety with U = hot | cold."""
    result = fossil_dsl.synthesise(
        fossil_dsl.load(SPECS / "probe74/ax04_reactor_neither_hot_nor_cold.fsl"), timeout=60)
    assert result.certified, result.reason
    unsafe = result.to_json()["property"]["roles"]["unsafe"]
    assert "hot" in unsafe and "cold" in unsafe


def test_an_orbit_through_the_second_obstacle_is_not_certified():
    result = fossil_dsl.synthesise(
        fossil_dsl.load(SPECS / "false/f122_rotation_through_pit_two_obstacles.fsl"),
        timeout=20)
    assert not result.certified
