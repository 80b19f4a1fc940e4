"""The Python interface; the `fossilc` command is a thin layer over these functions."""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path

from fossil_dsl.build import BespokeSet, BuildError, build_spec, spec_text
from fossil_dsl.cegis.learner import import_optimiser_support
from fossil_dsl.cegis.loop import Cegis
from fossil_dsl.check.checker import check as _check_tree
from fossil_dsl.plan import Plan, compile_spec
from fossil_dsl.kernel import Verdict, judge, not_certified
from fossil_dsl.result import Result, build_result, claim_of
from fossil_dsl.smt import registry
from fossil_dsl.smt.fallback import FallbackBackend
from fossil_dsl.diagnostics import Diagnostic, Source, SpecError, has_errors, render_all
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.parser import parse_source, read_source

# re-exported: specs built in Python are part of this API
__all__ = ["BespokeSet", "BuildError", "CheckResult", "build_spec", "check_file",
           "check_source", "check_text", "load", "loads", "parse", "spec_text", "synthesise"]


@dataclass(frozen=True)
class CheckResult:
    """The outcome of checking one spec: the checked spec (None if any error) and every
    finding, as objects; `render()` gives the `FILE:LINE:COL: ...` text."""

    source: Source
    spec: CheckedSpec | None
    diagnostics: tuple[Diagnostic, ...]

    @property
    def ok(self) -> bool:
        return self.spec is not None and not has_errors(self.diagnostics)

    @property
    def errors(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.diagnostics if d.is_error)

    @property
    def warnings(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.diagnostics if not d.is_error)

    def render(self) -> str:
        return render_all(self.diagnostics, self.source)


def parse(text: str, path: str = "<string>") -> ast.SpecFile:
    """The syntax tree of a spec; raises SpecSyntaxError (a SpecError) if it is malformed."""
    return parse_source(Source(path, text))


def check_source(source: Source) -> CheckResult:
    try:
        tree = parse_source(source)
    except SpecError as exc:
        return CheckResult(source, None, tuple(exc.diagnostics))
    report = _check_tree(tree)
    spec = report.spec and dataclasses.replace(report.spec, source=source.text)
    return CheckResult(source, spec, report.diagnostics)


def check_text(text: str, path: str = "<string>") -> CheckResult:
    """Parse and check a spec given as text; never raises for bad input."""
    return check_source(Source(path, text))


def check_file(path: str | Path) -> CheckResult:
    """Read, parse and check a spec file; never raises for bad input."""
    try:
        source = read_source(path)
    except SpecError as exc:
        return CheckResult(exc.source or Source(str(path), ""), None, tuple(exc.diagnostics))
    return check_source(source)


def synthesise(spec: CheckedSpec, progress=None, certificate=None, **options) -> Result:
    """Compile a checked spec and run CEGIS. `options` override the synthesis block:
    verifier, seed, max_iters, timeout, learning_rate, margin, digits, query_timeout,
    delta (precision of a delta-decision verifier), learn_only (train, report violation
    rates on fresh samples, prove nothing).
    `certificate` is a Certificate subclass to use instead of the registered one."""
    import_optimiser_support()
    started = time.monotonic()
    plan = compile_spec(spec, certificate=certificate, **options)
    backend = None if plan.options.learn_only else _backend(plan)
    outcome = Cegis(plan, backend, progress).run()
    return build_result(plan, outcome, _judge(plan, outcome), time.monotonic() - started)


def _judge(plan: Plan, outcome) -> Verdict:
    """The kernel's verdict on the engine's final formulas (judged afresh from the spec
    and those formulas alone; the engine's own answers are not used)."""
    if not outcome.certified:
        return not_certified(outcome.reason)
    return judge(claim_of(plan, outcome), timeout=plan.options.query_timeout,
                 delta=plan.options.delta)


def _backend(plan: Plan):
    backend = registry.load(plan.verifier, plan.options.delta)
    if plan.fallback:
        backend = FallbackBackend(backend, registry.load(plan.fallback, plan.options.delta))
    return backend


def _checked(result: CheckResult) -> CheckedSpec:
    if not result.ok:
        raise SpecError(result.errors, result.source)
    return result.spec


def load(path: str | Path) -> CheckedSpec:
    """The checked spec of a file; raises SpecError listing every error."""
    return _checked(check_file(path))


def loads(text: str, path: str = "<string>") -> CheckedSpec:
    """The checked spec of a text; raises SpecError listing every error."""
    return _checked(check_text(text, path))
