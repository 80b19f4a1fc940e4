"""`synthesis { region: largest }` (issue 25): the largest level the kernel proves for
the learned V, and how much of D and of the simulated basin its region covers."""
from __future__ import annotations

import json
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import fossil_dsl
from fossil_dsl.engine.region import largest_level
from fossil_dsl.kernel import Claim

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "specs" / "roa_largest.fsl"


def test_the_largest_level_is_proved_by_the_kernel_and_reported(tmp_path):
    result = fossil_dsl.synthesise(fossil_dsl.load(SPEC))
    assert result.certified and result.region
    region = result.region
    level = Fraction(region["level"])
    assert result.levels["beta"] == level
    proved = [Fraction(t["beta"]) for t in region["levels_tried"] if t["proved"]]
    refused = [Fraction(t["beta"]) for t in region["levels_tried"] if not t["proved"]]
    assert proved and max(proved) == level and all(b > level for b in refused)
    assert level <= region["level_upper_bound"] + 1e-9  # V > beta on the boundary of D
    assert 0 < region["share_of_domain"] <= 1 and 0 < region["basin_coverage"] <= 1
    assert region["region_points_not_converging"] == 0
    # the V shaped to the simulated basin (engine/basin.py) reaches near the limit cycle:
    # a quadratic from the linearisation covered 46 % of the basin
    assert "shaped to the simulated basin" in result.strategy
    assert region["basin_coverage"] >= 0.9
    assert "the largest level the kernel proved" in result.summary()
    result.save(tmp_path)
    assert json.loads((tmp_path / "result.json").read_text())["region"] == region
    again = fossil_dsl.load_result(tmp_path)  # judged afresh at the enlarged level
    assert again.certified and again.levels["beta"] == level and again.region == region
    figure = result.plot(tmp_path / "portrait.png")
    labels = [text.get_text() for text in figure.axes[0].get_legend().get_texts()]
    assert any(label.startswith("certified Ω") for label in labels), labels


@dataclass(frozen=True)
class Said:
    """What a stand-in judge says (only the kernel can make a certified Verdict)."""
    certified: bool
    reason: str


class Threshold:
    """A stand-in judge that accepts exactly the levels up to 1/2."""

    def __init__(self):
        self.asked = []

    def __call__(self, claim: Claim) -> Said:
        beta = claim.levels["beta"]
        self.asked.append(beta)
        accepted = beta <= Fraction(1, 2)
        return Said(accepted, f"{'proved' if accepted else 'not'} at {beta}")


def test_bisection_returns_only_a_level_its_judge_proved():
    spec = fossil_dsl.load(SPEC)
    claim = Claim(spec, {"V": _quadratic()}, {}, {"beta": Fraction(1, 10)})
    judge = Threshold()
    found = largest_level(claim, Said(True, "start"), judge, deadline=float("inf"))
    assert found.level <= Fraction(1, 2) and found.level in judge.asked
    assert Fraction(1, 2) - found.level < Fraction(1, 50)
    assert found.verdict.reason == f"proved at {found.level}"


def _quadratic():
    from fossil_dsl.ir import expr as E
    x0, x1 = E.Var("x0"), E.Var("x1")
    return E.add(E.mul(x0, x0), E.mul(x1, x1))


def test_region_is_only_for_a_region_of_attraction():
    text = SPEC.read_text().replace("prove from init: stable", "prove stable")
    checked = fossil_dsl.check_text(text, "stable.fsl")
    assert not checked.ok
    assert "`region: largest` enlarges a region of attraction" in checked.render()
    assert "stable.fsl:13:13" in checked.render()
    wrong = fossil_dsl.check_text(SPEC.read_text().replace("largest", "huge"), "huge.fsl")
    assert "`region` takes `largest`" in wrong.render() and "huge.fsl:13:21" in wrong.render()
