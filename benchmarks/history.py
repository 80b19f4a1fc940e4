"""Success and median time of each benchmark across several `fossilc bench` tables, one
column per table, for docs/benchmarks.md:

    python benchmarks/history.py LABEL=TABLE_CSV ...
"""
import csv
import sys


def read(path: str) -> dict[str, dict]:
    with open(path) as handle:
        return {row["spec"]: row for row in csv.DictReader(handle)}


def cell(row: dict | None) -> str:
    if row is None:
        return "not run"
    median = row["median s"]
    return row["success"] + ("" if median in ("", "–") else f", {float(median):.2f} s")


def main(arguments: list[str]) -> None:
    labels = [a.split("=", 1)[0] for a in arguments]
    tables = [read(a.split("=", 1)[1]) for a in arguments]
    specs = sorted(set().union(*tables), key=lambda s: (s.startswith("f1_"), s))
    print("| spec | " + " | ".join(labels) + " |")
    print("|---|" + "---|" * len(labels))
    for spec in specs:
        print(f"| {spec} | " + " | ".join(cell(t.get(spec)) for t in tables) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
