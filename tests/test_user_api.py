"""What users keep and drive (issue 7): artefacts, `fossilc recheck`, phase portraits,
the Python API (specs built in Python, bespoke sets, Result), and `fossilc import-yaml`."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp
import torch

import fossil_dsl
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.symbolic import SympyConversionError, from_sympy, to_sympy
from fossil_dsl.engine.evaluate import evaluate
from fossil_dsl.frontends.yaml_import import YamlImportError, import_yaml

ROOT = Path(__file__).resolve().parent.parent
STABLE = ROOT / "specs" / "stability_continuous.fsl"


def fossilc(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "fossil_dsl.frontends.cli", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, timeout=600)


@pytest.fixture(scope="module")
def stable_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("stable")
    run = fossilc(STABLE, "-o", out, "--plot", "-q")
    assert run.returncode == 0, run.stderr
    return out


# the default network named in the spec: learned (a sum-of-squares V is tried only where
# the spec leaves the template to the compiler)
LEARNED_TEXT = STABLE.read_text() + "\nsynthesis {\n    certificate: square(8)\n}\n"


@pytest.fixture(scope="module")
def learned_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("learned")
    spec = out / "stable_learned.fsl"
    spec.write_text(LEARNED_TEXT)
    run = fossilc(spec, "-o", out / "result", "-q")
    assert run.returncode == 0, run.stderr
    return out / "result"


# ---- artefacts ----------------------------------------------------------------
def test_result_json_schema_2_has_exact_weights_and_versions(learned_run):
    data = json.loads((learned_run / "result.json").read_text())
    assert data["schema"] == 3 and data["verdict"] == "certified"
    assert data["certificate_kind"] == "Lyapunov"
    assert {"torch", "z3-solver", "cvc5", "python"} <= set(data["versions"])
    layers = data["networks"]["V"]["layers"]
    weights = [Fraction(w) for layer in layers for row in layer["weight"] for w in row]
    assert weights and all((w * 10 ** 6).denominator == 1 for w in weights)
    assert layers[0]["activation"] == "square" and layers[-1]["activation"] == "identity"


def test_exact_weights_rebuild_the_reported_formula(learned_run):
    """The rationals in result.json are the network that the formula was built from."""
    data = json.loads((learned_run / "result.json").read_text())
    hidden, output = data["networks"]["V"]["layers"]
    x = [E.Var("x0"), E.Var("x1")]
    neurons = [E.power(E.add(*(E.mul(E.Num(Fraction(w)), v) for w, v in zip(row, x))),
                       E.Num(2)) for row in hidden["weight"]]
    rebuilt = E.add(*(E.mul(E.Num(Fraction(w)), n) for w, n in zip(output["weight"][0], neurons)))
    point = {"x0": torch.tensor([0.3, -0.7], dtype=torch.float64),
             "x1": torch.tensor([0.5, 0.2], dtype=torch.float64)}
    spec = fossil_dsl.loads(LEARNED_TEXT)
    reported = fossil_dsl.synthesise(spec, seed=spec.synthesis.seed or 0).formulas["V"]
    assert torch.allclose(evaluate(rebuilt, point), evaluate(reported, point), atol=1e-12)


def test_networks_pt_is_a_state_dict_per_network(learned_run):
    states = torch.load(learned_run / "networks.pt")
    assert set(states) == {"V"} and all(isinstance(t, torch.Tensor) for t in states["V"].values())


def test_recheck_reproves_every_obligation_with_another_solver(stable_run):
    run = fossilc("recheck", stable_run)
    assert run.returncode == 0, run.stdout + run.stderr
    data = json.loads((stable_run / "result.json").read_text())
    for obligation in data["kernel"]["obligations"]:
        stem = obligation["name"].replace(":", "-").replace(" ", "_")
        line = next(l for l in run.stdout.splitlines() if f"] {stem} " in l)
        assert "[re-proved]" in line and f"proved by {obligation['procedure']}" in line
        rechecker = re.search(r"rechecked by (\w+)", line).group(1)
        assert rechecker != obligation["procedure"]


def test_recheck_fails_a_tampered_obligation(stable_run, tmp_path):
    copy = tmp_path / "copy"
    subprocess.run(["cp", "-r", str(stable_run), str(copy)], check=True)
    obligation = copy / "obligations" / "condition-positive.smt2"
    # the kernel's scripts write V out: claim V(x) > 0 fails nowhere, i.e. assert false
    text = re.sub(r"\(assert .*\n", "(assert (> (* x0 x0) 1.0))\n", obligation.read_text())
    obligation.write_text(text)
    run = fossilc("recheck", copy)
    assert run.returncode == 1 and "[ALTERED] condition-positive" in run.stdout


def test_recheck_derives_the_obligations_from_the_spec(stable_run, tmp_path):
    """A run that leaves an obligation out does not pass: recheck derives the list
    itself, from the spec's text and the formulas in result.json."""
    copy = tmp_path / "copy"
    subprocess.run(["cp", "-r", str(stable_run), str(copy)], check=True)
    (copy / "obligations" / "neighbourhood.smt2").unlink()
    run = fossilc("recheck", copy)
    assert run.returncode == 1 and "[MISSING] neighbourhood" in run.stdout


