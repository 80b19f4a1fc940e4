"""Source text -> syntax tree (fossil_dsl.syntax.ast), with labelled syntax errors."""
from __future__ import annotations

import functools
import re
from importlib import resources
from pathlib import Path

import lark
from lark import Lark, Token, Transformer, Tree, v_args
from lark.lark import PostLex

from fossil_dsl.diagnostics import Source, Span, SpecSyntaxError, error
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.errors import describe_syntax_error

MAX_FILE_BYTES = 256_000  # parsing is linear, but a 2 MB dense expression takes ~30 s
MAX_NESTING = 100  # open brackets at once
MAX_TREE_DEPTH = 200  # the checker recurses ~3 frames a level; Python allows 1000

STATEMENT_WORDS = ("spec", "state", "input", "const", "dynamics", "domain", "set", "prove",
                   "synthesis")
_CLOSERS = {"RPAR": "LPAR", "RSQB": "LSQB", "RBRACE": "LBRACE"}
# A `{` after these opens a block, where newlines separate lines; any other `{` is a
# set { C1, C2 } and, like ( ) and [ ], ignores newlines.
_BLOCK_OPENERS = {"CONTINUOUS", "DISCRETE", "SYNTHESIS"}


class BracketError(Exception):
    """Raised by the post-lexer; carries a finished diagnostic."""

    def __init__(self, diagnostic):
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


def token_span(token: Token) -> Span:
    return Span(token.line, token.column, token.end_line, token.end_column)


class BracketTracker(PostLex):
    """Drops newlines inside ( ) and [ ]; reports unclosed and mismatched brackets.

    It also makes every reserved word a keyword token: the contextual lexer would
    otherwise read `next` as a name where no keyword is expected.
    """

    # NAME everywhere, so that `states` is one name and never the keyword `state` + `s`.
    always_accept = ("_NL", "NAME")

    def __init__(self):
        self.keywords: dict[str, str] = {}  # reserved word -> its terminal's name
        self.opened: list[Token] = []
        self.newline_free: list[bool] = []  # for each open bracket
        self.swallowed_newline = False  # the last newline was inside ( ), [ ] or a set

    def process(self, stream):
        self.opened, self.newline_free = [], []
        self.swallowed_newline = after_newline = False
        previous = None
        for token in stream:
            if token.type == "_NL":
                after_newline = True
                self.swallowed_newline = bool(self.newline_free) and self.newline_free[-1]
                if not self.swallowed_newline:
                    yield token
                continue
            if token.type == "NAME" and token.value in self.keywords:
                token = Token.new_borrow_pos(self.keywords[token.value], token.value, token)
            if after_newline and self.opened and token.value in STATEMENT_WORDS:
                raise BracketError(_unclosed(self.opened[-1]))
            after_newline = False
            self._track(token, previous)
            previous = token
            yield token
            self.swallowed_newline = False
        if self.opened:
            raise BracketError(_unclosed(self.opened[-1]))

    def unclosed_before(self, line: int):
        """The unclosed bracket to blame for an error at `line`, right after a newline
        that the bracket swallowed."""
        if self.swallowed_newline and self.opened and self.opened[-1].line < line:
            return _unclosed(self.opened[-1])
        return None

    def _track(self, token: Token, previous: Token | None) -> None:
        if token.type in ("LPAR", "LSQB", "LBRACE"):
            if len(self.opened) >= MAX_NESTING:
                raise BracketError(error(
                    f"brackets nested too deeply (more than {MAX_NESTING} levels)",
                    token_span(token)))
            self.opened.append(token)
            block = token.type == "LBRACE" and previous is not None \
                and previous.type in _BLOCK_OPENERS
            self.newline_free.append(not block)
        elif token.type in _CLOSERS:
            _close(token, self.opened)
            self.newline_free.pop()


def _close(token: Token, opened: list[Token]) -> None:
    if not opened:
        raise BracketError(error(f"unmatched `{token}`: nothing to close here",
                                 token_span(token)))
    if opened[-1].type != _CLOSERS[token.type]:
        start = opened[-1]
        raise BracketError(error(
            f"`{token}` does not match `{start}` opened at {start.line}:{start.column}",
            token_span(token)))
    opened.pop()


_BRACKET_NAMES = {"LPAR": "parenthesis `(`", "LSQB": "bracket `[`", "LBRACE": "brace `{`"}


def _unclosed(token: Token):
    return error(f"unclosed {_BRACKET_NAMES[token.type]}: it is never closed",
                 token_span(token))


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
    source = Source("<formula>", text)
    try:
        tree = _lark().parse(text, start="formula")
    except (BracketError, lark.exceptions.UnexpectedInput) as exc:
        diagnostic = getattr(exc, "diagnostic", None) or describe_syntax_error(exc, source)
        raise SpecSyntaxError([diagnostic], source) from None
    return ToAst().transform(tree)


def parse_expression(text: str, path: str = "<expression>") -> ast.Expr:
    """One expression alone, e.g. `x1 - x0**3` (used to import other tools' configs);
    raises SpecSyntaxError if the text is anything else."""
    source = Source(path, text)
    try:
        tree = _lark().parse(text, start="expr")
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
                "split it with constants", _meta_span(node.meta))], source)
        stack.extend((child, depth + 1) for child in node.children if isinstance(child, Tree))


