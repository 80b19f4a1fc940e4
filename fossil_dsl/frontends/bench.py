"""`fossilc bench`: every spec × seed in its own process, J at a time (or on the workers
of a Dask scheduler, `--cluster`); a table in the
style of the tool paper's (success rate, times over successful runs, learning against
verification), written as CSV (one row per run) and Markdown (one row per spec).

A run that fails, times out or crashes is recorded as such and never stops the others.
"""
from __future__ import annotations

import csv
import json
import os
import platform
import statistics
from dataclasses import asdict, dataclass
from datetime import date
from pathlib import Path
from typing import Callable, Iterable, Sequence

from fossil_dsl.cluster.executors import Executor, LocalExecutor
from fossil_dsl.cluster.jobs import GRACE, Job, JobOutput
from fossil_dsl.frontends.api import load
from fossil_dsl.diagnostics import FslError
from fossil_dsl.plan.compile import compile_spec
from fossil_dsl.version import __version__


@dataclass(frozen=True)
class Run:
    spec: str  # the spec's name
    path: str
    seed: int
    outcome: str  # certified, not certified, timeout, bad spec, crashed
    total: float | None = None  # seconds, as the run reports them
    learn: float | None = None
    verify: float | None = None
    iterations: int | None = None
    wall: float = 0.0  # seconds of the whole process, start-up included
    detail: str = ""
    worker: str = "local"  # where it ran (a Dask worker's address with --cluster)
    attempts: int = 1  # times it was started: more when its worker was lost


@dataclass(frozen=True)
class SpecInfo:
    name: str
    path: str
    states: int
    inputs: int
    certificate: str
    networks: str
    verifier: str


def spec_files(paths: Iterable[str]) -> list[Path]:
    found = []
    for path in map(Path, paths):
        found += sorted(path.rglob("*.fsl")) if path.is_dir() else [path]
    return found


def describe(path: Path, verifier: str | None) -> SpecInfo:
    try:
        spec = load(path)
        plan = compile_spec(spec, verifier=verifier)
    except FslError as exc:
        return SpecInfo(path.stem, str(path), 0, 0, f"(error: {exc})", "", "")
    networks = ["; ".join(", ".join(map(str, f.layers)) if f.candidate is None else "candidate"
                          for f in plan.functions)]
    if plan.controller:
        networks.append("k: " + ", ".join(map(str, plan.controller.layers)))
    return SpecInfo(spec.name, str(path), len(spec.states), len(spec.inputs),
                    spec.property.certificate, " | ".join(networks), plan.verifier)


def job_for(path: Path, seed: int, verifier: str | None, timeout: float, name: str) -> Job:
    return Job(path.read_text("utf-8"), path.stem, seed, timeout, verifier,
               label=f"{name} seed {seed}")


def run_from(output: JobOutput, job: Job, name: str, path: Path) -> Run:
    """A job's output as a table's run."""
    seed, wall, attempts = job.seed, output.wall, output.attempts
    where = {"worker": output.worker, "attempts": attempts}
    if output.worker == "lost":
        return Run(name, str(path), seed, "crashed", wall=wall, detail=_last_line(output.stderr),
                   **where)
    if output.returncode is None:
        return Run(name, str(path), seed, "timeout", wall=wall,
                   detail=f"killed after {job.timeout + GRACE:g} s", **where)
    if output.returncode == 2:
        return Run(name, str(path), seed, "bad spec", wall=wall,
                   detail=_last_line(output.stderr), **where)
    try:
        data = json.loads(output.stdout)
    except json.JSONDecodeError:
        return Run(name, str(path), seed, "crashed", wall=wall,
                   detail=f"exit {output.returncode}: {_last_line(output.stderr)}", **where)
    outcome = data["verdict"]
    if outcome != "certified" and data["reason"].startswith("timeout"):
        outcome = "timeout"
    seconds = data["seconds"]
    return Run(name, str(path), seed, outcome, seconds["total"], seconds["learn"],
               seconds["verify"], data["iterations"], wall, data["reason"], **where)