def test_recheck_reads_the_formulas_back_exactly(stable_run, tmp_path):
    """Changing a formula in result.json changes the derived obligations, which then
    differ from the exported files."""
    copy = tmp_path / "copy"
    subprocess.run(["cp", "-r", str(stable_run), str(copy)], check=True)
    data = json.loads((copy / "result.json").read_text())
    data["functions"]["V"] = data["functions"]["V"] + " + x0^4"
    (copy / "result.json").write_text(json.dumps(data))
    run = fossilc("recheck", copy)
    assert run.returncode == 1 and "[ALTERED] condition-positive" in run.stdout


def test_recheck_of_a_missing_folder_is_a_clear_error(tmp_path):
    run = fossilc("recheck", tmp_path / "nothing")
    assert run.returncode == 2 and "cannot read result.json" in run.stderr
    assert "Traceback" not in run.stderr


# ---- pictures ------------------------------------------------------------------
def test_plot_writes_png_and_svg(stable_run):
    assert (stable_run / "phase_portrait.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "<svg" in (stable_run / "phase_portrait.svg").read_text()[:1000]


def test_portrait_draws_sets_contours_and_trajectories():
    spec = fossil_dsl.load(ROOT / "specs" / "safety_continuous.fsl")
    result = fossil_dsl.synthesise(spec, seed=0)
    figure = result.plot()
    ax = figure.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"domain", "init", "unsafe"} <= set(labels) and "B = 0" in labels
    assert len(ax.lines) >= 10  # trajectories (and legend proxies)


def test_portrait_of_a_three_state_spec_has_three_slices():
    spec = fossil_dsl.load(ROOT / "specs" / "benchmarks" / "row01_stability_nonpoly2.fsl")
    figure = fossil_dsl.synthesise(spec, seed=0).plot()
    assert len(figure.axes) == 3 and "slice" in figure.axes[0].get_title()


def test_portrait_of_more_states_is_a_clear_error(tmp_path):
    run = fossilc(ROOT / "specs" / "benchmarks" / "row04_safety_hi_ord_8.fsl", "--plot", "-q",
                  "-o", tmp_path)
    assert run.returncode == 2 and "2- and 3-state specs" in run.stderr


# ---- the Python API --------------------------------------------------------------
x0, x1 = sp.symbols("x0 x1", real=True)


class Disc(fossil_dsl.BespokeSet):
    box = ([-0.3, 0.2], [0.3, 0.8])
    calls = 0

    def constraints(self, x):
        return [x[0] ** 2 + (x[1] - sp.Rational(1, 2)) ** 2 <= sp.Rational(9, 100)]

    def sample(self, count, generator):
        Disc.calls += 1
        r = 0.3 * torch.rand(count, generator=generator, dtype=torch.float64).sqrt()
        t = 2 * torch.pi * torch.rand(count, generator=generator, dtype=torch.float64)
        return torch.stack([r * t.cos(), 0.5 + r * t.sin()], 1)


def field(x, u):
    return torch.stack([x[:, 1], -x[:, 0] - x[:, 1] + x[:, 0] ** 3 / 3], 1)


