"""The process keeps rounding to nearest: codac's import switches it to upward rounding,
which fossil_dsl.ir.enclosure sets only around interval computations. Session 41 found
a run whose libraries were imported before its clock with `import codac` directly: the
whole run then rounded upwards and Python's floats overflowed to OverflowError (20 of 29
false-property runs crashed). Fresh processes: the first import is the one that counts."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def run_python(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, timeout=300)


def test_a_run_leaves_the_process_rounding_to_nearest():
    code = (
        "import ctypes, ctypes.util\n"
        "libm = ctypes.CDLL(ctypes.util.find_library('m'))\n"
        "before = libm.fegetround()\n"
        "import fossil_dsl\n"
        "result = fossil_dsl.synthesise(fossil_dsl.load('specs/stability_continuous.fsl'),"
        " verifier='interval', timeout=60)\n"
        "print(before, libm.fegetround(), result.certified, float('1e308') * 10)\n")
    run = run_python(code)
    assert run.returncode == 0, run.stderr
    before, after, certified, overflow = run.stdout.split()[-4:]
    assert before == after and certified == "True" and overflow == "inf"


def test_codac_imported_behind_the_enclosures_back_is_refused():
    code = ("import codac\n"
            "from fossil_dsl.ir import expr as E\n"
            "from fossil_dsl.ir.enclosure import enclose\n"
            "enclose(E.apply('sin', E.ONE))\n")
    run = run_python(code)
    assert run.returncode != 0 and "imported before fossil_dsl.ir.enclosure" in run.stderr
