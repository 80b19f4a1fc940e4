"""The `fossilc` command: a thin layer over fossil_dsl.api.

    fossilc SPEC.fsl            check, compile and synthesise (exit 0 / 1 / 2)
    fossilc check SPEC...       the static checks only (exit 0 / 2)
"""
from __future__ import annotations

import argparse
import os
import sys
from typing import Sequence

from rich.console import Console

from fossil_dsl import __version__
from fossil_dsl.api import CheckResult, check_file

EXIT_OK, EXIT_NOT_CERTIFIED, EXIT_BAD_SPEC, EXIT_INTERNAL = 0, 1, 2, 3


def _consoles() -> tuple[Console, Console]:
    return Console(highlight=False, soft_wrap=True), \
        Console(stderr=True, highlight=False, soft_wrap=True)


def _report(result: CheckResult, out: Console, err: Console, quiet: bool) -> None:
    for diagnostic in result.diagnostics:
        if quiet and not diagnostic.is_error:
            continue
        style = "red" if diagnostic.is_error else "yellow"
        err.print(diagnostic.render(result.source), style=style, markup=False)
    if result.ok:
        out.print(f"ok: {result.source.path}: {result.spec.summary()}", markup=False)


def command_check(args: argparse.Namespace) -> int:
    out, err = _consoles()
    results = [check_file(path) for path in args.specs]
    for result in results:
        _report(result, out, err, args.quiet)
    return EXIT_OK if all(r.ok for r in results) else EXIT_BAD_SPEC


def command_run(args: argparse.Namespace) -> int:
    out, err = _consoles()
    result = check_file(args.spec)
    _report(result, out, err, args.quiet)
    if not result.ok:
        return EXIT_BAD_SPEC
    err.print("fossilc: synthesis is not available yet in this version: the spec was "
              "checked, nothing was learned or proved", markup=False)
    return EXIT_BAD_SPEC


def _run_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fossilc", description="Check a .fsl spec, learn a certificate (and a "
        "controller) and prove it.",
        epilog="other commands: `fossilc check SPEC...` (run `fossilc check --help`)")
    parser.add_argument("spec", help="the .fsl file")
    parser.add_argument("-q", "--quiet", action="store_true", help="errors only")
    parser.add_argument("--version", action="version", version=f"fossilc {__version__}")
    parser.set_defaults(handler=command_run)
    return parser


def _check_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fossilc check",
                                     description="Run the static checks on .fsl specs.")
    parser.add_argument("specs", nargs="+", metavar="SPEC", help=".fsl files")
    parser.add_argument("-q", "--quiet", action="store_true", help="errors only")
    parser.set_defaults(handler=command_check)
    return parser


COMMANDS = {"check": _check_parser}


def parse_arguments(argv: Sequence[str]) -> argparse.Namespace:
    if argv and argv[0] in COMMANDS:
        return COMMANDS[argv[0]]().parse_args(argv[1:])
    return _run_parser().parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = parse_arguments(argv)
        return args.handler(args)
    except KeyboardInterrupt:
        return 130
    except Exception as exc:  # a bug in fossilc, never the user's input
        if os.environ.get("FOSSIL_DEBUG"):
            raise
        print(f"fossilc: internal error: {type(exc).__name__}: {exc} (this is a bug; "
              "set FOSSIL_DEBUG=1 for the traceback)", file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
