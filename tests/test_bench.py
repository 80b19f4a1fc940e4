"""`fossilc bench`: every spec × seed in its own process; failures are recorded, never
fatal; the table and the raw runs are written."""
import csv
import subprocess
import sys
from pathlib import Path

import pytest

from fossil_dsl.frontends import bench

ROOT = Path(__file__).resolve().parent.parent
FOSSILC = Path(sys.executable).with_name("fossilc")

SADDLE = """\
state x0, x1
dynamics continuous {
    x0' = x0 + x1
    x1' = -x1
}
domain ball([0, 0], 1)
prove stable
synthesis { max_iters: 2 }
"""


def test_bench_records_every_run_and_writes_the_tables(tmp_path):
    specs = tmp_path / "specs"
    specs.mkdir()
    (specs / "good.fsl").write_text((ROOT / "specs" / "stability_continuous.fsl").read_text())
    (specs / "saddle.fsl").write_text(SADDLE)
    (specs / "broken.fsl").write_text("state x0\n")
    out = tmp_path / "out"
    run = subprocess.run([str(FOSSILC), "bench", str(specs), "--seeds", "2", "--jobs", "2",
                          "--timeout", "120", "--out", str(out)],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    with (out / "runs.csv").open() as handle:
        runs = list(csv.DictReader(handle))
    assert len(runs) == 6
    outcomes = {(Path(r["path"]).stem, r["outcome"]) for r in runs}
    assert outcomes == {("good", "certified"), ("saddle", "not certified"),
                        ("broken", "bad spec")}
    table = (out / "table.md").read_text()
    assert "| stability_continuous | 2 | 0 | Lyapunov | square(8) | z3 | 2/2 |" in table
    assert "| saddle | 2 | 0 | Lyapunov | square(8) | z3 | 0/2 | – |" in table
    assert "| broken | 0 | 0 | (error:" in table
    # a saddle's stability is refuted at once (engine/unstable_origin.py)
    assert "saddle seed 1: not certified (the property is false: the origin is unstable" \
        in table
    assert table in run.stdout
    # stderr is no terminal here: one line per run as it finishes, not a silent bar
    finished = [line for line in run.stderr.splitlines() if " seed " in line]
    assert len(finished) == 6 and "saddle seed 1: not certified" in run.stderr


def test_table_rows_use_successful_runs_only():
    info = bench.SpecInfo("s", "s.fsl", 2, 1, "barrier", "square(8)", "z3")
    runs = [bench.Run("s", "s.fsl", 0, "certified", 2.0, 0.5, 1.0, 3),
            bench.Run("s", "s.fsl", 1, "certified", 4.0, 1.5, 2.0, 5),
            bench.Run("s", "s.fsl", 2, "timeout", None, None, None, None)]
    [row] = bench.table_rows([info], runs)
    assert row[6:] == ["2/3", "2.00", "3.00", "3.00", "4.00", "1.00", "1.50"]
    [empty] = bench.table_rows([info], runs[2:])
    assert empty[6] == "0/1" and empty[7:] == ["–"] * 6


BENCHMARKS = ROOT / "specs" / "benchmarks"
ROWS = [f"row{n:02d}" for n in range(1, 18)] + ["f1_nonpoly0", "f1_poly2", "f1_barr1",
                                                  "f1_barr3"]


def test_the_21_benchmarks_are_there_and_check():
    files = sorted(BENCHMARKS.glob("*.fsl"))
    stems = [f.stem for f in files]
    assert len(files) == 21
    for row in ROWS:
        assert sum(stem.startswith(row) for stem in stems) == 1, row
    run = subprocess.run([str(FOSSILC), "check", *map(str, files)], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    for path in files:
        assert path.read_text().startswith("# Row") or path.read_text().startswith("# Fossil-1")


# a smoke test only: speed is measured by `fossilc bench`, not by tests
@pytest.mark.parametrize("name", ["row14_stability_dt", "f1_nonpoly0", "row16_safety_dt_two_room",
                                  "f1_barr1"])
def test_fast_benchmarks_certify_with_one_seed(name):
    import fossil_dsl
    result = fossil_dsl.synthesise(fossil_dsl.load(BENCHMARKS / f"{name}.fsl"), seed=0)
    assert result.certified, result.reason


class StopsAfterOne:
    """An executor on which the user presses Ctrl-C once the first run has finished."""
    description = "a test executor"

    def run(self, jobs, on_done=lambda i, o: None, wins=lambda o: False):
        from fossil_dsl.cluster.jobs import run_job
        on_done(0, run_job(jobs[0]))
        raise KeyboardInterrupt

    def close(self):
        pass


def test_ctrl_c_keeps_the_runs_that_finished(tmp_path, monkeypatch, capsys):
    from fossil_dsl.cluster import executors
    from fossil_dsl.frontends.cli import main
    monkeypatch.setattr(executors, "executor_for", lambda cluster, jobs: StopsAfterOne())
    spec = ROOT / "specs" / "stability_continuous.fsl"
    assert main(["bench", str(spec), "--seeds", "3", "--out", str(tmp_path)]) == 130
    with (tmp_path / "runs.csv").open() as handle:
        runs = list(csv.DictReader(handle))
    assert [(r["seed"], r["outcome"]) for r in runs] == [("0", "certified")]
    assert "Interrupted (Ctrl-C): 1 of 3 runs finished" in (tmp_path / "table.md").read_text()
    assert "1 of 3 runs had finished" in capsys.readouterr().err