def built(**changes):
    arguments = dict(name="built", states=[x0, x1],
                     dynamics=[x1, -x0 - x1 + sp.Rational(1, 3) * x0 ** 3],
                     domain="box([-2, -2], [2, 2])",
                     sets={"init": Disc(), "unsafe": "ball([-1.5, -1.5], 0.3)"},
                     prove="from init: always not unsafe",
                     synthesis={"certificate": "square(5)"}, torch_dynamics=field)
    arguments.update(changes)
    return fossil_dsl.build_spec(**arguments)


def test_spec_built_in_python_with_a_bespoke_set_is_certified():
    Disc.calls = 0
    result = fossil_dsl.synthesise(built(), seed=0)
    assert result.certified and Disc.calls >= 1  # the set's own sampler fed the learner
    B = result.sympy["B"]
    assert B.free_symbols <= {sp.Symbol("x0", real=True), sp.Symbol("x1", real=True)}
    value = B.subs({sp.Symbol("x0", real=True): sp.Rational(1, 3),
                    sp.Symbol("x1", real=True): sp.Rational(1, 2)})
    exact = traversal.substitute(result.formulas["B"], {"x0": E.Num(Fraction(1, 3)),
                                                "x1": E.Num(Fraction(1, 2))})
    assert isinstance(exact, E.Num)
    assert value == sp.Rational(exact.value.numerator, exact.value.denominator)
    assert isinstance(result.networks["B"], torch.nn.Module)


def test_a_torch_field_that_differs_from_the_formulas_is_refused():
    with pytest.raises(fossil_dsl.BuildError, match="differs from the dynamics"):
        built(torch_dynamics=lambda x, u: torch.stack([x[:, 1], -x[:, 0]], 1))


def test_a_bad_property_in_a_built_spec_gives_located_diagnostics():
    with pytest.raises(fossil_dsl.SpecError) as info:
        built(prove="from init: always not nowhere")
    diagnostic = info.value.diagnostics[0]
    assert "nowhere" in diagnostic.message and diagnostic.span.line > 1


def test_strings_are_never_evaluated_as_dynamics():
    with pytest.raises(fossil_dsl.BuildError, match="not str"):
        built(dynamics=["__import__('os').getcwd()", x0])


def test_spec_text_is_a_spec_fossilc_accepts(tmp_path):
    text = fossil_dsl.spec_text("demo", ["x0", "x1"], [], [x1, -sp.sin(x0) - 0.1 * x1],
                                "ball([0, 0], 1)", "stable", {}, "continuous", {})
    path = tmp_path / "demo.fsl"
    path.write_text(text)
    assert fossilc("check", path).returncode == 0
    assert "x1' = -sin(x0) - 0.1*x1" in text


@pytest.mark.parametrize("expression", [
    x0 ** 3 - sp.Rational(2, 7) * x1, sp.sin(x0) * sp.exp(-x1), sp.sqrt(1 + x0 ** 2),
    sp.Abs(x0) + sp.atan(x1) - sp.pi, sp.tanh(x0) / (1 + x1 ** 2), sp.Float("0.125") * x0])
def test_sympy_round_trip_is_exact(expression):
    names = ["x0", "x1"]
    back = to_sympy(from_sympy(expression, names),
                    {"x0": sp.Symbol("x0", real=True), "x1": sp.Symbol("x1", real=True)})
    assert sp.simplify(back - sp.nsimplify(expression, rational=True)) == 0


def test_sympy_with_an_unknown_function_is_refused():
    with pytest.raises(SympyConversionError, match="not a function of the language"):
        from_sympy(sp.gamma(x0), ["x0"])


# ---- YAML import ------------------------------------------------------------------
LISTING_1 = """N_VARS: 2
SYSTEM: [x1 - x0**3, -x0]
CERTIFICATE: Lyapunov
TIME_DOMAIN: CONTINUOUS
DOMAINS:
  XD: Sphere([0,0], 1.0)
N_DATA:
  XD: 1000
N_HIDDEN_NEURONS: [5]
ACTIVATION: [SQUARE]
VERIFIER: Z3
"""

