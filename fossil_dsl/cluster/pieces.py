"""The pieces of a split query checked in parallel: by a pool of local processes, or by
the workers of a Dask scheduler.

A piece travels as an SMT-LIB 2 script (exact rationals, read back by our own reader):
data, not a pickled closure. Each is checked by the interval procedure; once one has a
point (SAT), the others are told to stop (a shared event they look at every 64 boxes),
and report UNKNOWN. Which pieces make a cover, and what their answers prove, is decided
by the caller (kernel/cover.py): a checker only answers queries.
"""
from __future__ import annotations

import threading
import uuid
from concurrent.futures import as_completed
from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status
from fossil_dsl.solvers.smtlib import query_text

PIECES_PER_WORKER = 4  # more pieces than workers: a hard piece does not hold up the rest


def check_piece(script: str, timeout: float, delta: float | None, stop=None) -> Answer:
    """One piece, as the interval procedure answers it (runs in a worker)."""
    from fossil_dsl.solvers.interval_backend import IntervalBackend
    from fossil_dsl.solvers.smtlib_reader import read_script
    read = read_script(script)
    backend = IntervalBackend(delta) if delta else IntervalBackend()
    return backend.check(read.formula, read.variables, timeout, stop)


def _check_on_dask(script: str, timeout: float, delta: float | None, stop_name: str) -> Answer:
    from distributed import Event
    return check_piece(script, timeout, delta, Event(stop_name))


def _scripts(formulas: Sequence[L.Formula], names: Sequence[str]) -> list[str]:
    return [query_text(f, sorted(set(names) | L.free_vars(f))) for f in formulas]


def _stopped() -> Answer:
    return Answer(Status.UNKNOWN, reason="stopped: another piece has a point")


class LocalPieces:
    """`workers` processes on this machine (started once, on first use)."""

    def __init__(self, workers: int):
        self.workers = max(1, workers)
        self.pieces = PIECES_PER_WORKER * self.workers
        self.description = f"{self.workers} local process{'es' if self.workers > 1 else ''}"
        self._pool = self._manager = None
        self._lock = threading.Lock()

    def _start(self):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor
        with self._lock:
            if self._pool is None:
                # not fork: the parent has torch's and the solvers' threads running
                context = multiprocessing.get_context("forkserver")
                self._manager = context.Manager()
                self._pool = ProcessPoolExecutor(self.workers, mp_context=context)
        return self._pool, self._manager

    def check_all(self, formulas, names, timeout: float, delta: float | None = None
                  ) -> list[Answer]:
        pool, manager = self._start()
        stop = manager.Event()
        futures = {pool.submit(check_piece, script, timeout, delta, stop): i
                   for i, script in enumerate(_scripts(formulas, names))}
        return _gather(futures, stop.set, lambda: [f.cancel() for f in futures])

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._manager.shutdown()
            self._pool = self._manager = None


class DaskPieces:
    """The workers of a Dask scheduler (a distributed.Client)."""

    def __init__(self, client):
        self.client = client
        self.workers = max(1, len(client.scheduler_info(n_workers=-1)["workers"]))
        self.pieces = PIECES_PER_WORKER * self.workers
        self.description = f"{self.workers} Dask worker{'s' if self.workers > 1 else ''}"

    def check_all(self, formulas, names, timeout: float, delta: float | None = None
                  ) -> list[Answer]:
        from distributed import Event
        from distributed import as_completed as completed
        stop = Event(f"fossil-pieces-{uuid.uuid4().hex[:12]}", client=self.client)
        futures = [self.client.submit(_check_on_dask, script, timeout, delta, stop.name,
                                      pure=False)
                   for script in _scripts(formulas, names)]
        index = {f.key: i for i, f in enumerate(futures)}
        answers: list[Answer] = [_stopped()] * len(futures)
        try:
            for future in completed(futures):
                answers[index[future.key]] = future.result() if not future.cancelled() \
                    else _stopped()
                if answers[index[future.key]].status is Status.SAT:
                    break
        finally:
            stop.set()
            self.client.cancel([f for f in futures if not f.done()])
        return answers

    def close(self) -> None:
        pass


def _gather(futures: dict, stop, cancel) -> list[Answer]:
    """The answers in order; the first SAT stops the rest (they count as UNKNOWN)."""
    answers: list[Answer] = [_stopped()] * len(futures)
    try:
        for future in as_completed(futures):
            if future.cancelled():
                continue
            answers[futures[future]] = future.result()
            if answers[futures[future]].status is Status.SAT:
                break
    finally:
        stop()
        cancel()
    return answers
