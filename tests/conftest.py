"""`fossilc` runs shared between test files: each command runs once per test command,
from a folder with the repository's specs and benchmarks, so the docs' tutorial commands
and the tests that look into what those commands produce share one run (the two
largest-region runs took ~4 of the test command's minutes twice). The test command runs
in several processes (pytest-xdist): a run is recorded in that folder, which they share,
and a lock per command makes the first process that asks run it and the others wait."""
from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from filelock import FileLock

ROOT = Path(__file__).resolve().parent.parent


class FossilcRuns:
    def __init__(self, folder: Path):
        self.folder = folder
        with FileLock(f"{folder}.lock"):
            folder.mkdir(exist_ok=True)
            for name in ("specs", "benchmarks"):
                if not (folder / name).exists():
                    (folder / name).symlink_to(ROOT / name)

    def __call__(self, words: list[str]) -> subprocess.CompletedProcess:
        """The finished `fossilc WORDS...` (relative paths are the folder's)."""
        digest = hashlib.sha256("\0".join(words).encode()).hexdigest()[:16]
        record = self.folder / f".run-{digest}.json"
        with FileLock(f"{record}.lock"):
            if not record.exists():
                run = subprocess.run(
                    [sys.executable, "-m", "fossil_dsl.frontends.cli", *words],
                    cwd=self.folder, capture_output=True, text=True, timeout=600,
                    env={**os.environ, "COLUMNS": "200"})
                record.write_text(json.dumps([run.args, run.returncode, run.stdout,
                                              run.stderr]))
            args, code, out, err = json.loads(record.read_text())
        return subprocess.CompletedProcess(args, code, out, err)


@pytest.fixture(scope="session")
def fossilc(tmp_path_factory) -> FossilcRuns:
    if os.environ.get("PYTEST_XDIST_WORKER") is None:  # one process: its own folder
        return FossilcRuns(tmp_path_factory.mktemp("fossilc"))
    # the workers' temporary folders lie in the test command's own
    return FossilcRuns(tmp_path_factory.getbasetemp().parent / "fossilc")