CASE_STUDY = """N_VARS: 2
SYSTEM: [x1 + u0, u1 + (0.73575*sin(x0) - 0.1*x1) / (0.0375)]
CERTIFICATE: RAR
DOMAINS:
  XD: Rectangle([-3.5, -3.5], [3.5, 3.5])
  XS: Rectangle([-3.0, -3.0], [3.0, 3.0])
  XI: Rectangle([-2.0, -2.0], [2.0, 2.0])
  XG: Rectangle([-0.1, -0.1], [0.1, 0.1])
  XF: Rectangle([-0.2, -0.2], [0.2, 0.2])
TIME_DOMAIN: CONTINUOUS
VERIFIER: DREAL
N_HIDDEN_NEURONS: [6]
ACTIVATION: [SIGMOID, SQUARE]
N_HIDDEN_NEURONS_ALT: [6]
ACTIVATION_ALT: [SIGMOID, SQUARE]
CTRLAYER: [8,2]
CTRLACTIVATION: [LINEAR]
SEED: 1
CEGIS_MAX_ITERS: 50
"""


def test_paper_listing_1_imports_to_an_equivalent_spec():
    translation = import_yaml(LISTING_1, "listing1")
    spec = fossil_dsl.loads(translation.text)
    assert spec.property.form == "stability" and spec.states == ("x0", "x1")
    assert [str(f) for f in spec.dynamics] == ["x1 - x0^3", "-x0"]
    assert "samples: domain 1000" in translation.text and "verifier: z3" in translation.text
    assert spec.synthesis.certificate[0].activation == "square"
    assert translation.notes == []


def test_case_study_imports_with_notes_on_what_changed(tmp_path):
    path = tmp_path / "ctrl_rar.yaml"
    path.write_text(CASE_STUDY + "FACTORS: QUADRATIC\n")
    out = tmp_path / "ctrl_rar.fsl"
    run = fossilc("import-yaml", path, "-o", out)
    assert run.returncode == 0, run.stderr
    spec = fossil_dsl.load(out)
    assert spec.property.form == "reach-avoid-remain" and spec.inputs == ("u0", "u1")
    assert "controller: linear(8)" in out.read_text() and "max_iters: 50" in out.read_text()
    assert "FACTORS: not translated" in run.stderr
    assert "VERIFIER DREAL" in run.stderr and "only the first 1 layer is built" in run.stderr


def test_a_torus_domain_becomes_the_whole_ball_with_a_note():
    translation = import_yaml(LISTING_1.replace("Sphere([0,0], 1.0)", "Torus([0,0], 1.0, 0.1)"))
    assert "domain ball([0, 0], 1.0)\n" in translation.text
    assert any("inner ball (radius 0.1) is not excluded" in n for n in translation.notes)
    assert fossil_dsl.check_text(translation.text).ok


SETS = {"XD": "Torus([0,0], 3.0, 0.01)", "XI": "Sphere([1,1], 0.2)",
        "XU": "Rectangle([-1.5,1.5], [-1,2])", "XS": "Rectangle([-2,-2], [2,2])",
        "XG": "Sphere([0,0], 0.3)", "XF": "Sphere([0,0], 0.6)"}
NEEDS = {"Lyapunov": ["XD"], "ROA": ["XD", "XI"], "Barrier": ["XD", "XI", "XU"],
         "BarrierAlt": ["XD", "XI", "XU"], "SWA": ["XD", "XI", "XU"],
         "RWA": ["XD", "XI", "XS", "XG"], "RSWA": ["XD", "XI", "XS", "XG"],
         "RAR": ["XD", "XI", "XS", "XG", "XF"]}


