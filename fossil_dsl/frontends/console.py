"""What every command shares: its two consoles, its exit codes and how it reports a
spec's diagnostics."""
from __future__ import annotations

from rich.console import Console

from fossil_dsl.frontends.checking import CheckResult

EXIT_OK, EXIT_BAD_SPEC, EXIT_INTERNAL = 0, 2, 3  # 1 (not certified) comes from the result
EXIT_INTERRUPTED = 130  # Ctrl-C, as shells report SIGINT


def consoles() -> tuple[Console, Console]:
    return Console(highlight=False, soft_wrap=True), \
        Console(stderr=True, highlight=False, soft_wrap=True)


def report(result: CheckResult, out: Console, err: Console, quiet: bool,
           summary: bool = True) -> None:
    for diagnostic in result.diagnostics:
        if quiet and not diagnostic.is_error:
            continue
        style = "red" if diagnostic.is_error else "yellow"
        err.print(diagnostic.render(result.source), style=style, markup=False)
    if result.ok and summary:
        out.print(f"ok: {result.source.path}: {result.spec.summary()}", markup=False)
