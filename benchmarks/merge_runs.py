"""Merge the runs.csv of several `fossilc bench` runs (each over part of a portfolio, same
commit) into one table: python benchmarks/merge_runs.py OUT_DIR RUNS_CSV... The specs
are named by file, so runs made from different folders still match."""
from __future__ import annotations

import csv
import sys
from dataclasses import replace
from pathlib import Path

from fossil_dsl.frontends.bench import Run, describe, write

ROOT = Path(__file__).resolve().parent.parent


def read_runs(path: Path) -> list[Run]:
    runs = []
    with path.open() as handle:
        for row in csv.DictReader(handle):
            spec_path = ROOT / "specs" / "benchmarks" / Path(row["path"]).name
            numbers = {k: float(row[k]) if row[k] else None for k in ("total", "learn", "verify")}
            iterations = int(row["iterations"]) if row["iterations"] else None
            runs.append(Run(row["spec"], str(spec_path.relative_to(ROOT)), int(row["seed"]),
                            row["outcome"], iterations=iterations, wall=float(row["wall"]),
                            detail=row["detail"], **numbers))
    return runs


def main(out: str, sources: list[str]) -> None:
    runs = [run for source in sources for run in read_runs(Path(source))]
    paths = sorted({run.path for run in runs})
    infos = [replace(describe(ROOT / path, None), path=path) for path in paths]
    write(Path(out), infos, runs, "merged from " + ", ".join(sources))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