def _last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1] if lines else ""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep: every job was stopped; the runs that had finished."""

    def __init__(self, infos: list[SpecInfo], runs: list[Run], planned: int):
        super().__init__()
        self.infos, self.runs, self.planned = infos, runs, planned


def run_all(paths: Sequence[Path], seeds: int, jobs: int, verifier: str | None,
            timeout: float, progress: Callable[[Run], None] = lambda run: None,
            executor: Executor | None = None) -> tuple[list[SpecInfo], list[Run]]:
    """Every spec × seed, on `executor` (default: `jobs` local processes). On Ctrl-C
    every job is stopped and Interrupted carries the runs that had finished."""
    infos = [describe(path, verifier) for path in paths]
    tasks = [(path, seed, info.name) for path, info in zip(paths, infos)
             for seed in range(seeds)]
    work = [job_for(path, seed, verifier, timeout, name) for path, seed, name in tasks]
    runs: list[Run | None] = [None] * len(work)

    def done(index: int, output: JobOutput) -> None:
        path, _, name = tasks[index]
        runs[index] = run_from(output, work[index], name, path)
        progress(runs[index])

    try:
        (executor or LocalExecutor(jobs)).run(work, done)
    except KeyboardInterrupt:
        raise Interrupted(infos, [r for r in runs if r is not None], len(work)) from None
    return infos, runs


# ---- tables ------------------------------------------------------------------------------
COLUMNS = ["spec", "states", "inputs", "certificate", "networks", "verifier", "success",
           "min s", "mean s", "median s", "max s", "median learn s", "median verify s"]


def table_rows(infos: Sequence[SpecInfo], runs: Sequence[Run]) -> list[list[str]]:
    rows = []
    for info in infos:
        mine = [r for r in runs if r.path == info.path]
        good = [r for r in mine if r.outcome == "certified"]
        times = [r.total for r in good]
        stats = [min(times), statistics.mean(times), statistics.median(times), max(times)] \
            if times else []
        medians = [statistics.median(r.learn for r in good),
                   statistics.median(r.verify for r in good)] if good else []
        numbers = [f"{v:.2f}" for v in stats + medians] or ["–"] * 6
        rows.append([info.name, str(info.states), str(info.inputs), info.certificate,
                     info.networks, info.verifier, f"{len(good)}/{len(mine)}", *numbers])
    return rows


def markdown(infos, runs, command: str, where: str = "", planned: int | None = None) -> str:
    rows = table_rows(infos, runs)
    machine = where or f"{platform.node() or 'this machine'} ({platform.machine()}, " \
        f"{os.cpu_count()} cores, Python {platform.python_version()})"
    lines = [f"Run on {date.today().isoformat()}, {machine}, "
             f"fossil_dsl {__version__}; command: `{command}`.",
             "Times are the runs' own (check excluded, process start-up excluded), over "
             "successful runs only.", ""]
    if planned is not None and planned > len(runs):
        lines += [f"**Interrupted (Ctrl-C): {len(runs)} of {planned} runs finished; the "
                  "table counts those only.**", ""]
    lines += ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |"
              for row in rows]
    retried = [r for r in runs if r.attempts > 1]
    if retried:
        lines += ["", "Runs started again after their worker was lost:", ""]
        lines += [f"- {r.spec} seed {r.seed}: {r.attempts} starts, finished on {r.worker}"
                  for r in retried]
    failures = [r for r in runs if r.outcome != "certified"]
    if failures:
        lines += ["", "Runs not certified:", ""]
        lines += [f"- {r.spec} seed {r.seed}: {r.outcome} ({r.detail})" for r in failures]
    return "\n".join(lines) + "\n"


def write(out: Path, infos, runs, command: str, where: str = "",
          planned: int | None = None) -> tuple[Path, Path]:
    out.mkdir(parents=True, exist_ok=True)
    runs_csv = out / "runs.csv"
    with runs_csv.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(asdict(runs[0]))) if runs else None
        if writer:
            writer.writeheader()
            writer.writerows(asdict(r) for r in runs)
    table = out / "table.md"
    table.write_text(markdown(infos, runs, command, where, planned))
    with (out / "table.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        writer.writerows(table_rows(infos, runs))
    return runs_csv, table

