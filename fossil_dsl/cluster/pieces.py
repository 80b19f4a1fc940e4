"""The pieces of a split query checked in parallel: by a pool of local processes, or by
the workers of a Dask scheduler.

A piece is the query within a region; both travel as SMT-LIB 2 scripts (exact
rationals, read back by our own reader): data, not a pickled closure. A worker compiles
the query once for all its pieces. Local workers are child processes started by
command (piece_worker.py: JSON lines on their pipes), so a user's script needs no
`if __name__ == "__main__"` guard. Each is checked by the interval procedure; once one has a
point (SAT), the others are told to stop (an event they look at every 64 boxes), and
report UNKNOWN. Which pieces make a cover, and what their answers prove, is decided
by the caller (kernel/cover.py): a checker only answers queries.
"""
from __future__ import annotations

import functools
import json
import queue
import threading
import time
import uuid
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status
from fossil_dsl.solvers.smtlib import query_text

PIECES_PER_WORKER = 4  # more pieces than workers: a hard piece does not hold up the rest


def check_piece(query: str, region: str, timeout: float, delta: float | None,
                stop=None) -> Answer:
    """One piece, the query within the region, as the interval procedure answers it
    (runs in a worker; the query's contractor is kept for its next piece)."""
    read = _read(query)
    return _backend(delta).check_within(read.formula, _read(region).formula,
                                        read.variables, timeout, stop)


@functools.lru_cache(maxsize=16)
def _read(script: str):
    from fossil_dsl.solvers.smtlib_reader import read_script
    return read_script(script)


@functools.lru_cache(maxsize=4)
def _backend(delta: float | None):
    from fossil_dsl.solvers.interval_backend import IntervalBackend
    return IntervalBackend(delta) if delta else IntervalBackend()


def _check_on_dask(query: str, region: str, timeout: float, delta: float | None,
                   stop_name: str) -> Answer:
    from distributed import Event
    return check_piece(query, region, timeout, delta, _Seldom(Event(stop_name)))


class _Seldom:
    """An event asked at most every `every` seconds (a Dask Event is a round trip to
    the scheduler; the search asks every 64 boxes)."""

    def __init__(self, event, every: float = 0.25):
        self.event, self.every = event, every
        self.asked, self.answer = 0.0, False

    def is_set(self) -> bool:
        now = time.monotonic()
        if not self.answer and now - self.asked >= self.every:
            self.asked, self.answer = now, self.event.is_set()
        return self.answer


def _scripts(query: L.Formula, regions: Sequence[L.Formula], names: Sequence[str]
             ) -> tuple[str, list[str]]:
    names = sorted(set(names) | L.free_vars(query))
    return query_text(query, names), [query_text(r, names) for r in regions]


def answer_json(answer: Answer) -> dict:
    model = None if answer.model is None else {k: str(v) for k, v in answer.model.items()}
    return {"status": answer.status.value, "model": model, "reason": answer.reason,
            "approximate": answer.approximate}


def answer_from(data: dict) -> Answer:
    model = None if data["model"] is None else \
        {k: Fraction(v) for k, v in data["model"].items()}
    return Answer(Status(data["status"]), model, data["reason"], data["approximate"],
                  "interval")


def stopped_answer() -> Answer:
    return Answer(Status.UNKNOWN, reason="stopped: another piece has a point")


