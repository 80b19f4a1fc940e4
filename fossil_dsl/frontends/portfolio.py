"""`fossilc SPEC --portfolio N`: N strategies race on one spec; the first whose result
the kernel certifies wins and the others are stopped.

A strategy is a seed (the run's seed, then the next ones): every seed is a different
initial network, sample set and counterexample history, and the seed alone repeats a
run, so the winner stays repeatable from what the result names (`--seed S`). Each
strategy is a job (cluster/jobs.py): the spec's text goes out, the run's files come back,
and the winner's result is read back with `load_result`, which has this machine's kernel
judge its formulas again: a worker's "certified" is never taken on trust.
"""
from __future__ import annotations

import json
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable

from fossil_dsl.cluster.executors import Executor, executor_for
from fossil_dsl.cluster.jobs import Job, JobOutput, write_files
from fossil_dsl.frontends.arguments import OptionError, check_options, scheduler_address, whole
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.kernel import not_certified
from fossil_dsl.plan.compile import compile_spec


SENT = {"seed", "timeout", "verifier", "max_iters", "learn_only"}  # the options a job carries


class PortfolioError(Exception):
    """No strategy left a result to read (every one crashed or was killed)."""


@dataclass(frozen=True)
class Finished:
    """What the race reports as each strategy ends."""
    strategy: str
    verdict: str  # certified, not certified, stopped, crashed, killed
    seconds: float
    detail: str = ""


def seeds_for(count: int, first: int) -> list[int]:
    return list(range(first, first + count))


def race(spec: CheckedSpec, strategies: int = 2, executor: Executor | None = None,
         on_finished: Callable[[Finished], None] = lambda f: None, cluster: str | None = None,
         **options):
    """The winning strategy's Result (judged again here), or the first strategy's
    not-certified one. The strategies run on `executor`, else on the workers of the Dask
    scheduler at `cluster` (tcp://HOST:PORT), else in local processes, all at once.
    `options` as for `synthesise` (seed is the first strategy's)."""
    count = whole(strategies, 1, "strategies")
    if executor is None:
        owned = executor_for(cluster and scheduler_address(cluster), count)
        try:
            return race(spec, count, owned, on_finished, **options)
        finally:
            owned.close()
    return _race(spec, count, executor, on_finished, options)


def _race(spec: CheckedSpec, count: int, executor: Executor, on_finished, options: dict):
    from fossil_dsl.outputs.load import load_result
    options = check_options(options)
    if options.get("learn_only"):
        raise OptionError("a portfolio races strategies to a certificate; learn_only "
                          "proves nothing (run it alone)")
    unsent = sorted(k for k, v in options.items() if v is not None and k not in SENT)
    if unsent:
        raise OptionError(f"a portfolio's runs take {', '.join(sorted(SENT))} only; put "
                          f"{', '.join(unsent)} in the spec's synthesis block instead")
    plan = compile_spec(spec, **options)  # a bad option or spec fails here, before any job
    jobs = [Job(spec.source, spec.name, seed, plan.options.timeout, options.get("verifier"),
                keep_files=True, label=f"seed {seed}", max_iters=options.get("max_iters"))
            for seed in seeds_for(count, plan.options.seed)]
    started = time.monotonic()
    outputs = executor.run(jobs, lambda i, o: on_finished(_finished(jobs[i], o)), _certified)
    seconds = time.monotonic() - started
    winner = next((i for i, o in enumerate(outputs) if _certified(o)), None)
    chosen = winner if winner is not None else next(
        (i for i, o in enumerate(outputs) if o.files), None)
    if chosen is None:
        raise PortfolioError("no strategy left a result: " + "; ".join(
            f"{job.label}: {_finished(job, o).detail}" for job, o in zip(jobs, outputs)))
    with tempfile.TemporaryDirectory(prefix="fossil-portfolio-") as folder:
        result = load_result(write_files(outputs[chosen].files, Path(folder)),
                             judge_again=winner is not None,
                             timeout=plan.options.query_timeout)
    if winner is not None and not result.certified:
        reason = f"{jobs[winner].label} reported a certificate that this machine's kernel " \
            f"does not prove: {result.reason}"
        record = _record(jobs, outputs, None, executor.description, seconds)
        return replace(result, reason=reason, portfolio=record, total_seconds=seconds)
    record = _record(jobs, outputs, winner, executor.description, seconds)
    if winner is None:
        reason = "no strategy certified: " + "; ".join(
            f"{job.label}: {_reason(o)}" for job, o in zip(jobs, outputs))
        return replace(result, certified=False, reason=reason, kernel=not_certified(reason),
                       portfolio=record, total_seconds=seconds)
    return replace(result, portfolio=record, total_seconds=seconds,
                   strategy=f"{jobs[winner].label} of {count} racing: {result.strategy}")


def _certified(output: JobOutput) -> bool:
    return output.returncode == 0 and _data(output).get("verdict") == "certified"


def _data(output: JobOutput) -> dict:
    try:
        return json.loads(output.stdout) if output.stdout else {}
    except json.JSONDecodeError:
        return {}


def _reason(output: JobOutput) -> str:
    if output.stopped:
        return "stopped (another strategy won)"
    if output.returncode is None:
        return "killed past its deadline" if output.worker != "lost" else output.stderr
    data = _data(output)
    if not data:
        lines = [line for line in output.stderr.splitlines() if line.strip()]
        return f"exit {output.returncode}: {lines[-1] if lines else 'no output'}"
    return data.get("reason", data.get("verdict", ""))


def _finished(job: Job, output: JobOutput) -> Finished:
    verdict = "stopped" if output.stopped else "killed" if output.returncode is None \
        else _data(output).get("verdict", "crashed")
    return Finished(job.label, verdict, output.wall, _reason(output))


def _record(jobs, outputs, winner: int | None, where: str, seconds: float) -> dict:
    """The race as result.json keeps it: each strategy, the winner and how to repeat it."""
    record = {"strategies": [{"strategy": job.label, "seed": job.seed,
                              "outcome": _finished(job, output).verdict,
                              "worker": output.worker, "attempts": output.attempts}
                             for job, output in zip(jobs, outputs)],
              "where": where, "seconds": round(seconds, 3), "winner": None}
    if winner is not None:
        record["winner"] = jobs[winner].label
        record["repeat"] = f"--seed {jobs[winner].seed}"
    return record
