"""Reading, parsing and checking specs: the part of the Python interface that learns
nothing, and so imports no torch, sympy or plotting (`fossilc check` stays fast)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from fossil_dsl.check.checker import check as _check_tree
from fossil_dsl.diagnostics import Diagnostic, Source, SpecError, has_errors, render_all
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.parser import parse_source, read_source


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
