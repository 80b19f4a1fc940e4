"""A stability-type property of an unstable origin is refuted before anything is searched
for (engine/unstable_origin.py): NOT CERTIFIED at once, with the eigenvalue that makes it
false; nothing is refuted where the argument does not hold (a field not differentiable at
the origin, an eigenvalue on the boundary, inputs), and no true spec is refuted."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

import fossil_dsl
from fossil_dsl.engine.unstable_origin import refutation
from fossil_dsl.plan.compile import compile_spec

ROOT = Path(__file__).resolve().parent.parent

UNSTABLE = ["f01_unstable", "f07_tanh_marginal", "f20_van_der_pol_unstable",
            "f27_tanh_map_gain", "f127_competition_exclusion_not_stable_3d",
            "f128_expanding_map_not_stable", "f130_strong_tanh_self_excitation_not_stable"]


def _plan(text: str):
    return compile_spec(fossil_dsl.loads(text))


def _system(equations: str, time: str = "continuous", prove: str = "prove stable") -> str:
    return (f"state x, y\ndynamics {time} {{\n{equations}\n}}\n"
            f"domain box([-1, -1], [1, 1])\nset I = ball([0.2, 0], 0.1)\n{prove}\n")


@pytest.mark.parametrize("name", UNSTABLE)
def test_false_specs_with_an_unstable_origin_are_refuted(name):
    plan = compile_spec(fossil_dsl.load(ROOT / f"specs/false/{name}.fsl"))
    assert "the origin is unstable" in refutation(plan)


def test_a_refuted_run_stops_at_once_and_says_why(tmp_path):
    spec = fossil_dsl.load(ROOT / "specs/false/f128_expanding_map_not_stable.fsl")
    result = fossil_dsl.synthesise(spec, timeout=120)
    assert not result.certified and result.iterations == 0
    assert "eigenvalue 1.05 of modulus 1.05 > 1" in result.reason
    assert result.total_seconds < 5
    result.save(tmp_path)
    data = json.loads((tmp_path / "result.json").read_text())
    assert data["verdict"] == "not certified" and data["functions"] == {}
    loaded = fossil_dsl.load_result(tmp_path)
    assert not loaded.certified and "the origin is unstable" in loaded.reason
    recheck = subprocess.run([sys.executable, "-m", "fossil_dsl.frontends.cli", "recheck",
                              str(tmp_path)], capture_output=True, text=True)
    assert recheck.returncode == 2 and "nothing to re-prove" in recheck.stderr
    assert "Traceback" not in recheck.stderr


def test_the_command_line_prints_the_refutation_and_exits_1():
    run = subprocess.run([sys.executable, "-m", "fossil_dsl.frontends.cli",
                          str(ROOT / "specs/false/f127_competition_exclusion_not_stable_3d.fsl")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1, run.stdout + run.stderr
    assert "NOT CERTIFIED" in run.stdout and "with positive real part" in run.stdout


def test_every_property_that_claims_the_origin_attracts_is_refuted():
    unstable = "    x' = 0.1*x + y\n    y' = -x + 0.1*y"
    for prove in ("prove stable", "prove from I: stable",
                  "set U = { x >= 0.8 }\nprove from I: stable and always not U"):
        assert refutation(_plan(_system(unstable, prove=prove))) is not None, prove
    # reach and safety say nothing of the origin's stability
    assert refutation(_plan(_system(unstable, prove="set U = { x >= 0.8 }\n"
                                                    "prove from I: always not U"))) is None


def test_nothing_is_refuted_on_the_boundary_or_without_a_derivative():
    centre = "    x' = y\n    y' = -x - y^3"  # eigenvalues +-i: asymptotically stable
    assert refutation(_plan(_system(centre))) is None
    rotation = "    next(x) = 0.8*x - 0.6*y\n    next(y) = 0.6*x + 0.8*y"  # modulus 1
    assert refutation(_plan(_system(rotation, time="discrete"))) is None
    kink = "    x' = abs(x) + 0.5*x\n    y' = -y"  # no derivative at 0
    assert refutation(_plan(_system(kink))) is None
    root = "    x' = -x + sqrt(x^2 + y^2)\n    y' = -y"
    assert refutation(_plan(_system(root))) is None
    shifted = "    x' = sqrt(1 + x) - 1 + 0.5*x\n    y' = -y"  # smooth at 0: slope 1
    assert refutation(_plan(_system(shifted))) is not None


def test_a_system_with_inputs_is_left_to_the_controller():
    text = ("state x, y\ninput u\ndynamics continuous {\n    x' = x + y\n    y' = u\n}\n"
            "domain box([-1, -1], [1, 1])\nprove stable\n")
    assert refutation(_plan(text)) is None


def test_no_true_stability_spec_is_refuted():
    folders = ("literature", "benchmarks", "discrete", "probe74", "probe75")
    paths = [p for folder in folders for p in sorted((ROOT / "specs" / folder).glob("*.fsl"))]
    checked = 0
    for path in paths:
        plan = compile_spec(fossil_dsl.load(path))
        checked += plan.certificate.form in ("stability", "region of attraction",
                                             "stable while avoid")
        assert refutation(plan) is None, path.name
    assert checked > 30


def test_a_marginal_linearisation_is_named_where_a_run_is_not_certified():
    from fossil_dsl.engine.unstable_origin import marginal_note
    pendulum = ROOT / "specs/probe75/ay29_cubic_damped_pendulum_marginal_stable.fsl"
    note = marginal_note(compile_spec(fossil_dsl.load(pendulum)))
    assert "on the imaginary axis (0 + 1i, 0 - 1i)" in note
    rotation = "    next(x) = 0.8*x - 0.6*y\n    next(y) = 0.6*x + 0.8*y"
    assert "on the unit circle" in marginal_note(_plan(_system(rotation, time="discrete")))
    damped = ROOT / "specs/probe75/ay06_atan_damped_pendulum_stable.fsl"
    assert marginal_note(compile_spec(fossil_dsl.load(damped))) is None
    result = fossil_dsl.synthesise(fossil_dsl.load(pendulum), max_iters=1, timeout=30)
    assert not result.certified and "no quadratic V decreases strictly" in result.reason
