"""The post-lexer: brackets tracked (newlines inside them dropped, unclosed and mismatched
ones reported) and reserved words made keywords."""
from __future__ import annotations

from lark import Token
from lark.lark import PostLex

from fossil_dsl.diagnostics import Span, error

MAX_NESTING = 100  # open brackets at once
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
                # no statement ends with a comma: the line goes on (`certificate:
                # sigmoid(6),` then `square(6)` on the next line)
                self.swallowed_newline = (bool(self.newline_free) and self.newline_free[-1]) \
                    or (previous is not None and previous.type == "COMMA")
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
