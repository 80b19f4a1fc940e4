"""Every property form end to end, with and without a controller; false properties of each
kind never certified; verifier-only and learner-only modes; `compile --explain`; and a
certificate defined outside the package."""
import json
import re
from fractions import Fraction
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

import fossil_dsl
from fossil_dsl.plan.certificates import base as certificate_registry
from fossil_dsl.check import properties
from fossil_dsl.kernel import guarantee_text
from fossil_dsl.kernel import registry as kernel_obligations
from fossil_dsl.plan.compile import compile_spec
from fossil_dsl.outputs.result import write_artefacts
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.cvc5_backend import Cvc5Backend
from fossil_dsl.solvers.z3_backend import Z3Backend

ROOT = Path(__file__).resolve().parent.parent
FOSSILC = Path(sys.executable).with_name("fossilc")
OTHER_SOLVER = {"z3": Cvc5Backend, "cvc5": Z3Backend}

PROPERTIES = ["roa", "swa", "rwa", "reach", "rswa", "rar"]
FORM_OF = {"roa": "region of attraction", "swa": "stable while avoid",
           "rwa": "reach while avoid", "reach": "reach", "rswa": "reach and stay while avoid",
           "rar": "reach-avoid-remain", "stability": "stability", "safety": "safety"}
DISCRETE = ["roa", "swa", "rwa", "reach", "rswa", "rar"]  # with stability and safety below
AUTONOMOUS = [f"{p}_continuous" for p in PROPERTIES] + [f"{p}_discrete" for p in DISCRETE]
CONTROLLED = [f"{p}_controlled" for p in PROPERTIES] + [
    f"{p}_discrete_controlled" for p in DISCRETE] + [
    "stability_controlled", "stability_discrete_controlled", "safety_controlled",
    "safety_discrete_controlled"]


def spec_file(name: str):
    return fossil_dsl.load(ROOT / "specs" / f"{name}.fsl")


def spec_text(text: str):
    return fossil_dsl.loads(text, "test.fsl")


@pytest.mark.parametrize("name", AUTONOMOUS + CONTROLLED)
def test_property_certified_end_to_end(name, tmp_path):
    spec = spec_file(name)
    assert spec.property.form == FORM_OF[name.split("_")[0]]
    result = fossil_dsl.synthesise(spec, seed=0)
    assert result.certified, result.reason
    assert all(c.status == "unsat" for c in result.conditions)
    # every learned function is reported, and the controller where there is one
    assert set(result.formulas) == {f.name for f in result.plan.functions}
    assert bool(result.controller) == (name in CONTROLLED)
    assert set(result.levels) == {level.name for level in result.plan.levels}
    # the exported obligations (closed loop substituted) are UNSAT for another solver
    write_artefacts(result, tmp_path)
    if result.plan.verifier in OTHER_SOLVER:
        other = OTHER_SOLVER[result.plan.verifier]()
        for path in sorted((tmp_path / "obligations").glob("*.smt2")):
            assert other.check_text(path.read_text(), timeout=60).status is Status.UNSAT, \
                path.name
    else:  # sin, exp: `fossilc recheck`'s procedures for transcendental obligations
        from fossil_dsl.outputs.recheck import recheck
        assert all(check.reproved for check in recheck(tmp_path, timeout=60))
    exported = json.loads((tmp_path / "result.json").read_text())
    assert exported["controller"] == {u: str(k) for u, k in result.controller.items()}
    assert exported["levels"] == {n: str(v) for n, v in result.levels.items()}
    assert_loads_back(result, tmp_path)
    assert_onnx_agrees(result, tmp_path)


def assert_loads_back(result, folder):
    """run -> save -> load_result -> the same result, judged again by the kernel."""
    loaded = fossil_dsl.load_result(folder)
    assert loaded.certified and loaded.kernel.certified
    assert loaded.formulas == result.formulas and loaded.controller == result.controller
    assert loaded.levels == result.levels and loaded.digits == result.digits
    assert loaded.plan.spec.property.form == result.plan.spec.property.form
    assert loaded.plan.options.seed == result.plan.options.seed
    assert loaded.conditions == result.conditions and loaded.obligations == result.obligations
    assert loaded.guarantee() == result.guarantee()
    assert loaded.sympy == result.sympy
    points = torch.rand(20, len(result.plan.states), dtype=torch.float64)
    for name, network in result.networks.items():
        assert torch.allclose(loaded.networks[name](points), network(points)), name


