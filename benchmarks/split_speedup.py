"""Split verification measured: the kernel judging a run's formulas again with the
interval procedure's queries whole, and split into the pieces of a cover checked by 1 and
2 local processes, and by 1 and 2 Dask workers on loopback (issue 26; docs/scaling.md).

    python benchmarks/split_speedup.py RESULT_DIR... [--timeout 120]

Each RESULT_DIR is what `fossilc SPEC -o DIR` wrote. Prints, per folder and setting, the
kernel's seconds in all and on the obligations the interval procedure proved.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from fossil_dsl.cluster.pieces import DaskPieces, LocalPieces
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel import Claim, judge
from fossil_dsl.outputs.load import load_result


class Timed:
    """A checker that adds up the seconds spent on split queries (the part that is
    parallel)."""

    def __init__(self, inner):
        self.inner, self.pieces = inner, inner.pieces
        self.seconds = 0.0
        self.queries = 0

    def check_all(self, query, regions, names, timeout, delta=None):
        started = time.monotonic()
        answers = self.inner.check_all(query, regions, names, timeout, delta)
        self.seconds += time.monotonic() - started
        self.queries += 1
        return answers


class DaskCluster:
    """DaskPieces on a LocalCluster of `workers` single-threaded worker processes (a
    scheduler and workers on loopback, as on a cluster)."""

    def __init__(self, workers: int):
        from distributed import Client, LocalCluster
        self.cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                    dashboard_address=None)
        self.client = Client(self.cluster)
        self.inner = DaskPieces(self.client)
        self.pieces = self.inner.pieces

    def check_all(self, query, regions, names, timeout, delta=None):
        return self.inner.check_all(query, regions, names, timeout, delta)

    def close(self):
        self.client.close()
        self.cluster.close()


def timed(claim, timeout: float, pieces) -> tuple[float, bool]:
    """(kernel seconds, certified)."""
    started = time.monotonic()
    verdict = judge(claim, timeout=timeout, pieces=pieces)
    return time.monotonic() - started, verdict.certified


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("folders", nargs="+")
    parser.add_argument("--timeout", type=float, default=120.0)
    args = parser.parse_args()
    settings = [("whole", lambda: None), ("split, 1 process", lambda: LocalPieces(1)),
                ("split, 2 processes", lambda: LocalPieces(2)),
                ("split, 1 Dask worker", lambda: DaskCluster(1)),
                ("split, 2 Dask workers", lambda: DaskCluster(2))]
    print("| run | setting | kernel s | of which split queries s (count) | certified |\n"
          "|---|---|---|---|---|")
    for folder in args.folders:
        result = load_result(folder, judge_again=False)
        claim = Claim(result.plan.spec, result.formulas, result.controller, result.levels,
                      result.plan.origin_radius, {}, result.refutations)
        for name, make in settings:
            local = make()
            pieces = Timed(local) if local is not None else None
            if local is not None:
                local.check_all(L.TRUE, [], [], 1.0)  # start the processes before timing
            try:
                total, certified = timed(claim, args.timeout, pieces)
            finally:
                if local is not None:
                    local.close()
            split = f"{pieces.seconds:.2f} ({pieces.queries})" if pieces else "–"
            print(f"| {Path(folder).name} | {name} | {total:.2f} | {split} | {certified} |",
                  flush=True)


if __name__ == "__main__":
    main()
