"""Puts a `fossilc bench` table next to the reference tool's figures.

    python benchmarks/compare_reference.py benchmarks/results/portfolio-10-seeds/table.csv

`reference_figures.csv` is transcribed from ../shared/benchmarks/peer-results.md: the
reference (Fossil 2.0) measured on a machine like ours (success and median seconds;
without dReal, so only 8 rows ran), and its tool paper's own figures (with dReal; min /
mean / max over all 10 runs, and the success rate). The target is a median at most half
the measured one, and 10 of 10 seeds certified.
"""
import csv
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def rows(path: Path) -> dict[str, dict]:
    with path.open() as handle:
        return {row["spec"]: row for row in csv.DictReader(handle)}


def verdict(ours: dict, reference: dict) -> str:
    done, runs = ours["success"].split("/")
    met = [done == runs]
    if reference["measured_median_s"] and ours["median s"] not in ("–", ""):
        met.append(float(ours["median s"]) <= float(reference["measured_median_s"]) / 2)
    return "yes" if all(met) else "no"


def table(ours_path: Path) -> str:
    ours, reference = rows(ours_path), rows(HERE / "reference_figures.csv")
    lines = ["| spec | success | median s | min / mean / max s | reference measured: success, median s | target median s | paper (dReal): min / mean / max s, success | target met |",
             "|---|---|---|---|---|---|---|---|"]
    for name, ref in reference.items():
        row = ours.get(name)
        if row is None:
            continue
        target = f"{float(ref['measured_median_s']) / 2:.2f}" if ref["measured_median_s"] else "–"
        measured = ref["measured_success"] + (f", {ref['measured_median_s']}"
                                              if ref["measured_median_s"] else "")
        lines.append(f"| {name} | {row['success']} | {row['median s']} | {row['min s']} / "
                     f"{row['mean s']} / {row['max s']} | {measured} | {target} | "
                     f"{ref['paper_min_s']} / {ref['paper_mean_s']} / {ref['paper_max_s']}, "
                     f"{ref['paper_success_pct']} % | {verdict(row, ref)} |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table(Path(sys.argv[1])))
