"""`fossilc` runs shared between test files: each command runs once per session, from a
folder with the repository's specs and benchmarks, so the docs' tutorial commands and
the tests that look into what those commands produce share one run (the two
largest-region runs took ~4 of the test command's minutes twice)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


class FossilcRuns:
    def __init__(self, folder: Path):
        self.folder = folder
        for name in ("specs", "benchmarks"):
            (folder / name).symlink_to(ROOT / name)
        self.done: dict[tuple[str, ...], subprocess.CompletedProcess] = {}

    def __call__(self, words: list[str]) -> subprocess.CompletedProcess:
        """The finished `fossilc WORDS...` (relative paths are the folder's)."""
        key = tuple(words)
        if key not in self.done:
            env = {**os.environ, "COLUMNS": "200"}
            self.done[key] = subprocess.run(
                [sys.executable, "-m", "fossil_dsl.frontends.cli", *words], cwd=self.folder,
                capture_output=True, text=True, timeout=600, env=env)
        return self.done[key]


@pytest.fixture(scope="session")
def fossilc(tmp_path_factory) -> FossilcRuns:
    return FossilcRuns(tmp_path_factory.mktemp("fossilc"))