def assert_onnx_agrees(result, folder, count=200):
    """certificate.onnx (and controller.onnx) evaluated by ONNX Runtime at random points
    of the domain's box agree with the exact formulas to 1e-6 relative."""
    import onnxruntime
    from fossil_dsl.engine.evaluate import evaluate
    low, high = (torch.tensor(side, dtype=torch.float64)
                 for side in result.plan.spec.domain.bounding_box())
    points = low + (high - low) * torch.rand(count, len(low), dtype=torch.float64)
    env = {s: points[:, i] for i, s in enumerate(result.plan.states)}
    for file, formulas in (("certificate.onnx", result.formulas),
                           ("controller.onnx", result.controller)):
        if not formulas:
            assert not (folder / file).exists()
            continue
        session = onnxruntime.InferenceSession(str(folder / file))
        values = session.run(None, {"x": points.numpy()})[0]
        for column, formula in enumerate(formulas.values()):
            exact = (evaluate(formula, env) * torch.ones(count, dtype=torch.float64)).numpy()
            scale = np.maximum(np.abs(exact), 1.0)
            assert (np.abs(values[:, column] - exact) <= 1e-6 * scale).all(), (file, column)


def test_two_function_certificates_report_both():
    for name in ("swa_continuous", "rar_continuous"):
        plan = compile_spec(spec_file(name))
        assert [f.name for f in plan.functions] == ["V", "B"]
        assert any(c.name.startswith("barrier_") for c in plan.conditions)


def test_controller_keeps_the_equilibrium_where_stability_needs_it():
    stable = compile_spec(spec_file("roa_controlled"))
    reach = compile_spec(spec_file("rwa_controlled"))
    assert stable.controller.zero_at_origin and not reach.controller.zero_at_origin
    result = fossil_dsl.synthesise(spec_file("stability_controlled"), seed=0)
    from fossil_dsl.ir import expr as E
    from fossil_dsl.ir import traversal
    at_origin = traversal.substitute(result.controller["u0"], {"x0": E.ZERO, "x1": E.ZERO})
    assert at_origin == E.ZERO


# ---- false properties of every kind: never certified, whatever the seed ------------------
FALSE_PROPERTIES = {
    "saddle-origin": """\
state x0, x1
dynamics continuous {
    x0' = x0 + x1
    x1' = -x1
}
domain ball([0, 0], 1)
prove stable
""",
    "expanding-map": """\
state x0, x1
dynamics discrete {
    next(x0) = 1.1*x0
    next(x1) = 0.5*x1
}
domain box([-1, -1], [1, 1])
prove stable
""",
    "flow-into-unsafe": """\
state x0, x1
dynamics continuous {
    x0' = 1
    x1' = -x1
}
domain box([-2, -2], [2, 2])
set init = box([-0.5, -0.5], [0, 0.5])
set unsafe = box([1, -2], [2, 2])
prove from init: always not unsafe
""",
    "map-into-unsafe": """\
state x0, x1
dynamics discrete {
    next(x0) = x0 + 0.5
    next(x1) = 0.5*x1
}
domain box([-2, -2], [2, 2])
set init = box([-0.5, -0.5], [0, 0.5])
set unsafe = box([1, -2], [2, 2])
prove from init: always not unsafe
""",
    # trajectories converge to the origin; the goal is elsewhere
    "goal-never-reached": """\
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-1, -1], [1, 1])
set init = box([-0.8, -0.8], [-0.5, -0.5])
set goal = ball([0.6, 0.6], 0.1)
prove from init: eventually goal
""",
    # a centre: trajectories circle for ever at radius 0.5 to 0.7
    "circling-never-reaches": """\
state x0, x1
dynamics continuous {
    x0' = x1
    x1' = -x0
}
domain box([-2, -2], [2, 2])
set safe = box([-1.5, -1.5], [1.5, 1.5])
set init = box([0.5, -0.1], [0.7, 0.1])
set goal = ball([0, 0], 0.2)
prove from init: safe until goal
""",
    # the region of attraction is |x0| < 1, and init reaches x0 = 1.1
    "init-outside-roa": """\
state x0, x1
dynamics continuous {
    x0' = -x0 + x0^3
    x1' = -x1
}
domain box([-1.5, -1.5], [1.5, 1.5])
set init = ball([0, 0], 1.1)
prove from init: stable
""",
    # trajectories pass through `final` on their way to the origin, outside it
    "final-set-left": """\
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-2, -2], [2, 2])
set unsafe = box([1.6, -2], [2, 2])
set init = box([-1.2, -0.1], [-1, 0.1])
set final = ball([-0.6, 0], 0.3)
prove from init: not unsafe until always final
""",
    # a centre: from the goal, trajectories circle out of `final`
    "remain-fails": """\
state x0, x1
dynamics continuous {
    x0' = x1
    x1' = -x0
}
domain box([-2, -2], [2, 2])
set unsafe = box([1.6, -2], [2, 2])
set init = ball([0.5, 0], 0.05)
set goal = ball([0.5, 0], 0.1)
set final = ball([0.5, 0], 0.2)
prove from init: not unsafe until (goal and always final)
""",
    # x0 is unstable and no input reaches it
    "uncontrollable-roa": """\
state x0, x1
input u0
dynamics continuous {
    x0' = x0
    x1' = u0
}
domain box([-1, -1], [1, 1])
set init = ball([0, 0], 0.5)
prove from init: stable
""",
}


