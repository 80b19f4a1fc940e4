"""The `fossilc` command as a user meets it: a real process, its output and exit code."""
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SPECS = sorted((ROOT / "specs").glob("*.fsl"))
FOSSILC = Path(sys.executable).with_name("fossilc")

GOOD = """\
state x0, x1
dynamics continuous {
    x0' = x1 - x0^3
    x1' = -x0
}
domain ball([0, 0], 1)
prove stable
"""


def fossilc(*args, cwd=None):
    return subprocess.run([str(FOSSILC), *map(str, args)], capture_output=True, text=True,
                          timeout=120, cwd=cwd)


def write(tmp_path, text, name="spec.fsl"):
    path = tmp_path / name
    path.write_text(text)
    return path


def assert_no_traceback(run):
    assert "Traceback" not in run.stderr + run.stdout
    assert "internal error" not in run.stderr


def test_console_script_is_installed():
    assert FOSSILC.exists()


def test_check_bundled_specs_ok():
    run = fossilc("check", *SPECS)
    assert run.returncode == 0, run.stderr
    assert len(SPECS) >= 3
    for spec in SPECS:
        assert f"ok: {spec}" in run.stdout


def test_check_summary_line_for_the_case_study():
    run = fossilc("check", ROOT / "specs" / "pendulum_rar.fsl")
    assert run.returncode == 0
    first, second = run.stdout.strip().splitlines()
    assert first.endswith(
        "reach-avoid-remain (RWA + barrier), 2 states, 2 inputs, continuous time")
    # sin in the model: no polynomial verifier; dReal where installed, else intervals
    assert re.match(r"  verifier: (dreal|interval) \(the problem has transcendental", second)


def test_check_names_z3_for_polynomial_specs():
    run = fossilc("check", ROOT / "specs" / "stability_continuous.fsl")
    assert "  verifier: z3 (the problem is polynomial arithmetic" in run.stdout


def test_check_reports_error_with_location_and_exit_2(tmp_path):
    path = write(tmp_path, GOOD.replace("x1' = -x0", "x1' = -y"))
    run = fossilc("check", path)
    assert run.returncode == 2
    assert f"{path}:4:12: error: undeclared name `y`" in run.stderr
    assert "^" in run.stderr
    assert "ok:" not in run.stdout
    assert_no_traceback(run)


def test_check_many_files_exit_2_if_any_is_bad(tmp_path):
    good, bad = write(tmp_path, GOOD, "good.fsl"), write(tmp_path, "state x\n", "bad.fsl")
    run = fossilc("check", good, bad)
    assert run.returncode == 2
    assert f"ok: {good}" in run.stdout
    assert f"{bad}:1:1: error:" in run.stderr


def test_warnings_print_but_exit_0(tmp_path):
    path = write(tmp_path, "const unused = 3\n" + GOOD)
    run = fossilc("check", path)
    assert run.returncode == 0
    assert f"{path}:1:7: warning: constant `unused`" in run.stderr
    quiet = fossilc("check", "--quiet", path)
    assert quiet.returncode == 0 and "warning" not in quiet.stderr


CERTIFIABLE = GOOD.replace("x1 - x0^3", "-x0 + x0*x1").replace("-x0\n}", "-x1\n}")


def test_run_certifies_and_exits_0(tmp_path):
    run = fossilc(write(tmp_path, CERTIFIABLE), "--seed", "1", "--verbose")
    assert run.returncode == 0, run.stdout + run.stderr
    assert "CERTIFIED (stability, Lyapunov function)" in run.stdout
    assert "V(x) = " in run.stdout and "guarantee: the origin is asymptotically stable" in run.stdout
    assert "iteration   1" in run.stderr  # a line per iteration with --verbose
    assert_no_traceback(run)


def test_run_not_certified_exits_1(tmp_path):
    unstable = CERTIFIABLE.replace("-x0 + x0*x1", "x0 + x1")
    run = fossilc(write(tmp_path, unstable), "--max-iters", "2", "--quiet")
    assert run.returncode == 1
    assert "NOT CERTIFIED" in run.stdout and "nothing is proved" in run.stdout
    assert "iteration" not in run.stderr
    assert_no_traceback(run)


def test_run_json_is_pure_json(tmp_path):
    import json
    run = fossilc(write(tmp_path, CERTIFIABLE), "--json")
    data = json.loads(run.stdout)
    assert data["verdict"] == "certified" and data["schema"] == 3
    assert set(data["functions"]) == {"V"}


def test_run_on_bad_spec_exits_2(tmp_path):
    run = fossilc(write(tmp_path, "prove stable\n"))
    assert run.returncode == 2
    assert "no `state` statement" in run.stderr
    assert_no_traceback(run)


@pytest.mark.parametrize("args", [["check", "missing.fsl"], ["missing.fsl"]])
def test_missing_file_is_a_clear_error(tmp_path, args):
    run = fossilc(*args, cwd=tmp_path)
    assert run.returncode == 2
    assert "missing.fsl" in run.stderr and "cannot read the file" in run.stderr
    assert_no_traceback(run)


def test_directory_instead_of_file(tmp_path):
    run = fossilc("check", tmp_path)
    assert run.returncode == 2
    assert "cannot read the file" in run.stderr
    assert_no_traceback(run)


@pytest.mark.parametrize("content", [b"", b"\x00\xff\xfe\x80binary", b"\xef\xbb\xbfstate x\n",
                                     b"(" * 100_000, b"x" * 3_000_000])
def test_broken_files_never_crash(tmp_path, content):
    path = tmp_path / "broken.fsl"
    path.write_bytes(content)
    run = fossilc("check", path)
    assert run.returncode == 2
    assert f"{path}:" in run.stderr
    assert_no_traceback(run)


def test_usage_errors_exit_2():
    assert fossilc().returncode == 2
    assert fossilc("check").returncode == 2


def test_version():
    run = fossilc("--version")
    assert run.returncode == 0 and run.stdout.startswith("fossilc ")


@pytest.mark.parametrize("where", [
    "CODE\n" + GOOD,
    GOOD.replace("x1 - x0^3", "CODE"),
    "const c = CODE\n" + GOOD,
    GOOD.replace("ball([0, 0], 1)", "ball([0, 0], CODE)"),
    GOOD + "synthesis {\n    candidate: CODE\n}\n",
    GOOD.replace("prove stable", "prove CODE"),
    "# CODE\n" + GOOD.replace("prove stable", "prove stable # CODE"),
])
def test_python_in_a_spec_never_runs(tmp_path, where):
    marker = tmp_path / "PWNED"
    code = f"__import__('os').system('touch {marker}')"
    path = write(tmp_path, where.replace("CODE", code))
    run = fossilc("check", path)
    assert not marker.exists()
    assert_no_traceback(run)
    if not where.startswith("# "):  # inside a comment it is just a comment
        assert run.returncode == 2


def test_python_in_comment_is_only_a_comment(tmp_path):
    path = write(tmp_path, "# __import__('os').system('true')\n" + GOOD)
    assert fossilc("check", path).returncode == 0
