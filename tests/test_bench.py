"""`fossilc bench`: every spec × seed in its own process; failures are recorded, never
fatal; the table and the raw runs are written."""
import csv
import subprocess
import sys
from pathlib import Path

from fossil_dsl import bench

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
    assert "saddle seed 1: not certified (gave up after 2 iterations)" in table
    assert table in run.stdout


def test_table_rows_use_successful_runs_only():
    info = bench.SpecInfo("s", "s.fsl", 2, 1, "barrier", "square(8)", "z3")
    runs = [bench.Run("s", "s.fsl", 0, "certified", 2.0, 0.5, 1.0, 3),
            bench.Run("s", "s.fsl", 1, "certified", 4.0, 1.5, 2.0, 5),
            bench.Run("s", "s.fsl", 2, "timeout", None, None, None, None)]
    [row] = bench.table_rows([info], runs)
    assert row[6:] == ["2/3", "2.00", "3.00", "3.00", "4.00", "1.00", "1.50"]
    [empty] = bench.table_rows([info], runs[2:])
    assert empty[6] == "0/1" and empty[7:] == ["–"] * 6
