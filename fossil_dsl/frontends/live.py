"""What `fossilc SPEC` shows while it runs: a live line on a terminal (iteration, what
the loop is doing, counterexamples so far, the failing conditions, elapsed and remaining
time), or one plain line per iteration with --verbose."""
from __future__ import annotations

import time

from rich.console import Console
from rich.live import Live
from rich.spinner import Spinner
from rich.table import Table
from rich.text import Text

from fossil_dsl.engine.loop import IterationRecord, Listener
from fossil_dsl.solvers.api import Status


class LiveDisplay(Listener):
    """Two lines on standard error, redrawn four times a second and removed when the run
    ends (the summary follows). Use as a context manager around the run."""

    def __init__(self, console: Console):
        self.spinner = Spinner("dots")
        self.started = time.monotonic()
        self.timeout = None
        self.max_iters = 0
        self.doing = "starting"
        self.counterexamples = 0
        self.failing = ""
        self.live = Live(console=console, transient=True, refresh_per_second=4,
                         get_renderable=self.render)

    def __enter__(self) -> "LiveDisplay":
        self.live.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        self.live.__exit__(*exc)

    def render(self) -> Table:
        elapsed = time.monotonic() - self.started
        clock = _minutes(elapsed) + (f" of {_minutes(self.timeout)} "
                                     f"({_minutes(max(0.0, self.timeout - elapsed))} left)"
                                     if self.timeout is not None else "")
        found = f"{self.counterexamples} counterexample" + \
            ("" if self.counterexamples == 1 else "s")
        lines = Text(f"{self.doing}   {clock}\n{found}")
        if self.failing:
            lines.append(f"; not yet proved: {self.failing}", style="yellow")
        grid = Table.grid(padding=(0, 1))
        grid.add_row(self.spinner, lines)
        return grid

    def start(self, plan) -> None:
        """(Again for each attempt of a run; the clock runs from the display's start.)"""
        self.max_iters = plan.options.max_iters
        self.timeout = plan.options.timeout

    def phase(self, iteration: int, text: str) -> None:
        """(Iteration 0: before the loop, e.g. the sum-of-squares attempt.)"""
        self.doing = f"iteration {iteration}/{self.max_iters}: {text}" if iteration else text

    def finished(self, record: IterationRecord) -> None:
        self.counterexamples += sum(v.status is Status.SAT for v in record.verdicts)
        self.failing = ", ".join(record.failed)


def _minutes(seconds: float) -> str:
    whole = int(seconds)
    return f"{whole // 60}:{whole % 60:02d}"


class IterationLines(Listener):
    """One line per iteration (for logs): loss, failing conditions, times."""

    def __init__(self, console: Console):
        self.console = console

    def finished(self, record: IterationRecord) -> None:
        failed = ", ".join(record.failed) or "none"
        self.console.print(f"  iteration {record.iteration:3d}  loss {record.loss:10.3g}  "
                           f"failed: {failed:<24}  learn {record.learn_seconds:6.2f} s  "
                           f"verify {record.verify_seconds:6.2f} s", markup=False, style="dim")