def _meta_span(meta) -> Span:
    if getattr(meta, "empty", True):
        return Span(1, 1)
    return Span(meta.line, meta.column, meta.end_line, meta.end_column)


def _ident(token: Token) -> ast.Ident:
    return ast.Ident(str(token), token_span(token))


def _present(children) -> tuple:
    return tuple(child for child in children if child is not None)


@v_args(meta=True)
class ToAst(Transformer):
    """Lark parse tree -> frozen dataclasses. One method per grammar alternative."""

    def start(self, meta, children):
        return children

    # ---- declarations ----
    def spec_decl(self, meta, children):
        return ast.SpecDecl(_ident(children[0]), _meta_span(meta))

    def state_decl(self, meta, children):
        return ast.StateDecl(tuple(map(_ident, children)), _meta_span(meta))

    def input_decl(self, meta, children):
        return ast.InputDecl(tuple(map(_ident, children)), _meta_span(meta))

    def const_decl(self, meta, children):
        return ast.ConstDecl(tuple(children), _meta_span(meta))

    def const_def(self, meta, children):
        return ast.ConstDef(_ident(children[0]), children[1], _meta_span(meta))

    def dynamics_decl(self, meta, children):
        time, *equations = _present(children)
        return ast.DynamicsDecl(str(time), tuple(equations), _meta_span(meta))

    def derivative_eq(self, meta, children):
        return ast.Equation("derivative", _ident(children[0]), children[1], _meta_span(meta))

    def next_eq(self, meta, children):
        return ast.Equation("next", _ident(children[0]), children[1], _meta_span(meta))

    def plain_eq(self, meta, children):
        return ast.Equation("plain", _ident(children[0]), children[1], _meta_span(meta))

    def domain_decl(self, meta, children):
        return ast.DomainDecl(children[0], _meta_span(meta))

    def set_decl(self, meta, children):
        return ast.SetDecl(_ident(children[0]), children[1], _meta_span(meta))

    def prove_decl(self, meta, children):
        return ast.ProveDecl(children[0], children[1], _meta_span(meta))

    def synthesis_decl(self, meta, children):
        return ast.SynthesisDecl(_present(children), _meta_span(meta))

    def option(self, meta, children):
        return ast.Option(_ident(children[0]), tuple(children[1:]), _meta_span(meta))

    def named_count(self, meta, children):
        name, count = children
        return ast.NamedCount(_ident(name), ast.Number(str(count), token_span(count)),
                              _meta_span(meta))

    def domain_count(self, meta, children):
        count = children[0]
        span = _meta_span(meta)
        return ast.NamedCount(ast.Ident("domain", span),
                              ast.Number(str(count), token_span(count)), span)

    # ---- sets ----
    def _set_binary(op):
        def build(self, meta, children):
            return ast.SetBinary(op, children[0], children[1], _meta_span(meta))
        return build

    set_union = _set_binary("|")
    set_intersection = _set_binary("&")
    set_difference = _set_binary("-")

    def set_complement(self, meta, children):
        return ast.SetComplement(children[0], _meta_span(meta))

    def shape(self, meta, children):
        kind, *args = children
        return ast.Shape(str(kind), _present(args), False, _meta_span(meta))

    def open_shape(self, meta, children):
        shape = children[0]
        return ast.Shape(shape.kind, shape.args, True, _meta_span(meta))

    def vector(self, meta, children):
        return ast.Vector(_present(children), _meta_span(meta))

    def semialgebraic(self, meta, children):
        return ast.Semialgebraic(tuple(children), _meta_span(meta))

    def constraint(self, meta, children):
        left, relation, right = children
        return ast.Constraint(left, str(relation), right, _meta_span(meta))

    def set_ref(self, meta, children):
        return ast.SetRef(str(children[0]), token_span(children[0]))

    # ---- formulas ----
    def _formula_binary(op):
        def build(self, meta, children):
            return ast.FBinary(op, children[0], children[1], _meta_span(meta))
        return build

    f_or = _formula_binary("or")
    f_and = _formula_binary("and")
    f_until = _formula_binary("until")

    def _formula_unary(op):
        def build(self, meta, children):
            return ast.FUnary(op, children[0], _meta_span(meta))
        return build

    f_not = _formula_unary("not")
    f_always = _formula_unary("always")
    f_eventually = _formula_unary("eventually")

    def f_set(self, meta, children):
        return ast.FSet(str(children[0]), token_span(children[0]))

    def f_stable(self, meta, children):
        return ast.FStable(token_span(children[0]))

    # ---- expressions ----
    def _binary(op):
        def build(self, meta, children):
            return ast.Binary(op, children[0], children[-1], _meta_span(meta))
        return build

    add = _binary("+")
    sub = _binary("-")
    mul = _binary("*")
    div = _binary("/")
    pow = _binary("^")

    def neg(self, meta, children):
        return ast.Unary("-", children[0], _meta_span(meta))

    def pos(self, meta, children):
        return ast.Unary("+", children[0], _meta_span(meta))

    def number(self, meta, children):
        return ast.Number(str(children[0]), token_span(children[0]))

    def name(self, meta, children):
        return ast.Name(str(children[0]), token_span(children[0]))

    def pi(self, meta, children):
        return ast.Pi(token_span(children[0]))

    def call(self, meta, children):
        func, *args = children
        return ast.Call(_ident(func), _present(args), _meta_span(meta))
