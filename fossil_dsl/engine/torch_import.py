"""torch, imported when a run first learns, with the seconds the import took recorded.

A run that never learns (a sum-of-squares certificate, a conserved quantity, given
functions) does not import torch at all: it and torch._dynamo, which torch's optimisers
import on their first step, were 2-3 s of a 4.5 s `fossilc` call whose proof took 0.1 s.
A run that learns imports them here; the time it took is start-up, like every other
library's import (frontends/api.py), so the API leaves it out of the run's time and
moves the run's deadlines on by it."""
from __future__ import annotations

import importlib
import sys
import time

_spent = 0.0  # seconds spent importing, over the process's life


def learning_support():
    """torch, with what its optimisers import on first use; imported on the first call."""
    global _spent
    if "torch._dynamo" not in sys.modules:
        started = time.monotonic()
        importlib.import_module("torch._dynamo")
        _spent += time.monotonic() - started
    return sys.modules["torch"]


def seconds_spent() -> float:
    """Seconds spent in learning_support's imports so far (compare two readings)."""
    return _spent
