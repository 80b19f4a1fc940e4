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
from rich.progress import Progress, TextColumn

from fossil_dsl.diagnostics import error
from fossil_dsl.frontends import arguments
from fossil_dsl.frontends.checking import CheckResult, check_file, check_text
from fossil_dsl.plan.compile import CompileError, compile_spec
from fossil_dsl.plan.readable import loss_text, plan_text, symbolic_queries
from fossil_dsl.solvers.registry import BackendUnavailable
from fossil_dsl.version import __version__

# Learning, plotting, benchmarks and YAML import are imported by the commands that use
# them: `fossilc --help` and `fossilc check` import no torch, sympy or matplotlib.

EXIT_OK, EXIT_BAD_SPEC, EXIT_INTERNAL = 0, 2, 3  # 1 (not certified) comes from the result
EXIT_INTERRUPTED = 130  # Ctrl-C, as shells report SIGINT


def _consoles() -> tuple[Console, Console]:
    return Console(highlight=False, soft_wrap=True), \
        Console(stderr=True, highlight=False, soft_wrap=True)


def _report(result: CheckResult, out: Console, err: Console, quiet: bool,
            summary: bool = True) -> None:
    for diagnostic in result.diagnostics:
        if quiet and not diagnostic.is_error:
            continue
        style = "red" if diagnostic.is_error else "yellow"
        err.print(diagnostic.render(result.source), style=style, markup=False)
    if result.ok and summary:
        out.print(f"ok: {result.source.path}: {result.spec.summary()}", markup=False)


def command_check(args: argparse.Namespace) -> int:
    out, err = _consoles()
    good = True
    for path in args.specs:
        result = check_file(path)
        _report(result, out, err, args.quiet)
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
    out, err = _consoles()
    result = check_file(args.spec)
    _report(result, out, err, args.quiet or args.json, summary=not args.json)
    if not result.ok:
        return EXIT_BAD_SPEC
    overrides = {"verifier": args.verifier, "seed": args.seed, "max_iters": args.max_iters,
                 "timeout": args.timeout, "learn_only": args.learn_only or None}
    try:
        with _display(args, out, err) as listener:
            outcome = synthesise(result.spec, progress=listener, **overrides)
    except (CompileError, BackendUnavailable) as exc:
        _compile_error(exc, result, err)
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
    out, err = _consoles()
    result = check_file(args.spec)
    _report(result, out, err, quiet=True)
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


def command_bench(args: argparse.Namespace) -> int:
    from fossil_dsl.frontends import bench
    out, err = _consoles()
    paths = bench.spec_files(args.paths)
    if not paths:
        err.print("fossilc bench: no .fsl files found", style="red")
        return EXIT_BAD_SPEC
    total = len(paths) * args.seeds
    with Progress(*Progress.get_default_columns(), TextColumn("{task.fields[last]}"),
                  console=err, transient=True) as progress:
        task = progress.add_task("benchmarks", total=total, last="")

        def advance(run) -> None:
            progress.update(task, advance=1, last=f"{run.spec} seed {run.seed}: {run.outcome}")

        infos, runs = bench.run_all(paths, args.seeds, args.jobs, args.verifier,
                                    args.timeout, advance)
    command = (f"fossilc bench {' '.join(args.paths)} --seeds {args.seeds} --jobs {args.jobs} "
               f"--timeout {args.timeout:g} --out {args.out}"
               + (f" --verifier {args.verifier}" if args.verifier else ""))
    runs_csv, table = bench.write(Path(args.out), infos, runs, command)
    out.print(table.read_text(), markup=False)
    out.print(f"written: {runs_csv}, {table}, {table.with_suffix('.csv')}", markup=False)
    return EXIT_OK


def _bench_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fossilc bench",
                                     description="Run specs with several seeds, each in its "
                                     "own process, and tabulate success and time.")
    parser.add_argument("paths", nargs="+", metavar="FILE_OR_DIR", help=".fsl files or folders")
    parser.add_argument("--seeds", type=arguments.COUNT, default=10,
                        help="seeds 0..N-1 (default 10)")
    parser.add_argument("--jobs", type=arguments.COUNT, default=1,
                        help="runs at a time (default 1)")
    parser.add_argument("--verifier", type=arguments.SOLVER,
                        help="z3, cvc5, dreal or interval (default: per spec)")
    parser.add_argument("--timeout", type=arguments.SECONDS, default=600.0,
                        help="seconds per run (default 600)")
    parser.add_argument("--out", default="benchmarks/results/latest", type=arguments.FOLDER,
                        help="folder for runs.csv, table.csv and table.md")
    parser.set_defaults(handler=command_bench)
    return parser


def command_recheck(args: argparse.Namespace) -> int:
    from fossil_dsl.outputs import recheck
    out, err = _consoles()
    try:
        checks = recheck.recheck(args.directory, args.timeout, args.solver)
    except (recheck.RecheckError, BackendUnavailable) as exc:
        err.print(f"fossilc recheck: {exc}", style="red", markup=False)
        return EXIT_BAD_SPEC
    out.print(recheck.report_text(checks), markup=False)
    return EXIT_OK if all(c.reproved for c in checks) else 1


def _recheck_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fossilc recheck", description="Re-prove the SMT-LIB 2 obligations of a "
        "result folder (written by `fossilc SPEC -o DIR`), each with an installed solver "
        "other than the one that proved it. Exit 0 if every one is re-proved, 1 if not.")
    parser.add_argument("directory", metavar="DIR", help="the folder `-o DIR` wrote")
    parser.add_argument("--solver", type=arguments.SOLVER,
                        help="use this solver for every obligation "
                        "(default: the first suitable one that did not prove it)")
    parser.add_argument("--timeout", type=arguments.SECONDS, default=60.0,
                        help="seconds per obligation (default 60)")
    parser.set_defaults(handler=command_recheck)
    return parser


def command_import_yaml(args: argparse.Namespace) -> int:
    from fossil_dsl.frontends import yaml_import
    out, err = _consoles()
    path = Path(args.config)
    try:
        translation = yaml_import.import_yaml(path.read_text("utf-8"), path.stem)
    except (OSError, UnicodeDecodeError) as exc:
        err.print(f"fossilc import-yaml: cannot read {path}: {exc}", style="red", markup=False)
        return EXIT_BAD_SPEC
    except yaml_import.YamlImportError as exc:
        err.print(f"fossilc import-yaml: {path}: {exc}", style="red", markup=False)
        return EXIT_BAD_SPEC
    for note in translation.notes:
        err.print(f"{path}: note: {note}", style="yellow", markup=False)
    target = args.output or "<translated>"
    if args.output:
        Path(args.output).write_text(translation.text)
    else:
        out.print(translation.text, markup=False, end="")
    checked = check_text(translation.text, target)
    _report(checked, out if args.output else err, err, quiet=False, summary=bool(args.output))
    return EXIT_OK if checked.ok else EXIT_BAD_SPEC


def _import_yaml_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fossilc import-yaml", description="Translate a Fossil 2.0 YAML configuration "
        "into a .fsl spec, say what could not be translated, and check the result.")
    parser.add_argument("config", metavar="CONFIG.yaml")
    parser.add_argument("-o", "--output", metavar="SPEC.fsl", type=arguments.FILE,
                        help="write the spec here (default: print it)")
    parser.set_defaults(handler=command_import_yaml)
    return parser


COMMANDS = {"check": _check_parser, "compile": _compile_parser, "bench": _bench_parser,
            "recheck": _recheck_parser, "import-yaml": _import_yaml_parser}


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
