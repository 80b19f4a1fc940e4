"""The `fossilc` command: a thin layer over fossil_dsl.frontends.api.

    fossilc SPEC.fsl            check, compile and synthesise (exit 0 / 1 / 2)
    fossilc check SPEC...       the static checks only (exit 0 / 2)
    fossilc compile SPEC        the certificate plan, its SMT-LIB queries or its losses
    fossilc bench FILES_OR_DIRS every spec with several seeds, tabulated
    fossilc recheck DIR         re-prove a result's obligations with another solver
    fossilc import-yaml CONFIG  a Fossil 2.0 YAML configuration as a .fsl spec
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
from pathlib import Path
from typing import Sequence

from rich.console import Console

from fossil_dsl.diagnostics import error
from fossil_dsl.frontends import arguments
from fossil_dsl.frontends.checking import CheckResult, check_file
from fossil_dsl.frontends.console import (EXIT_BAD_SPEC, EXIT_INTERNAL, EXIT_INTERRUPTED,
                                          EXIT_OK, consoles, report)
from fossil_dsl.frontends.tools import bench_parser, import_yaml_parser, recheck_parser
from fossil_dsl.plan.compile import CompileError, compile_spec
from fossil_dsl.plan.readable import loss_text, plan_text, symbolic_queries
from fossil_dsl.solvers.registry import BackendUnavailable
from fossil_dsl.version import __version__

# Learning, plotting, benchmarks and YAML import are imported by the commands that use
# them: `fossilc --help` and `fossilc check` import no torch, sympy or matplotlib.


def command_check(args: argparse.Namespace) -> int:
    out, err = consoles()
    good = True
    for path in args.specs:
        result = check_file(path)
        report(result, out, err, args.quiet)
        good = good and result.ok and _report_verifier(result, out, err)
    return EXIT_OK if good else EXIT_BAD_SPEC


def _report_verifier(result: CheckResult, out: Console, err: Console) -> bool:
    """Which verifier a run would use, and why (False if the spec cannot be compiled)."""
    try:
        plan = compile_spec(result.spec)
    except (CompileError, BackendUnavailable) as exc:
        _compile_error(exc, result, err)
        return False
    out.print(f"  verifier: {plan.verifier} ({plan.verifier_reason})", markup=False)
    return True


def command_run(args: argparse.Namespace) -> int:
    from fossil_dsl.frontends.api import synthesise
    from fossil_dsl.outputs.artefacts import write_artefacts
    from fossil_dsl.outputs.summary import summary_text
    out, err = consoles()
    result = check_file(args.spec)
    report(result, out, err, args.quiet or args.json, summary=not args.json)
    if not result.ok:
        return EXIT_BAD_SPEC
    overrides = {"verifier": args.verifier, "seed": args.seed, "max_iters": args.max_iters,
                 "timeout": args.timeout, "learn_only": args.learn_only or None}
    try:
        if args.split:
            outcome = _split_run(result.spec, args, overrides, out, err)
        elif args.portfolio or args.cluster:
            outcome = _race(result.spec, args, overrides, err)
        else:
            with _display(args, out, err) as listener:
                outcome = synthesise(result.spec, progress=listener, **overrides)
    except (CompileError, BackendUnavailable) as exc:
        _compile_error(exc, result, err)
        return EXIT_BAD_SPEC
    if outcome is None:
        return EXIT_BAD_SPEC
    if args.output:
        write_artefacts(outcome, args.output)
    if args.plot and not outcome.interrupted and not _write_plots(outcome, args, err):
        return EXIT_BAD_SPEC
    if args.json:
        print(json.dumps(outcome.to_json(), indent=2))
    else:
        style = "bold green" if outcome.certified else "bold red"
        out.print(summary_text(outcome), style=style if args.quiet else None, markup=False)
    return outcome.exit_code


def _split_run(spec, args: argparse.Namespace, overrides: dict, out: Console, err: Console):
    """One run whose interval queries are split into pieces checked in parallel by
    --split N local processes, or by the workers of --cluster; None after saying why it
    cannot run."""
    from fossil_dsl.cluster.executors import ClusterError, DaskExecutor
    from fossil_dsl.cluster.pieces import DaskPieces, LocalPieces
    from fossil_dsl.frontends.api import synthesise
    if args.portfolio:
        err.print("fossilc: --split and --portfolio both use the workers: choose one",
                  style="red", markup=False)
        return None
    try:
        executor = DaskExecutor(args.cluster) if args.cluster else None
    except ClusterError as exc:
        err.print(f"fossilc: {exc}", style="red", markup=False)
        return None
    pieces = DaskPieces(executor.client) if executor else LocalPieces(args.split)
    if not (args.quiet or args.json):
        err.print(f"interval queries split into {pieces.pieces + 1} pieces on "
                  f"{pieces.description}", markup=False)
    try:
        with _display(args, out, err) as listener:
            return synthesise(spec, progress=listener, pieces=pieces, **overrides)
    finally:
        pieces.close()
        if executor:
            executor.close()


def _race(spec, args: argparse.Namespace, overrides: dict, err: Console):
    """The portfolio's Result, or None after saying why it cannot run."""
    from fossil_dsl.cluster.executors import ClusterError, LocalExecutor, executor_for
    from fossil_dsl.frontends.portfolio import PortfolioError, race
    count = args.portfolio or 1
    if args.learn_only:
        err.print("fossilc: --portfolio and --cluster race strategies to a certificate; "
                  "--learn-only proves nothing (run it alone)", style="red", markup=False)
        return None
    try:
        executor = executor_for(args.cluster, count) if args.cluster else LocalExecutor(count)
    except ClusterError as exc:
        err.print(f"fossilc: {exc}", style="red", markup=False)
        return None
    talk = not (args.quiet or args.json)
    if talk:
        err.print(f"racing {count} strateg{'y' if count == 1 else 'ies'} on "
                  f"{executor.description}", markup=False)

    def finished(report) -> None:
        if talk:
            err.print(f"  {report.strategy}: {report.verdict} after {report.seconds:.1f} s"
                      + (f" ({report.detail})" if report.verdict not in ("certified", "stopped")
                         else ""), markup=False)
    try:
        return race(spec, count, executor, finished, **overrides)
    except PortfolioError as exc:
        err.print(f"fossilc: {exc}", style="red", markup=False)
        return None
    finally:
        executor.close()