FALSE_PROPERTIES["init-outside-roa-swa"] = FALSE_PROPERTIES["init-outside-roa"].replace(
    "prove from init: stable", "set unsafe = box([1.3, 1.3], [1.5, 1.5])\n"
    "prove from init: stable and always not unsafe")


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("name", FALSE_PROPERTIES)
def test_false_property_is_never_certified(name, seed):
    result = fossil_dsl.synthesise(spec_text(FALSE_PROPERTIES[name]), seed=seed, max_iters=2,
                                   learn_steps=300, query_timeout=5)
    assert not result.certified
    assert result.exit_code == 1 and result.guarantee() == "nothing is proved"
    # an unstable origin's stability is refuted before anything is searched for
    refuted = "the origin is unstable" in result.reason
    assert refuted == (name in ("saddle-origin", "expanding-map")), result.reason
    assert refuted or any(c.status != "unsat" for c in result.conditions)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [3, 4])
@pytest.mark.parametrize("name", FALSE_PROPERTIES)
def test_false_property_survives_a_full_run(name, seed):
    result = fossil_dsl.synthesise(spec_text(FALSE_PROPERTIES[name]), seed=seed,
                                   query_timeout=10, timeout=300)
    assert not result.certified


# ---- verifier-only ------------------------------------------------------------------
ROA_LINEAR = """\
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-1, -1], [1, 1])
set init = ball([0, 0], 0.5)
set unsafe = box([0.6, 0.6], [0.9, 0.9])
"""


def test_candidate_roa_certified_with_its_level():
    result = fossil_dsl.synthesise(spec_text(
        ROA_LINEAR + "prove from init: stable\nsynthesis { candidate: x0^2 + x1^2 }\n"))
    assert result.certified and result.iterations == 1
    # β lies between max V on I (1/4) and min V on the boundary of D (1)
    assert 0.25 < result.levels["beta"] < 1


def test_wrong_second_candidate_is_rejected_with_a_counterexample():
    result = fossil_dsl.synthesise(spec_text(
        ROA_LINEAR + "prove from init: stable and always not unsafe\n"
        "synthesis {\n    candidate: x0^2 + x1^2\n    candidate2: 1 - x0\n}\n"))
    assert not result.certified and result.iterations == 1
    failing = {c.name: c for c in result.conditions if c.status == "sat"}
    assert "barrier_initial" in failing and "positive" not in failing
    x0, x1 = (float(v) for v in failing["barrier_initial"].counterexample)
    assert x0 ** 2 + x1 ** 2 <= 0.25 + 1e-9 and 1 - x0 > 0  # in I, and B > 0 there


