"""Which guarantee does each spec get? Certify each (seed 0) and write one CSV row per spec:
certified or not, the kernel's strengthening (e.g. "never leaves D" for safety, "no ball
left out" for stability with a delta-decision verifier), the seconds, and a recheck of
the exported obligations.

    python benchmarks/guarantees.py specs/barrierbench/*.fsl --timeout 120 --out FILE.csv

One spec at a time, in this process (the numbers are for the table of
docs/benchmarks.md, not timings: `fossilc bench` times runs).
"""
from __future__ import annotations

import argparse
import csv
import sys
import tempfile
import time

import fossil_dsl
from fossil_dsl.outputs.recheck import recheck

COLUMNS = ("spec", "certified", "strengthening", "seconds", "rechecked", "not_rechecked")


def row(path: str, timeout: float, recheck_timeout: float) -> dict:
    started = time.monotonic()
    result = fossil_dsl.synthesise(fossil_dsl.load(path), seed=0, timeout=timeout)
    seconds = time.monotonic() - started
    found = {"spec": path, "certified": result.certified,
             "strengthening": result.kernel.strengthened or "",
             "seconds": f"{seconds:.2f}", "rechecked": "", "not_rechecked": ""}
    if result.certified:
        with tempfile.TemporaryDirectory() as folder:
            result.save(folder)
            checks = recheck(folder, timeout=recheck_timeout)
        found["rechecked"] = sum(c.reproved for c in checks)
        found["not_rechecked"] = " ".join(f"{c.condition}:{c.status}" for c in checks
                                          if not c.reproved)
    return found


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("specs", nargs="+")
    parser.add_argument("--timeout", type=float, default=120)
    parser.add_argument("--recheck-timeout", type=float, default=20)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    with open(args.out, "w", newline="") as handle:
        writer = csv.DictWriter(handle, COLUMNS)
        writer.writeheader()
        for path in args.specs:
            found = row(path, args.timeout, args.recheck_timeout)
            writer.writerow(found)
            handle.flush()
            print(", ".join(f"{k}={v}" for k, v in found.items()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
