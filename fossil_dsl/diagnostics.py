"""Source positions, findings (diagnostics) and the one error root of the package."""
from __future__ import annotations

import difflib
import functools
from dataclasses import dataclass, field
from enum import Enum
from typing import Iterable, Sequence


@dataclass(frozen=True)
class Span:
    """A region of source text; lines and columns count from 1, the end is exclusive."""

    line: int
    column: int
    end_line: int | None = None
    end_column: int | None = None

    def __str__(self) -> str:
        return f"{self.line}:{self.column}"


@dataclass(frozen=True)
class Source:
    """A spec's text and the name it is reported under. Line endings are normalised to
    \n (and a byte-order mark dropped) so positions mean the same everywhere."""

    path: str
    text: str

    def __post_init__(self):
        text = self.text.removeprefix("\ufeff").replace("\r\n", "\n").replace("\r", "\n")
        object.__setattr__(self, "text", text)

    @functools.cached_property
    def lines(self) -> list[str]:
        return self.text.split("\n")  # as the parser counts lines (text is normalised)

    def line_text(self, line: int) -> str:
        return self.lines[line - 1] if 0 < line <= len(self.lines) else ""


class Severity(Enum):
    ERROR = "error"
    WARNING = "warning"


@dataclass(frozen=True)
class Diagnostic:
    severity: Severity
    message: str
    span: Span | None = None
    notes: tuple[str, ...] = ()

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def render(self, source: Source | None) -> str:
        """`FILE:LINE:COL: error: message`, then the source line and a caret."""
        path = source.path if source else "<spec>"
        where = f"{path}:{self.span}" if self.span else path
        lines = [f"{where}: {self.severity.value}: {self.message}"]
        if self.span and source:
            lines.extend(_caret_lines(source, self.span))
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)


MAX_SHOWN_LINE = 200


def _caret_lines(source: Source, span: Span) -> list[str]:
    text = source.line_text(span.line)
    start = max(span.column - 1, 0)
    if len(text) > MAX_SHOWN_LINE:
        offset = max(0, start - MAX_SHOWN_LINE // 2)
        text = text[offset:offset + MAX_SHOWN_LINE]
        start -= offset
    text = "".join(c if c.isprintable() else " " if c == "\t" else "?" for c in text)
    if not text.strip():
        return []
    width = 1
    if span.end_line == span.line and span.end_column:
        width = max(1, min(span.end_column - span.column, len(text) - start))
    return [f"  {text}", "  " + " " * start + "^" * width]


def error(message: str, span: Span | None = None, *notes: str) -> Diagnostic:
    return Diagnostic(Severity.ERROR, message, span, tuple(notes))


def warning(message: str, span: Span | None = None, *notes: str) -> Diagnostic:
    return Diagnostic(Severity.WARNING, message, span, tuple(notes))


def article(noun: str) -> str:
    return f"{'an' if noun[:1] in 'aeiou' else 'a'} {noun}"


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """' (did you mean `x`?)' for the closest choice, or ''."""
    cutoff = 0.5 if len(word) <= 3 else 0.6  # `x2` should still suggest `x1`
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=cutoff)
    return f" (did you mean `{close[0]}`?)" if close else ""


class FslError(Exception):
    """Root of every error fossil_dsl raises on purpose."""


@dataclass
class SpecError(FslError, ValueError):
    """A spec that could not be read, parsed or checked; carries every finding."""

    diagnostics: Sequence[Diagnostic]
    source: Source | None = None
    _rendered: str = field(init=False, default="")

    def __post_init__(self) -> None:
        self._rendered = render_all(self.diagnostics, self.source)
        super().__init__(self._rendered)

    def __str__(self) -> str:
        return self._rendered


class SpecSyntaxError(SpecError):
    """The text is not a sentence of the .fsl grammar."""


def render_all(diagnostics: Iterable[Diagnostic], source: Source | None) -> str:
    return "\n".join(d.render(source) for d in diagnostics)


def has_errors(diagnostics: Iterable[Diagnostic]) -> bool:
    return any(d.is_error for d in diagnostics)
