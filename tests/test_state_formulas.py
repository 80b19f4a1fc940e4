"""Sets combined inside a `prove` formula (`always not (rock or pit)`): the property's
roles are the combined sets, and the checker's relations are proved on them."""
from __future__ import annotations

from fractions import Fraction

import pytest

from fossil_dsl import check_text
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.atoms import folded

HEADER = """\
state x, y
dynamics continuous {
    x' = -x
    y' = -2*y
}
domain box([-3, -3], [3, 3])
set init = ball([1.5, 1.5], 0.3)
set rock = ball([-1, 1], 0.4)
set pit = ball([1, -1], 0.4)
set goal = ball([0, 0], 0.3)
set lane = { y <= 2.5 }
"""


def spec_of(prove: str):
    result = check_text(HEADER + f"prove from init: {prove}\n")
    assert result.ok, result.render()
    return result.spec


def inside(region: S.SetExpr, x: str, y: str) -> bool:
    point = {"x": E.Num(Fraction(x)), "y": E.Num(Fraction(y))}
    decided = L.truth(folded(L.substitute(region.contains_formula(("x", "y")), point), ()))
    assert decided is not None, "exact rationals decide membership"
    return decided


@pytest.mark.parametrize("prove", [
    "always not (rock or pit)",
    "always (not rock and not pit)",
    "always not (pit or rock)",
    "not (eventually (rock or pit))",
])
def test_a_union_of_obstacles_is_the_unsafe_set(prove):
    prop = spec_of(prove).property
    assert prop.form == "safety"
    unsafe = prop.role("unsafe")
    assert inside(unsafe, "-1", "1") and inside(unsafe, "1", "-1")
    assert not inside(unsafe, "0", "0") and not inside(unsafe, "1.5", "1.5")
    assert inside(prop.role("safe"), "0", "0") and not inside(prop.role("safe"), "-1", "1")


def test_goal_and_safe_set_as_combinations():
    prop = spec_of("(lane and not rock) until (goal or pit)").property
    assert prop.form == "reach while avoid"
    assert inside(prop.role("goal"), "0", "0") and inside(prop.role("goal"), "1", "-1")
    assert not inside(prop.role("goal"), "2", "2")
    safe = prop.role("safe")
    assert inside(safe, "1.5", "1.5") and not inside(safe, "-1", "1")
    assert not inside(safe, "0", "2.8")  # outside the lane


def test_set_conjuncts_beside_always_join_into_one_goal():
    spec = check_text(HEADER + "set final = ball([0, 0], 0.5)\n"
                      "prove from init: not rock until (goal and lane and always final)\n")
    assert spec.ok, spec.render()
    assert spec.spec.property.form == "reach-avoid-remain"


def test_relations_are_proved_on_the_combination():
    """init meets `rock or init`: I and U are not disjoint, so the spec is refused."""
    result = check_text(HEADER.replace("set pit = ball([1, -1], 0.4)",
                                       "set pit = ball([1.5, 1.2], 0.4)")
                        + "prove from init: always not (rock or pit)\n")
    assert not result.ok
    assert any("disjoint" in d.message or "unsafe" in d.message for d in result.errors), \
        result.render()


@pytest.mark.parametrize("prove", [
    "always (rock or eventually pit)",
    "always not (rock or stable)",
])
def test_combinations_with_temporal_parts_stay_outside_the_table(prove):
    result = check_text(HEADER + f"prove from init: {prove}\n")
    assert not result.ok
    assert any("unsupported property" in d.message for d in result.errors)
