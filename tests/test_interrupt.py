"""Ctrl-C: a run stops with what it has (a partial summary, result.json when -o was
given) and exit code 130; the live display on a terminal, nothing on a pipe."""
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import fossil_dsl
from fossil_dsl.engine.loop import IterationRecord, Verdict
from fossil_dsl.solvers.api import Status

ROOT = Path(__file__).resolve().parent.parent
# A false property (the orbit through init runs through unsafe): never certified, so the
# run goes on learning, iteration after iteration, until it is stopped.
LONG_RUN = """
state x0, x1
dynamics continuous {
    x0' = x1
    x1' = -x0
}
domain box([-2, -2], [2, 2])
set init = ball([1, 0], 0.1)
set unsafe = ball([0, -1], 0.1)
prove from init: always not unsafe
synthesis { max_iters: 1000 }
"""


def _start(*arguments: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "fossil_dsl.frontends.cli", *arguments],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def test_ctrl_c_stops_with_a_partial_summary_and_exit_130(tmp_path):
    spec = tmp_path / "false_safety.fsl"
    spec.write_text(LONG_RUN)
    run = _start(str(spec), "-o", str(tmp_path / "out"), "--verbose")
    first = ""
    while "iteration   2" not in first:  # two iterations done: a candidate was verified
        line = run.stderr.readline()
        assert line, "the run ended before two iterations"
        first += line
    run.send_signal(signal.SIGINT)
    stopped = time.monotonic()
    out, err = run.communicate(timeout=60)
    assert run.returncode == 130, out + err
    assert time.monotonic() - stopped < 30
    assert "NOT CERTIFIED" in out and "why: interrupted (Ctrl-C) in iteration" in out
    assert "B(x) = " in out and "guarantee: nothing is proved" in out
    assert "Traceback" not in err
    data = json.loads((tmp_path / "out" / "result.json").read_text())
    assert data["interrupted"] is True and data["verdict"] == "not certified"
    loaded = fossil_dsl.load_result(tmp_path / "out", judge_again=False)
    assert loaded.interrupted and loaded.exit_code == 130 and not loaded.certified


def _hard_query():
    """Six variables, degree 7: Z3 runs for seconds on it."""
    from fossil_dsl.ir import expr as E
    from fossil_dsl.ir import logic as L
    a, b, c, d, e, f = (E.Var(f"x{i}") for i in range(6))

    def p(x, n):
        return E.power(x, E.lift(n))
    poly = E.add(E.mul(p(a, 2), p(b, 3)), E.neg(E.mul(p(c, 5), d)), E.mul(E.lift(3), e, p(f, 4)),
                 E.neg(p(a, 7)), p(b, 7), E.neg(E.mul(c, d, e, f)), E.lift(-1))
    return L.conjunction(L.Compare("<=", poly, E.lift(0)), L.Compare(">=", poly, E.lift(0)),
                         L.Compare(">", E.mul(a, b, c, d), E.lift(3)),
                         L.Compare("<", E.add(p(e, 2), p(f, 2), p(a, 2)), E.lift(1)))


def test_ctrl_c_during_a_z3_query_reaches_the_main_thread():
    """Z3 catches SIGINT itself and answers unknown; the backend passes it on."""
    from fossil_dsl.solvers.z3_backend import Z3Backend
    query = _hard_query()
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    started = time.monotonic()
    timer.start()
    answered = []
    with pytest.raises(KeyboardInterrupt):
        answered.append(Z3Backend().check(query, [f"x{i}" for i in range(6)], 30.0))
        time.sleep(5)  # (if Z3 answered first, the signal itself arrives here)
    timer.cancel()
    assert time.monotonic() - started < 3  # Z3 alone takes about 5 s on it
    assert not answered  # the interrupt came out of the query itself, not the sleep


def test_a_pipe_gets_no_progress_and_a_terminal_gets_the_live_display(tmp_path):
    spec = tmp_path / "learned.fsl"  # a template named: learned, not sum of squares
    spec.write_text((ROOT / "specs" / "stability_continuous.fsl").read_text()
                    + "\nsynthesis {\n    certificate: square(8)\n}\n")
    piped = subprocess.run([sys.executable, "-m", "fossil_dsl.frontends.cli", str(spec)],
                           cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert piped.returncode == 0
    assert "iteration" not in piped.stderr and "\x1b[" not in piped.stderr + piped.stdout
    terminal = _run_on_a_terminal([sys.executable, "-m", "fossil_dsl.frontends.cli", str(spec)])
    assert "iteration 1/" in terminal and "learning" in terminal and "left)" in terminal
    assert "CERTIFIED" in terminal


def _run_on_a_terminal(command) -> str:
    import pty
    leader, follower = pty.openpty()
    process = subprocess.Popen(command, cwd=ROOT, stdout=follower, stderr=follower,
                               env={**os.environ, "COLUMNS": "100", "TERM": "xterm"})
    os.close(follower)
    chunks = []
    while True:
        try:
            chunk = os.read(leader, 65536)
        except OSError:  # the terminal closed: the process ended
            break
        if not chunk:
            break
        chunks.append(chunk)
    process.wait(timeout=300)
    os.close(leader)
    assert process.returncode == 0
    return b"".join(chunks).decode("utf-8", "replace")


def test_the_live_display_shows_iteration_phase_counterexamples_and_time():
    from rich.console import Console
    from fossil_dsl.frontends.live import LiveDisplay
    from fossil_dsl.plan.compile import compile_spec
    plan = compile_spec(fossil_dsl.load(ROOT / "specs" / "stability_continuous.fsl"),
                        timeout=90)
    console = Console(record=True, width=120, force_terminal=False)
    display = LiveDisplay(console)
    display.start(plan)
    display.phase(1, "verifying decrease (2/2)")
    display.finished(IterationRecord(1, 0.5, (
        Verdict("positive", Status.UNSAT), Verdict("decrease", Status.SAT, counterexample=(1, 0))),
        0.1, 0.2))
    display.phase(2, "learning")
    console.print(display.render())
    text = console.export_text()
    assert f"iteration 2/{plan.options.max_iters}: learning" in text
    assert "1 counterexample;" in text and "not yet proved: decrease" in text
    assert "of 1:30 (1:29 left)" in text or "of 1:30 (1:30 left)" in text