def test_wrong_reach_candidate_fails_with_a_counterexample_in_the_cli(tmp_path):
    path = tmp_path / "rwa.fsl"
    path.write_text(ROA_LINEAR + "set goal = ball([0, 0], 0.1)\n"
                    "prove from init: eventually goal\nsynthesis { candidate: x0 }\n")
    run = subprocess.run([str(FOSSILC), str(path), "-q"], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 1, run.stderr
    assert re.search(r"\[fails\] V\(x\) <= 0 for every x in I at \(", run.stdout)


# ---- learner-only -----------------------------------------------------------------------
def test_learn_only_reports_violation_rates_and_proves_nothing(tmp_path):
    run = subprocess.run([str(FOSSILC), str(ROOT / "specs" / "swa_controlled.fsl"),
                          "--learn-only", "-q", "-o", str(tmp_path)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 1, run.stderr
    assert "NOTHING WAS PROVED" in run.stdout and "no verifier" in run.stdout
    rates = re.findall(r"(\d+) of (\d+) fresh samples violate it", run.stdout)
    assert len(rates) == 7 and all(int(a) <= int(b) for a, b in rates)
    assert sum(int(b) for _, b in rates) > 0
    data = json.loads((tmp_path / "result.json").read_text())
    assert data["learn_only"] and data["verdict"] == "not certified"
    assert {c["status"] for c in data["conditions"]} == {"not verified"}


def test_learn_only_counts_a_condition_it_violates():
    spec = spec_text(ROA_LINEAR + "prove from init: stable\nsynthesis { candidate: x0^2 - x1^2 }\n")
    result = fossil_dsl.synthesise(spec, learn_only=True)
    positive = next(c for c in result.conditions if c.name == "positive")
    fails, total = map(int, re.search(r"(\d+) of (\d+)", positive.reason).groups())
    assert 0 < fails <= total


def test_learn_only_judges_an_escapable_guard_where_it_holds(monkeypatch):
    """A fresh sample just outside {B <= 0} (in the band trained on, where training lets
    it escape) is not a violation of "B(f(x)) <= 0 where B(x) <= 0"; one inside is."""
    from fossil_dsl.engine import learner as learning
    from fossil_dsl.engine.linear import set_quadratic
    spec = spec_text("state x0, x1\ndynamics discrete {\n    next(x0) = 1.5*x0\n"
                     "    next(x1) = 1.5*x1\n}\ndomain box([-2, -2], [2, 2])\n"
                     "set init = box([-0.1, -0.1], [0.1, 0.1])\n"
                     "set unsafe = box([1.8, -2], [2, 2])\nprove from init: always not unsafe\n")
    plan = compile_spec(spec, learn_only=True)
    learner = learning.Learner(plan, torch.Generator().manual_seed(0))
    set_quadratic(learner.networks["B"], np.eye(2), 1.0)  # B = |x|^2 - 1
    points = torch.tensor([[1.01, 0.0], [0.9, 0.0]], dtype=torch.float64)
    monkeypatch.setattr(learning, "sample", lambda *args, **kwargs: points)
    # both steps land where B > 0; only the second starts where B <= 0
    assert learner.violation_rates(torch.Generator())["invariance"] == (1, 1)


# ---- compile --explain ------------------------------------------------------------------
@pytest.mark.parametrize("name", AUTONOMOUS + ["stability_continuous", "safety_continuous"])
def test_compile_explain_names_certificate_conditions_and_guarantee(name):
    run = subprocess.run([str(FOSSILC), "compile", str(ROOT / "specs" / f"{name}.fsl"),
                          "--explain"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    plan = compile_spec(spec_file(name))
    assert f"certificate: {plan.certificate.title}" in run.stdout
    for condition in plan.conditions:
        assert f"[{condition.name}] {condition.text}" in run.stdout
    assert "guarantee, once every obligation is proved: " + guarantee_text(plan.spec, 0, False) \
        in run.stdout
    for level in plan.levels:
        assert level.text in run.stdout


# ---- a certificate defined outside the package (docs/extending.md) -----------------------
@pytest.fixture
def registries():
    forms = list(properties.FORMS)
    rules = dict(certificate_registry.CERTIFICATES)
    kernel_rules = dict(kernel_obligations.RULES)
    guarantees = dict(kernel_obligations.GUARANTEES)
    yield
    kernel_obligations.RULES.clear()
    kernel_obligations.RULES.update(kernel_rules)
    kernel_obligations.GUARANTEES.clear()
    kernel_obligations.GUARANTEES.update(guarantees)
    properties.FORMS[:] = forms
    certificate_registry.CERTIFICATES.clear()
    certificate_registry.CERTIFICATES.update(rules)


def python_blocks(path: Path) -> str:
    return "\n".join(re.findall(r"```python\n(.*?)```", path.read_text(), re.S))


def test_user_defined_certificate_from_the_docs(registries, capsys):
    namespace = {}
    exec(python_blocks(ROOT / "docs" / "extending.md"), namespace)  # noqa: S102 (our docs)
    assert namespace["result"].certified
    assert "reach-and-stay certificate" in capsys.readouterr().out
    # the new form is now part of the language, for the checker and the CLI alike
    spec = spec_text(FALSE_PROPERTIES["goal-never-reached"].replace(
        "eventually goal", "always eventually goal"))
    assert spec.property.form == "recurrence"
    assert not fossil_dsl.synthesise(spec, max_iters=2, learn_steps=300).certified


def test_certificate_passed_for_one_run_only(registries):
    from fossil_dsl.plan.certificates.lyapunov import Lyapunov
    from fossil_dsl.extend import Condition, change_of, expr, logic, value_of

    class FastDecrease(Lyapunov):
        title = "Lyapunov function with dV/dt <= -V/10"

        def conditions(self):
            decrease = Condition("fast_decrease", "dV/dt <= -V/10 on D", self.spec.domain,
                                 logic.Compare("<=", change_of("V"), expr.mul(
                                     expr.lift(Fraction(-1, 10)), value_of("V"))))
            return super().conditions() + (decrease,)

    spec = spec_file("stability_continuous")
    result = fossil_dsl.synthesise(spec, certificate=FastDecrease, seed=0)
    assert result.plan.certificate.title == FastDecrease.title
    assert "fast_decrease" in {c.name for c in result.conditions}
    assert certificate_registry.CERTIFICATES["stability"] is Lyapunov
