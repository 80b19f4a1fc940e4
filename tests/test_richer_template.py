"""Where the compiler's quadratic templates give up, the loop learns again with quartic
ones (engine/learning.py): probe70/at17's goal lies round an equilibrium off the origin,
I far on one side and D's boundary near on the other, so no quadratic V reaches it."""
from pathlib import Path

import fossil_dsl
from fossil_dsl.outputs.result import write_artefacts
from fossil_dsl.ir.spec import Layer
from fossil_dsl.plan.compile import compile_spec, richer_plan

SPECS = Path(__file__).resolve().parent.parent / "specs"
THERMOSTAT = (SPECS / "probe70/at17_room_wall_thermostat_reach_tanh.fsl").read_text()


def test_quadratic_templates_become_quartic_and_a_chosen_one_stays():
    plan = compile_spec(fossil_dsl.loads(THERMOSTAT))
    assert plan.functions[0].layers == (Layer("square", 8),)
    assert richer_plan(plan).functions[0].layers == (Layer("poly4", 8),)
    chosen = THERMOSTAT + "synthesis { certificate: square(8) }\n"
    assert richer_plan(compile_spec(fossil_dsl.loads(chosen))) is None


def test_a_reach_no_quadratic_meets_is_certified_with_the_quartic_template(tmp_path):
    result = fossil_dsl.synthesise(fossil_dsl.loads(THERMOSTAT), max_iters=3, timeout=120)
    assert result.certified, result.reason
    assert result.strategy.startswith("learning with quartic templates")
    assert result.iterations > 3  # the quadratic template's three come first
    assert result.kernel.certified
    write_artefacts(result, tmp_path)
    again = fossil_dsl.load_result(tmp_path)
    assert again.certified and again.formulas == result.formulas


def test_a_false_reach_stays_uncertified_after_both_templates():
    """The room cannot reach a goal box above the equilibrium (T = 0.08): T' < 0 there."""
    unreachable = THERMOSTAT.replace("set goal = box([-0.1, -0.4], [0.25, 0.1])",
                                     "set goal = box([0.3, -0.4], [0.6, 0.1])")
    result = fossil_dsl.synthesise(fossil_dsl.loads(unreachable), max_iters=2, timeout=60)
    assert not result.certified
    assert "quartic templates" in result.strategy