@pytest.mark.parametrize("controlled", [False, True])
@pytest.mark.parametrize("counts", ["number", "per set"])
@pytest.mark.parametrize("certificate", sorted(NEEDS))
def test_every_certificate_type_imports_to_a_spec_that_checks(certificate, counts,
                                                               controlled):
    """The reference's configs give N_DATA for every set (XU too for safe-set
    certificates) and a Torus domain: the translation must still check."""
    system = "[x1 + u0, -x0 - x1 + u1]" if controlled else "[x1, -x0 - x1]"
    n_data = "N_DATA: 1000" if counts == "number" else \
        "N_DATA:\n" + "".join(f"  {k}: 500\n" for k in SETS)
    yaml_text = (f"SYSTEM: {system}\nCERTIFICATE: {certificate}\nTIME_DOMAIN: CONTINUOUS\n"
                 "DOMAINS:\n" + "".join(f"  {k}: {SETS[k]}\n" for k in NEEDS[certificate])
                 + n_data + "\nN_HIDDEN_NEURONS: [5]\nACTIVATION: [SQUARE]\n"
                 + ("CTRLAYER: [5, 2]\nCTRLACTIVATION: [LINEAR]\n" if controlled else ""))
    translation = import_yaml(yaml_text, "generated")
    result = fossil_dsl.check_text(translation.text)
    assert result.ok, translation.text + result.render()


@pytest.mark.parametrize("shape, expected", [
    ("Union(Sphere([1,0], 0.5), Rectangle([-1,-1], [0,0]))",
     "(ball([1, 0], 0.5)) | (box([-1, -1], [0, 0]))"),
    ("SetMinus(Rectangle([-2,-2], [2,2]), Sphere([0,0], 0.5))",
     "(box([-2, -2], [2, 2])) - (ball([0, 0], 0.5))")])
def test_set_constructors_translate(shape, expected):
    text = import_yaml(LISTING_1.replace("Sphere([0,0], 1.0)", shape)).text
    assert f"domain {expected}" in text
    # these domains have no neighbourhood of the origin: `prove stable` is refused
    errors = fossil_dsl.check_text(text).errors
    assert [e.message for e in errors if "neighbourhood of the origin" not in e.message] == []


def test_untranslatable_parts_are_named_never_dropped_silently():
    yaml_text = LISTING_1.replace("Sphere([0,0], 1.0)", "MyBespokeDomain()") + \
        "ROUNDING: 3\n"
    notes = import_yaml(yaml_text).notes
    assert any("DOMAINS.XD: not translated" in n for n in notes)
    assert any("needs the set `domain`" in n for n in notes)
    assert any("ROUNDING: not translated" in n for n in notes)


@pytest.mark.parametrize("system", ["__import__('os').getcwd()", "x1; x0", "x0\nprove stable",
                                    "lambda: 0"])
def test_yaml_expressions_are_parsed_never_evaluated(system):
    with pytest.raises(YamlImportError, match="not an expression of the language"):
        import_yaml(LISTING_1.replace("[x1 - x0**3, -x0]", f"[{json.dumps(system)}, -x0]"))


def test_yaml_with_python_tags_is_refused(tmp_path):
    path = tmp_path / "evil.yaml"
    path.write_text("SYSTEM: !!python/object/apply:os.getcwd []\n")
    run = fossilc("import-yaml", path)
    assert run.returncode == 2 and "not valid YAML" in run.stderr
    assert "Traceback" not in run.stderr


def test_a_bespoke_domain_without_a_box_is_refused():
    class Anywhere(Disc):
        box = None
    with pytest.raises(fossil_dsl.BuildError, match="needs a `box`"):
        built(domain=Anywhere())



# the decrease of a rational V vanishes at the origin: the interval procedure cannot
# refute the boxes round it and answers delta-SAT there, which is not a counterexample
RATIONAL = """\
state x0, x1
dynamics continuous {
    x0' = -x0 + x1/(x0^2 + 1)
    x1' = -x1
}
domain ball([0, 0], 1)
prove stable
"""


def test_recheck_never_reports_a_delta_sat_box_as_a_failure(tmp_path):
    from fossil_dsl.outputs import recheck
    result = fossil_dsl.synthesise(fossil_dsl.loads(RATIONAL), seed=0, timeout=60)
    assert result.certified, result.reason
    result.save(tmp_path)
    checks = recheck.recheck(tmp_path, timeout=20)
    assert all(c.reproved for c in checks), [c for c in checks if not c.reproved]
    by_interval = recheck.recheck(tmp_path, timeout=5, solver="interval")
    assert all(c.status in ("unsat", "unknown") for c in by_interval), by_interval
