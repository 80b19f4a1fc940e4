"""The commands around a run: `fossilc bench`, `fossilc recheck` and `fossilc
import-yaml` (each imports what it needs when it runs)."""
from __future__ import annotations

import argparse
from pathlib import Path

from rich.progress import Progress, TextColumn

from fossil_dsl.frontends import arguments
from fossil_dsl.frontends.checking import check_text
from fossil_dsl.frontends.console import (EXIT_BAD_SPEC, EXIT_INTERRUPTED, EXIT_OK, consoles,
                                          report)
from fossil_dsl.solvers.registry import BackendUnavailable


def command_bench(args: argparse.Namespace) -> int:
    from fossil_dsl.cluster.executors import ClusterError, executor_for
    from fossil_dsl.frontends import bench
    out, err = consoles()
    paths = bench.spec_files(args.paths)
    if not paths:
        err.print("fossilc bench: no .fsl files found", style="red")
        return EXIT_BAD_SPEC
    try:
        executor = executor_for(args.cluster, args.jobs)
    except ClusterError as exc:
        err.print(f"fossilc bench: {exc}", style="red", markup=False)
        return EXIT_BAD_SPEC
    total = len(paths) * args.seeds
    planned = None
    try:
        with Progress(*Progress.get_default_columns(), TextColumn("{task.fields[last]}"),
                      console=err, transient=True) as progress:
            task = progress.add_task(f"benchmarks ({executor.description})", total=total,
                                     last="")

            def advance(run) -> None:
                line = f"{run.spec} seed {run.seed}: {run.outcome}"
                progress.update(task, advance=1, last=line)
                if not err.is_terminal:  # a log gets one line per run; a bar shows nothing
                    err.print(f"{line} ({run.wall:.1f} s)", markup=False, highlight=False)

            infos, runs = bench.run_all(paths, args.seeds, args.jobs, args.verifier,
                                        args.timeout, advance, executor)
    except bench.Interrupted as stop:  # every job stopped: keep what had finished
        infos, runs, planned = stop.infos, stop.runs, stop.planned
    finally:
        executor.close()
    command = (f"fossilc bench {' '.join(args.paths)} --seeds {args.seeds} --jobs {args.jobs} "
               f"--timeout {args.timeout:g} --out {args.out}"
               + (f" --verifier {args.verifier}" if args.verifier else "")
               + (f" --cluster {args.cluster}" if args.cluster else ""))
    where = executor.description if args.cluster else ""
    runs_csv, table = bench.write(Path(args.out), infos, runs, command, where, planned)
    out.print(table.read_text(), markup=False)
    out.print(f"written: {runs_csv}, {table}, {table.with_suffix('.csv')}", markup=False)
    if planned is not None:
        err.print(f"fossilc bench: interrupted; {len(runs)} of {planned} runs had finished",
                  style="red", markup=False)
        return EXIT_INTERRUPTED
    return EXIT_OK


def bench_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fossilc bench",
                                     description="Run specs with several seeds, each in its "
                                     "own process, and tabulate success and time.")
    parser.add_argument("paths", nargs="+", metavar="FILE_OR_DIR", help=".fsl files or folders")
    parser.add_argument("--seeds", type=arguments.COUNT, default=10,
                        help="seeds 0..N-1 (default 10)")
    parser.add_argument("--jobs", type=arguments.COUNT, default=1,
                        help="runs at a time on this machine (default 1)")
    parser.add_argument("--cluster", metavar="ADDRESS", type=arguments.SCHEDULER_ADDRESS,
                        help="run on the workers of the Dask scheduler at tcp://HOST:PORT "
                        "(needs the [cluster] extra; --jobs is then ignored)")
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
    out, err = consoles()
    try:
        checks = recheck.recheck(args.directory, args.timeout, args.solver)
    except (recheck.RecheckError, BackendUnavailable) as exc:
        err.print(f"fossilc recheck: {exc}", style="red", markup=False)
        return EXIT_BAD_SPEC
    out.print(recheck.report_text(checks), markup=False)
    return EXIT_OK if all(c.reproved for c in checks) else 1


def recheck_parser() -> argparse.ArgumentParser:
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
    out, err = consoles()
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
    report(checked, out if args.output else err, err, quiet=False, summary=bool(args.output))
    return EXIT_OK if checked.ok else EXIT_BAD_SPEC


def import_yaml_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="fossilc import-yaml", description="Translate a Fossil 2.0 YAML configuration "
        "into a .fsl spec, say what could not be translated, and check the result.")
    parser.add_argument("config", metavar="CONFIG.yaml")
    parser.add_argument("-o", "--output", metavar="SPEC.fsl", type=arguments.FILE,
                        help="write the spec here (default: print it)")
    parser.set_defaults(handler=command_import_yaml)
    return parser