class _Worker:
    """A piece worker process (piece_worker.py) and its pipes."""

    def __init__(self):
        import subprocess
        import sys
        import tempfile
        self.errors = tempfile.TemporaryFile("w+")
        self.process = subprocess.Popen(
            [sys.executable, "-m", "fossil_dsl.cluster.piece_worker"], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=self.errors, text=True, bufsize=1)
        self.lock = threading.Lock()

    def send(self, message: dict) -> None:
        with self.lock:
            self.process.stdin.write(json.dumps(message) + "\n")
            self.process.stdin.flush()

    def ask(self, message: dict) -> Answer:
        try:
            self.send(message)
            line = self.process.stdout.readline()
        except OSError:
            line = ""
        if not line:
            self.errors.seek(0)
            tail = self.errors.read()[-300:].strip()
            return Answer(Status.UNKNOWN, reason=f"the piece worker exited: {tail}")
        return answer_from(json.loads(line)["answer"])

    @property
    def alive(self) -> bool:
        return self.process.poll() is None

    def close(self) -> None:
        if self.alive:
            self.process.stdin.close()
            try:
                self.process.wait(timeout=5)
            except Exception:
                self.process.kill()
                self.process.wait()
        self.errors.close()


class LocalPieces:
    """`workers` processes on this machine (started on first use, kept until close)."""

    def __init__(self, workers: int):
        self.workers = max(1, workers)
        self.pieces = PIECES_PER_WORKER * self.workers
        self.description = f"{self.workers} local process{'es' if self.workers > 1 else ''}"
        self._started: list[_Worker] = []

    def _running(self) -> list[_Worker]:
        for worker in [w for w in self._started if not w.alive]:
            worker.close()
        self._started = [w for w in self._started if w.alive]
        self._started += [_Worker() for _ in range(self.workers - len(self._started))]
        return self._started

    def check_all(self, query, regions, names, timeout: float, delta: float | None = None
                  ) -> list[Answer]:
        """The answer for each piece (the query within each region), in order; the first
        with a point stops the others (they answer UNKNOWN)."""
        workers = self._running()
        batch = uuid.uuid4().hex[:12]
        query_script, region_scripts = _scripts(query, regions, names)
        waiting: queue.Queue = queue.Queue()
        for index in range(len(region_scripts)):
            waiting.put(index)
        answers: list[Answer] = [stopped_answer()] * len(region_scripts)
        found = threading.Event()

        def drive(worker: _Worker) -> None:
            while not found.is_set():
                try:
                    index = waiting.get_nowait()
                except queue.Empty:
                    return
                answers[index] = worker.ask({"id": index, "batch": batch,
                                             "query": query_script,
                                             "region": region_scripts[index],
                                             "timeout": timeout, "delta": delta})
                if answers[index].status is Status.SAT and not found.is_set():
                    found.set()
                    for other in workers:
                        if other is not worker and other.alive:
                            other.send({"stop": batch})

        threads = [threading.Thread(target=drive, args=(w,), daemon=True) for w in workers]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        return answers

    def close(self) -> None:
        for worker in self._started:
            worker.close()
        self._started = []


class DaskPieces:
    """The workers of a Dask scheduler (a distributed.Client)."""

    def __init__(self, client):
        self.client = client
        self.workers = max(1, len(client.scheduler_info(n_workers=-1)["workers"]))
        self.pieces = PIECES_PER_WORKER * self.workers
        self.description = f"{self.workers} Dask worker{'s' if self.workers > 1 else ''}"

    def check_all(self, query, regions, names, timeout: float, delta: float | None = None
                  ) -> list[Answer]:
        from distributed import Event
        from distributed import as_completed as completed
        stop = Event(f"fossil-pieces-{uuid.uuid4().hex[:12]}", client=self.client)
        query_script, region_scripts = _scripts(query, regions, names)
        futures = [self.client.submit(_check_on_dask, query_script, region, timeout, delta,
                                      stop.name, pure=False)
                   for region in region_scripts]
        index = {f.key: i for i, f in enumerate(futures)}
        answers: list[Answer] = [stopped_answer()] * len(futures)
        try:
            for future in completed(futures):
                answers[index[future.key]] = future.result() if not future.cancelled() \
                    else stopped_answer()
                if answers[index[future.key]].status is Status.SAT:
                    break
        finally:
            stop.set()
            self.client.cancel([f for f in futures if not f.done()])
        return answers

    def close(self) -> None:
        pass
