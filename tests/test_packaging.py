"""The wheel ships the grammar: a non-editable install parses specs outside the source tree."""
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    out = tmp_path_factory.mktemp("wheel")
    try:
        import setuptools  # noqa: F401  (build without network when it is here)
        isolation = ["--no-build-isolation"]
    except ImportError:
        isolation = []
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", *isolation, "-q",
                    "-w", str(out), str(ROOT)], check=True, capture_output=True, timeout=300)
    [built] = out.glob("fossil_dsl-*.whl")
    return built


def test_wheel_contains_grammar_and_entry_point(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    assert "fossil_dsl/grammar/fsl.lark" in names
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    assert "fossilc = fossil_dsl.frontends.cli:main" in zipfile.ZipFile(wheel).read(entry_points).decode()


def test_wheel_contains_every_module(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    package = ROOT / "fossil_dsl"
    modules = {f"fossil_dsl/{p.relative_to(package)}" for p in package.rglob("*.py")}
    assert modules <= names, f"missing from the wheel: {sorted(modules - names)}"


def test_installed_wheel_parses_outside_the_source_tree(wheel, tmp_path):
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target",
                    str(site), str(wheel)], check=True, capture_output=True, timeout=300)
    script = ("import fossil_dsl, sys; "
              "assert fossil_dsl.__file__.startswith(sys.argv[1]), fossil_dsl.__file__; "
              "print(fossil_dsl.loads('state x\\ndynamics continuous { x\\' = -x }\\n"
              "domain ball([0], 1)\\nprove stable\\n').summary())")
    run = subprocess.run([sys.executable, "-c", script, str(site)], cwd=tmp_path,
                         env={"PYTHONPATH": str(site), "PATH": "/usr/bin:/bin"},
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "stability (Lyapunov), 1 state, 0 inputs, continuous time" in run.stdout


def test_runs_from_a_source_checkout():
    """`python` started in the repository imports the source tree, where the grammar
    lives in grammar/ rather than in the package: it must still be found."""
    script = ("import fossil_dsl, sys; assert fossil_dsl.__file__.startswith(sys.argv[1]); "
              "print(fossil_dsl.check_text('state x\\ndynamics continuous { x\\' = -x }\\n"
              "domain ball([0], 1)\\nprove stable\\n').ok)")
    run = subprocess.run([sys.executable, "-c", script, str(ROOT)], cwd=ROOT,
                         env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"},
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "True"