def _write_plots(outcome, args: argparse.Namespace, err: Console) -> bool:
    """phase_portrait.png and .svg in the -o folder, else SPECNAME_portrait.* here."""
    from fossil_dsl.outputs.plot import PlotError, write_portraits
    stem = Path(args.output) / "phase_portrait" if args.output else \
        Path(f"{outcome.plan.spec.name}_portrait")
    try:
        written = write_portraits(outcome, stem)
    except PlotError as exc:
        err.print(f"fossilc: {exc}", style="red", markup=False)
        return False
    err.print("phase portrait: " + ", ".join(str(p) for p in written), markup=False)
    return True


def _compile_error(exc: Exception, result: CheckResult, err: Console) -> None:
    diagnostic = exc.diagnostic() if isinstance(exc, CompileError) else error(str(exc))
    err.print(diagnostic.render(result.source), style="red", markup=False)


def _display(args: argparse.Namespace, out: Console, err: Console):
    """A live line on a terminal, a line per iteration with --verbose, else nothing
    (output to a file or a pipe stays plain)."""
    from fossil_dsl.frontends.live import IterationLines, LiveDisplay
    if args.quiet or args.json:
        return contextlib.nullcontext(None)
    if args.verbose:
        return contextlib.nullcontext(IterationLines(err))
    if out.is_terminal and err.is_terminal:
        return LiveDisplay(err)
    return contextlib.nullcontext(None)


def command_compile(args: argparse.Namespace) -> int:
    out, err = consoles()
    result = check_file(args.spec)
    report(result, out, err, quiet=True)
    if not result.ok:
        return EXIT_BAD_SPEC
    try:
        plan = compile_spec(result.spec, verifier=args.verifier)
    except (CompileError, BackendUnavailable) as exc:
        _compile_error(exc, result, err)
        return EXIT_BAD_SPEC
    if args.emit == "plan" or args.explain:
        out.print(plan_text(plan, explain=args.explain), markup=False)
    if args.emit == "smt2":
        for name, script in symbolic_queries(plan).items():
            out.print(script, markup=False)
    if args.emit == "losses":
        out.print(loss_text(plan), markup=False)
    return EXIT_OK


