"""Bad option values are refused before any work: exit 2, a message that says what is
allowed, and nothing run (no iteration printed, no folder written). Every numeric,
solver and path option of every subcommand, and the Python API's keyword options."""
import subprocess
import sys
from pathlib import Path

import pytest

import fossil_dsl
from fossil_dsl.frontends.arguments import OptionError

ROOT = Path(__file__).resolve().parents[1]
SPEC = str(ROOT / "specs" / "stability_continuous.fsl")
UNWRITABLE = "/proc/no/such/dir"

CASES = [
    # (arguments, words the message must contain)
    ([SPEC, "--max-iters", "0"], "at least 1"),
    ([SPEC, "--max-iters", "2.5"], "whole number"),
    ([SPEC, "--timeout", "0"], "positive"),
    ([SPEC, "--timeout", "-3"], "positive"),
    ([SPEC, "--timeout", "inf"], "finite"),
    ([SPEC, "--seed", "abc"], "whole number"),
    ([SPEC, "--seed", "-1"], "at least 0"),
    ([SPEC, "--verifier", "yices"], "the solvers are: z3"),
    ([SPEC, "-o", UNWRITABLE], "cannot write to the folder"),
    (["compile", SPEC, "--verifier", "yices"], "unknown solver"),
    (["bench", SPEC, "--seeds", "0"], "at least 1"),
    (["bench", SPEC, "--jobs", "0"], "at least 1"),
    (["bench", SPEC, "--timeout", "0"], "positive"),
    (["bench", SPEC, "--verifier", "yices"], "unknown solver"),
    (["bench", SPEC, "--out", UNWRITABLE], "cannot write to the folder"),
    (["recheck", "somewhere", "--timeout", "0"], "positive"),
    (["recheck", "somewhere", "--solver", "yices"], "unknown solver"),
    (["import-yaml", "config.yaml", "-o", UNWRITABLE + "/spec.fsl"], "cannot write"),
]


@pytest.mark.parametrize("arguments, words", CASES, ids=[" ".join(c[0][-2:]) + f" {i}"
                                                          for i, c in enumerate(CASES)])
def test_a_bad_option_is_refused_before_any_work(arguments, words, tmp_path):
    run = subprocess.run([sys.executable, "-m", "fossil_dsl.frontends.cli", *arguments],
                         capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert run.returncode == 2, run.stdout + run.stderr
    assert words in run.stderr, run.stderr
    assert "  iteration " not in run.stdout + run.stderr and "internal error" not in run.stderr
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.parametrize("options", [{"max_iters": 0}, {"timeout": 0}, {"seed": -2},
                                     {"seed": 1.5}, {"verifier": "yices"},
                                     {"learning_rate": float("nan")}, {"delta": -1},
                                     {"query_timeout": 0}, {"digits": 0}])
def test_the_python_api_refuses_bad_options_before_any_work(options):
    spec = fossil_dsl.load(SPEC)
    with pytest.raises(OptionError):
        fossil_dsl.synthesise(spec, **options)


@pytest.mark.parametrize("number", ["1e300", "2e12", "1e999", "1000000 * 1000000 * 10"])
def test_numbers_beyond_what_solvers_handle_faithfully_are_refused(number):
    text = f"state x\ndynamics continuous {{\n  x' = -{number}*x\n}}\n" \
           "domain box([-1], [1])\nprove stable\n"
    result = fossil_dsl.check_text(text, "spec.fsl")
    assert not result.ok
    assert any("up to 1e12" in d.message and d.span.line == 3 for d in result.errors)


@pytest.mark.parametrize("number", ["1e12", "1e-12", "1e-300", "0", "6.674e-11", "299792458"])
def test_numbers_within_the_range_are_accepted(number):
    text = f"state x\ndynamics continuous {{\n  x' = -x + {number}*x^3\n}}\n" \
           "domain box([-1], [1])\nprove stable\n"
    assert fossil_dsl.check_text(text, "spec.fsl").ok
