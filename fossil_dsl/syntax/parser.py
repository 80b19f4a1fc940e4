"""Source text -> syntax tree (fossil_dsl.syntax.ast), with labelled syntax errors."""
from __future__ import annotations

import functools
import re
from importlib import resources
from pathlib import Path

import lark
from lark import Lark, Tree

from fossil_dsl.diagnostics import Source, Span, SpecSyntaxError, error
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.brackets import BracketError, BracketTracker
from fossil_dsl.syntax.errors import describe_syntax_error
from fossil_dsl.syntax.to_ast import ToAst, meta_span

MAX_FILE_BYTES = 256_000  # parsing is linear, but a 2 MB dense expression takes ~30 s
MAX_TREE_DEPTH = 200  # the checker recurses ~3 frames a level; Python allows 1000


def _grammar_text() -> str:
    try:
        return resources.files("fossil_dsl.grammar").joinpath("fsl.lark").read_text("utf-8")
    except ModuleNotFoundError:  # a source checkout on sys.path, not installed
        return (Path(__file__).resolve().parents[2] / "grammar" / "fsl.lark").read_text("utf-8")


@functools.cache
def _lark() -> Lark:
    parser = Lark(_grammar_text(), parser="lalr", lexer="contextual", postlex=BracketTracker(),
                  propagate_positions=True, maybe_placeholders=True,
                  start=["start", "formula", "expr"])
    parser.options.postlex.keywords = {
        t.pattern.value: t.name for t in parser.terminals
        if t.pattern.type == "str" and re.fullmatch(r"[A-Za-z_]\w*", t.pattern.value)}
    return parser


def read_source(path: str | Path) -> Source:
    """Read a spec file; an unreadable, huge or non-text file is a SpecError."""
    path = Path(path)
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise SpecSyntaxError([error(f"cannot read the file: {exc.strerror or exc}")],
                              Source(str(path), "")) from None
    return decode_source(str(path), data)


def decode_source(path: str, data: bytes) -> Source:
    if len(data) > MAX_FILE_BYTES:
        raise SpecSyntaxError([error(
            f"file too large: a spec may have at most {MAX_FILE_BYTES} bytes")],
            Source(path, ""))
    try:
        return Source(path, data.decode("utf-8"))
    except UnicodeDecodeError as exc:
        text = data[:exc.start].decode("utf-8", errors="replace")
        line = text.count("\n") + 1
        column = len(text) - (text.rfind("\n") + 1) + 1
        raise SpecSyntaxError([error(
            f"not UTF-8 text: byte 0x{data[exc.start]:02x} cannot be decoded "
            "(is this a binary file?)", Span(line, column))],
            Source(path, data.decode("utf-8", errors="replace"))) from None


def parse_source(source: Source) -> ast.SpecFile:
    """Parse a spec's text; raises SpecSyntaxError with one labelled diagnostic."""
    if len(source.text) > MAX_FILE_BYTES:
        raise SpecSyntaxError([error(
            f"file too large: a spec may have at most {MAX_FILE_BYTES} characters")], source)
    text = source.text if source.text.endswith(("\n", "\r")) else source.text + "\n"
    try:
        tree = _lark().parse(text, start="start")
    except BracketError as exc:
        raise SpecSyntaxError([exc.diagnostic], source) from None
    except lark.exceptions.UnexpectedInput as exc:
        raise SpecSyntaxError([_diagnose(exc, source)], source) from None
    _check_depth(tree, source)
    statements = ToAst().transform(tree)
    return ast.SpecFile(tuple(statements), source.path)


def _diagnose(exc: lark.exceptions.UnexpectedInput, source: Source):
    unclosed = _lark().options.postlex.unclosed_before(exc.line)
    return unclosed or describe_syntax_error(exc, source)


def parse(text: str, path: str = "<string>") -> ast.SpecFile:
    return parse_source(Source(path, text))


def parse_formula(text: str) -> ast.Formula:
    """A temporal formula alone, e.g. `not U until G` (used for the property table)."""
    return _parse_fragment(text, "formula", "<formula>")


def parse_expression(text: str, path: str = "<expression>") -> ast.Expr:
    """One expression alone, e.g. `x1 - x0**3` (used to import other tools' configs);
    raises SpecSyntaxError if the text is anything else."""
    return _parse_fragment(text, "expr", path)


def _parse_fragment(text: str, start: str, path: str):
    source = Source(path, text)
    try:
        tree = _lark().parse(text, start=start)
    except (BracketError, lark.exceptions.UnexpectedInput) as exc:
        diagnostic = getattr(exc, "diagnostic", None) or describe_syntax_error(exc, source)
        raise SpecSyntaxError([diagnostic], source) from None
    _check_depth(tree, source)
    return ToAst().transform(tree)


def _check_depth(tree: Tree, source: Source) -> None:
    """Reject trees deeper than the later, recursive stages can walk."""
    stack = [(tree, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_TREE_DEPTH:
            raise SpecSyntaxError([error(
                f"expression nested too deeply (more than {MAX_TREE_DEPTH} levels); "
                "split it with constants", meta_span(node.meta))], source)
        stack.extend((child, depth + 1) for child in node.children if isinstance(child, Tree))
