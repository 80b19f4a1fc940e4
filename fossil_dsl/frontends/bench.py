"""`fossilc bench`: every spec × seed in its own process, J at a time; a table in the
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
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from datetime import date
from pathlib import Path
from typing import Callable, Iterable, Sequence

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


def run_one(path: Path, seed: int, verifier: str | None, timeout: float, name: str) -> Run:
    command = [sys.executable, "-m", "fossil_dsl.frontends.cli", str(path), "--json", "-q",
               "--seed", str(seed), "--timeout", str(timeout)]
    if verifier:
        command += ["--verifier", verifier]
    started = time.monotonic()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout + 60)
    except subprocess.TimeoutExpired:
        return Run(name, str(path), seed, "timeout", wall=time.monotonic() - started,
                   detail=f"killed after {timeout + 60:g} s")
    wall = time.monotonic() - started
    if done.returncode == 2:
        return Run(name, str(path), seed, "bad spec", wall=wall, detail=_last_line(done.stderr))
    try:
        data = json.loads(done.stdout)
    except json.JSONDecodeError:
        return Run(name, str(path), seed, "crashed", wall=wall,
                   detail=f"exit {done.returncode}: {_last_line(done.stderr)}")
    outcome = data["verdict"]
    if outcome != "certified" and data["reason"].startswith("timeout"):
        outcome = "timeout"
    seconds = data["seconds"]
    return Run(name, str(path), seed, outcome, seconds["total"], seconds["learn"],
               seconds["verify"], data["iterations"], wall, data["reason"])


def _last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1] if lines else ""


def run_all(paths: Sequence[Path], seeds: int, jobs: int, verifier: str | None,
            timeout: float, progress: Callable[[Run], None] = lambda run: None
            ) -> tuple[list[SpecInfo], list[Run]]:
    infos = [describe(path, verifier) for path in paths]
    tasks = [(path, seed, info.name) for path, info in zip(paths, infos)
             for seed in range(seeds)]

    def one(task) -> Run:
        path, seed, name = task
        run = run_one(path, seed, verifier, timeout, name)
        progress(run)
        return run

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        runs = list(pool.map(one, tasks))
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


def markdown(infos, runs, command: str) -> str:
    rows = table_rows(infos, runs)
    lines = [f"Run on {date.today().isoformat()}, {platform.node() or 'this machine'} "
             f"({platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}), "
             f"fossil_dsl {__version__}; command: `{command}`.",
             "Times are the runs' own (check excluded, process start-up excluded), over "
             "successful runs only.", "",
             "| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |"
              for row in rows]
    failures = [r for r in runs if r.outcome != "certified"]
    if failures:
        lines += ["", "Runs not certified:", ""]
        lines += [f"- {r.spec} seed {r.seed}: {r.outcome} ({r.detail})" for r in failures]
    return "\n".join(lines) + "\n"


def write(out: Path, infos, runs, command: str) -> tuple[Path, Path]:
    out.mkdir(parents=True, exist_ok=True)
    runs_csv = out / "runs.csv"
    with runs_csv.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(asdict(runs[0]))) if runs else None
        if writer:
            writer.writeheader()
            writer.writerows(asdict(r) for r in runs)
    table = out / "table.md"
    table.write_text(markdown(infos, runs, command))
    with (out / "table.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        writer.writerows(table_rows(infos, runs))
    return runs_csv, table

