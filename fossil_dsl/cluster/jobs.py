"""One run of `fossilc` on a spec's text, as a job any executor can run: on this machine
or on a Dask worker elsewhere.

What travels is data, not code: the spec's text, its options and, back, the run's
stdout (result.json) and the files `-o` wrote, as bytes. The run itself is a child
process (`python -m fossil_dsl.frontends.cli`), so a crash in a solver, a run past its
deadline or a stop from the client ends that process and nothing else.
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

GRACE = 60.0  # s past its own deadline after which a run is killed
POLL = 0.25  # s between looks at the run and at the stop flag


@dataclass(frozen=True)
class Job:
    text: str  # the spec's source
    name: str  # the spec's name (and the file's stem on the worker)
    seed: int
    timeout: float  # the run's own deadline (--timeout)
    verifier: str | None = None
    max_iters: int | None = None
    keep_files: bool = False  # return what `-o DIR` writes (result.json, networks...)
    label: str = ""  # what the job is, for progress and tables

    def command(self, spec_file: Path, output: Path | None) -> list[str]:
        command = [sys.executable, "-m", "fossil_dsl.frontends.cli", str(spec_file), "--json",
                   "-q", "--seed", str(self.seed), "--timeout", str(self.timeout)]
        if self.verifier:
            command += ["--verifier", self.verifier]
        if self.max_iters:
            command += ["--max-iters", str(self.max_iters)]
        if output is not None:
            command += ["-o", str(output)]
        return command


@dataclass(frozen=True)
class JobOutput:
    returncode: int | None  # None: killed (past its deadline, or stopped)
    stdout: str
    stderr: str
    wall: float  # seconds of the child process, start-up included
    stopped: bool = False  # ended because the client asked (another strategy won)
    files: dict[str, bytes] = field(default_factory=dict)  # relative path -> content
    worker: str = "local"
    attempts: int = 1  # times the job was started (more: a worker was lost)


def run_job(job: Job, should_stop: Callable[[], bool] = lambda: False,
            worker: str = "local") -> JobOutput:
    """Run the job in a child process; stop it once `should_stop()` says so."""
    with tempfile.TemporaryDirectory(prefix="fossil-job-") as folder:
        spec_file = Path(folder) / f"{job.name}.fsl"
        spec_file.write_text(job.text)
        output = Path(folder) / "result" if job.keep_files else None
        started = time.monotonic()
        with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
            child = subprocess.Popen(job.command(spec_file, output), stdout=out, stderr=err,
                                     text=True)
            returncode, stopped = _wait(child, job.timeout + GRACE, should_stop)
            wall = time.monotonic() - started
            out.seek(0)
            err.seek(0)
            stdout, stderr = out.read(), err.read()
        files = _files(output) if output is not None and returncode is not None else {}
        return JobOutput(returncode, stdout, stderr[-4000:], wall, stopped, files, worker)


def _wait(child: subprocess.Popen, limit: float, should_stop) -> tuple[int | None, bool]:
    """(exit code or None if it was killed, whether it was stopped on request)."""
    deadline = time.monotonic() + limit
    while True:
        try:
            return child.wait(timeout=POLL), False
        except subprocess.TimeoutExpired:
            pass
        stop = should_stop()
        if stop or time.monotonic() > deadline:
            child.kill()
            child.wait()
            return None, stop


def _files(folder: Path) -> dict[str, bytes]:
    if not folder.is_dir():
        return {}
    return {str(path.relative_to(folder)): path.read_bytes()
            for path in sorted(folder.rglob("*")) if path.is_file()}


def write_files(files: dict[str, bytes], folder: Path) -> Path:
    """A job's files written under `folder` (created); the folder."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, content in files.items():
        target = folder / name
        if Path(name).is_absolute() or ".." in Path(name).parts:
            raise ValueError(f"a job returned a file outside its folder: {name}")
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(content)
    return folder