def _run_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fossilc", description="Check a .fsl spec, learn a certificate (and a "
        "controller) and prove it.",
        epilog="other commands: `fossilc check SPEC...`, `fossilc compile SPEC --emit "
        "plan|smt2|losses`, `fossilc bench FILES_OR_DIRS`, `fossilc recheck DIR`, `fossilc import-yaml CONFIG.yaml` (each has --help)")
    parser.add_argument("spec", help="the .fsl file")
    parser.add_argument("-o", "--output", metavar="DIR", type=arguments.FOLDER,
                        help="write result.json, certificate.txt and obligations/*.smt2 "
                        "(the folder is created, and checked writable, before the run)")
    parser.add_argument("--verifier", type=arguments.SOLVER,
                        help="z3, cvc5, dreal or interval")
    parser.add_argument("--seed", type=arguments.SEED,
                        help="random seed, 0 or more (the same seed, the same run)")
    parser.add_argument("--max-iters", type=arguments.ITERATIONS,
                        help="CEGIS iterations before giving up (at least 1)")
    parser.add_argument("--timeout", type=arguments.SECONDS,
                        help="seconds for the whole run (positive)")
    parser.add_argument("--learn-only", action="store_true",
                        help="train without verifying; report how many fresh samples "
                        "violate each condition (nothing is proved)")
    parser.add_argument("--portfolio", metavar="N", type=arguments.COUNT,
                        help="race N strategies (seeds S, S+1, ...) in parallel processes; "
                        "the first the kernel certifies wins, the others are stopped")
    parser.add_argument("--cluster", metavar="ADDRESS", type=arguments.SCHEDULER_ADDRESS,
                        help="run the strategies (or, with --split, the pieces) on the "
                        "workers of the Dask scheduler at tcp://HOST:PORT (needs the "
                        "[cluster] extra)")
    parser.add_argument("--split", metavar="N", type=arguments.COUNT,
                        help="split the interval procedure's queries (in the loop and in "
                        "the kernel) into pieces checked by N local processes, or by the "
                        "workers of --cluster")
    parser.add_argument("--plot", action="store_true",
                        help="draw the phase portrait (2- and 3-state specs) as PNG and SVG: "
                        "DIR/phase_portrait.* with -o DIR, else SPECNAME_portrait.*")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress, errors only")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="a line per CEGIS iteration (loss, failing conditions, times) "
                        "instead of the live display")
    parser.add_argument("--json", action="store_true", help="print result.json on stdout")
    parser.add_argument("--version", action="version", version=f"fossilc {__version__}")
    parser.set_defaults(handler=command_run)
    return parser


def _compile_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fossilc compile",
                                     description="Show the certificate plan of a spec.")
    parser.add_argument("spec", help="the .fsl file")
    parser.add_argument("--emit", choices=["plan", "smt2", "losses"], default="plan")
    parser.add_argument("--explain", action="store_true",
                        help="also print the plan and the guarantee in words")
    parser.add_argument("--verifier", type=arguments.SOLVER,
                        help="z3, cvc5, dreal or interval")
    parser.set_defaults(handler=command_compile)
    return parser


def _check_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fossilc check",
                                     description="Run the static checks on .fsl specs.")
    parser.add_argument("specs", nargs="+", metavar="SPEC", help=".fsl files")
    parser.add_argument("-q", "--quiet", action="store_true", help="errors only")
    parser.set_defaults(handler=command_check)
    return parser


COMMANDS = {"check": _check_parser, "compile": _compile_parser, "bench": bench_parser,
            "recheck": recheck_parser, "import-yaml": import_yaml_parser}


def parse_arguments(argv: Sequence[str]) -> argparse.Namespace:
    if argv and argv[0] in COMMANDS:
        return COMMANDS[argv[0]]().parse_args(argv[1:])
    return _run_parser().parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        args = parse_arguments(argv)
        return args.handler(args)
    except KeyboardInterrupt:  # outside a run's loop (which stops with a summary)
        print("fossilc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:  # a bug in fossilc, never the user's input
        if os.environ.get("FOSSIL_DEBUG"):
            raise
        print(f"fossilc: internal error: {type(exc).__name__}: {exc} (this is a bug; "
              "set FOSSIL_DEBUG=1 for the traceback)", file=sys.stderr)
        return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
