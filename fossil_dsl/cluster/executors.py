"""Where jobs run: this machine's cores (child processes, no set-up) or the workers of a
Dask scheduler (`--cluster tcp://HOST:PORT`).

Both offer one operation, `run(jobs, on_done, wins)`: every job is run, its output given
to `on_done` as it arrives, and once `wins(output)` holds for one of them the others are
stopped (a race); the outputs come back in the jobs' order. Ctrl-C stops every job.

On Dask, a job whose worker dies is started again on another worker by the scheduler
(up to its `allowed-failures`); each start is logged as an event, so the output says
how many times it was started. The result is taken from the job's one future: a lost
worker neither loses nor duplicates it.
"""
from __future__ import annotations

import threading
import uuid
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import replace
from typing import Callable, Protocol, Sequence

from fossil_dsl.cluster.jobs import Job, JobOutput, run_job
from fossil_dsl.version import __version__

EVENTS = "fossil-jobs"  # the Dask event topic each job's start is logged on
CONNECT_SECONDS = 15.0


class ClusterError(Exception):
    """The cluster cannot be used (not installed, unreachable, another version)."""


Done = Callable[[int, JobOutput], None]


class Executor(Protocol):
    description: str

    def run(self, jobs: Sequence[Job], on_done: Done = lambda i, o: None,
            wins: Callable[[JobOutput], bool] = lambda o: False) -> list[JobOutput]: ...

    def close(self) -> None: ...


def _stopped() -> JobOutput:
    return JobOutput(None, "", "", 0.0, stopped=True)


class LocalExecutor:
    """Up to `workers` child processes at a time on this machine."""

    def __init__(self, workers: int):
        self.workers = max(1, workers)
        self.description = f"{self.workers} local process{'es' if self.workers > 1 else ''}"

    def run(self, jobs, on_done=lambda i, o: None, wins=lambda o: False):
        stop = threading.Event()

        def one(job: Job) -> JobOutput:
            return _stopped() if stop.is_set() else run_job(job, stop.is_set)

        outputs: list[JobOutput | None] = [None] * len(jobs)
        pool = ThreadPoolExecutor(max_workers=self.workers)
        futures = {pool.submit(one, job): i for i, job in enumerate(jobs)}
        try:
            for future in as_completed(futures):
                index = futures[future]
                outputs[index] = future.result()
                on_done(index, outputs[index])
                if wins(outputs[index]):
                    stop.set()
        finally:
            stop.set()  # on Ctrl-C (or any error) every running child is killed
            pool.shutdown(wait=True, cancel_futures=True)
        return outputs

    def close(self) -> None:
        pass


def _remote(job: Job, stop_name: str, key: str) -> JobOutput:
    """What a Dask worker runs: the job, stopped when the client sets the named event."""
    from distributed import Event, get_worker
    worker = get_worker()
    worker.log_event(EVENTS, {"job": key, "worker": worker.address})
    stop = Event(stop_name)
    return run_job(job, stop.is_set, worker=worker.address)


def _worker_version() -> str:
    from fossil_dsl.version import __version__ as version
    return version


class DaskExecutor:
    """The workers of the Dask scheduler at `address`."""

    def __init__(self, address: str):
        try:
            from distributed import Client
        except ImportError as exc:
            raise ClusterError("--cluster needs Dask: pip install 'fossil_dsl[cluster]' "
                               "(dask and distributed)") from exc
        try:
            self.client = Client(address, timeout=CONNECT_SECONDS)
        except (OSError, TimeoutError) as exc:
            raise ClusterError(f"cannot reach the Dask scheduler at {address}: {exc}") from exc
        self._check_workers(address)
        workers = len(self.client.scheduler_info(n_workers=-1)["workers"])
        self.description = f"Dask scheduler {address}, {workers} worker" \
            f"{'s' if workers != 1 else ''}"

    def _check_workers(self, address: str) -> None:
        try:
            self.client.wait_for_workers(1, timeout=CONNECT_SECONDS)
        except TimeoutError as exc:
            raise ClusterError(f"no worker joined the Dask scheduler at {address} within "
                               f"{CONNECT_SECONDS:g} s") from exc
        versions = self.client.run(_worker_version)
        other = {w: v for w, v in versions.items() if v != __version__}
        if other:
            raise ClusterError("workers with another fossil_dsl than this one "
                               f"({__version__}): " + ", ".join(f"{w} has {v}"
                                                                for w, v in other.items()))

    def run(self, jobs, on_done=lambda i, o: None, wins=lambda o: False):
        from distributed import Event, as_completed as completed
        batch = uuid.uuid4().hex[:12]
        stop = Event(f"fossil-stop-{batch}", client=self.client)
        keys = [f"fossil-{batch}-{i}" for i in range(len(jobs))]
        futures = [self.client.submit(_remote, job, stop.name, key, key=key, pure=False)
                   for job, key in zip(jobs, keys)]
        index = {future.key: i for i, future in enumerate(futures)}
        outputs: list[JobOutput | None] = [None] * len(jobs)
        try:
            for future in completed(futures):
                i = index[future.key]
                outputs[i] = replace(self._output(future),
                                     attempts=self._starts(keys[i]))
                on_done(i, outputs[i])
                if wins(outputs[i]):
                    stop.set()
                    self.client.cancel([f for f in futures if not f.done()])
        finally:
            stop.set()
            self.client.cancel([f for f in futures if not f.done()])
        return outputs

    @staticmethod
    def _output(future) -> JobOutput:
        if future.cancelled():
            return _stopped()
        try:
            return future.result()
        except Exception as exc:  # the job's worker died too often (KilledWorker), ...
            return JobOutput(None, "", f"{type(exc).__name__}: {exc}", 0.0, worker="lost")

    def _starts(self, key: str) -> int:
        """(At least 1: the scheduler keeps only the latest events of a topic.)"""
        events = self.client.get_events(EVENTS)
        return max(1, sum(1 for _, event in events if event.get("job") == key))

    def close(self) -> None:
        self.client.close()


def executor_for(cluster: str | None, local_workers: int) -> Executor:
    """The scheduler's workers with an address; else this machine's processes."""
    return DaskExecutor(cluster) if cluster else LocalExecutor(local_workers)
