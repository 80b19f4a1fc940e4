"""Turn lark's parse failures into one labelled diagnostic each.

Each labeller looks at the unexpected token and what the parser expected, and returns a
message for a common mistake, or None; the first that answers wins. The last resort
lists the expected tokens in words.
"""
from __future__ import annotations

from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from fossil_dsl.diagnostics import Diagnostic, Source, Span, did_you_mean, error

KEYWORDS = ("spec state input const dynamics continuous discrete next domain set prove "
            "from stable always eventually until and or not synthesis open pi").split()
# Shape names (box, ball, ellipsoid, ...) are reserved too; the grammar reads them as
# names, so the checker refuses them as declared names (check/context.py).
STATEMENTS = "spec state input const dynamics domain set prove synthesis".split()

_WORDS = {
    "NAME": "a name", "NUMBER": "a number", "_NL": "end of line", "$END": "end of file",
    "RELATION": "a comparison (<=, <, >=, >)", "POW": "`^`",
    "STABLE": "`stable`", "PI": "`pi`", "_FROM": "`from`",
}
_PUNCTUATION = {
    "LPAR": "(", "RPAR": ")", "LSQB": "[", "RSQB": "]", "LBRACE": "{", "RBRACE": "}",
    "EQUAL": "=", "COMMA": ",", "COLON": ":", "PLUS": "+", "MINUS": "-", "STAR": "*",
    "SLASH": "/", "VBAR": "|", "AMPERSAND": "&", "TILDE": "~", "QUOTE": "'",
}


def token_words(name: str) -> str:
    if name in _WORDS:
        return _WORDS[name]
    if name in _PUNCTUATION:
        return f"`{_PUNCTUATION[name]}`"
    return f"`{name.lower()}`"


def describe_syntax_error(exc: UnexpectedInput, source: Source) -> Diagnostic:
    if isinstance(exc, UnexpectedCharacters):
        return _unexpected_character(exc, source)
    assert isinstance(exc, UnexpectedToken)
    token = exc.token
    span = _token_span(exc, source)
    expected = _parser_expected(exc)
    if _previous_token_type(exc) == "OPEN" and token.type != "NAME":
        return error(f"`open` must be followed by a shape such as `ball(...)` or "
                     f"`box(...)`, not {_shown(token)}", span)
    for labeller in _LABELLERS:
        message = labeller(token, expected)
        if message:
            return error(message, span)
    return error(_fallback(token, expected), span)


def _parser_expected(exc: UnexpectedToken) -> set[str]:
    """The terminals the parser could take here. Errors found by the lexer report what
    the lexer tried, which includes the always-lexed NAME and newline."""
    state = exc.state
    try:
        return {name for name in state.parse_conf.states[state.position]
                if name == name.upper()}  # terminals; rules are lower-case
    except AttributeError:
        return set(exc.expected)


def _previous_token_type(exc: UnexpectedToken) -> str | None:
    stack = getattr(exc.state, "value_stack", None) or [None]
    return getattr(stack[-1], "type", None)


def _token_span(exc: UnexpectedToken, source: Source) -> Span:
    token = exc.token
    if token.type == "$END" or token.line is None:
        lines = source.text.splitlines() or [""]
        return Span(len(lines), len(lines[-1]) + 1)
    if token.type == "_NL":
        return Span(token.line, token.column)
    return Span(token.line, token.column, token.end_line, token.end_column)


def _shown(token) -> str:
    if token.type == "_NL":
        return "end of line"
    if token.type == "$END":
        return "end of file"
    text = str(token)
    return f"`{text[:30]}`"


def _fallback(token, expected) -> str:
    words = sorted({token_words(name) for name in expected})
    listed = ", ".join(words[:8]) + (", ..." if len(words) > 8 else "")
    return f"unexpected {_shown(token)}; expected {listed}"


# ---- labellers: (token, expected terminal names) -> message or None -------------
def _keyword_as_name(token, expected):
    if "NAME" in expected and str(token) in KEYWORDS and token.type != "NAME":
        return f"`{token}` is a reserved keyword and cannot be used as a name"
    return None


def _string_literal(token, expected):
    if str(token) in ("'", '"'):
        return ("strings are not part of the .fsl language (a spec never runs code); "
                "a prime `'` may only follow a state on the left of an equation")
    return None


def _unknown_statement(token, expected):
    if token.type == "NAME" and "STATE" in expected and "PROVE" in expected:
        hint = did_you_mean(str(token), STATEMENTS)
        if not hint and not ("DOMAIN" in expected and "SET" in expected):
            return None
        return f"unknown statement `{token}`{hint}; a statement starts with one of: " + \
            ", ".join(STATEMENTS)
    return None


def _missing_equals(token, expected):
    if "EQUAL" in expected and token.type not in ("_NL", "$END"):
        return f"missing `=` before {_shown(token)}"
    if "EQUAL" in expected:
        return "missing `=` and a value"
    return None


def _time_domain(token, expected):
    if "CONTINUOUS" in expected and "DISCRETE" in expected:
        hint = did_you_mean(str(token), ["continuous", "discrete"])
        return f"`dynamics` must be followed by `continuous` or `discrete`, not " \
               f"{_shown(token)}{hint}"
    return None


def _incomplete(token, expected):
    if token.type in ("_NL", "$END"):
        words = sorted({token_words(name) for name in expected})[:6]
        return "incomplete statement: it ends here but needs " + " or ".join(words)
    return None


def _missing_comma(token, expected):
    if "COMMA" in expected and token.type in ("NAME", "NUMBER"):
        return f"unexpected {_shown(token)}: is a `,` missing before it?"
    return None


def _missing_operator(token, expected):
    operators = {"PLUS", "STAR", "MINUS", "SLASH"}
    if operators <= expected and token.type in ("NAME", "NUMBER", "LPAR", "PI"):
        return f"unexpected {_shown(token)}: is an operator (such as `*`) missing before it?"
    return None


def _stray_closer(token, expected):
    if token.type in ("RPAR", "RSQB", "RBRACE"):
        return f"stray {_shown(token)}: something is missing before it; expected " + \
            ", ".join(sorted({token_words(n) for n in expected})[:6])
    return None


_LABELLERS = (_string_literal, _keyword_as_name, _unknown_statement, _time_domain,
              _missing_equals, _incomplete, _missing_operator,
              _missing_comma, _stray_closer)


# ---- characters the lexer cannot read ---------------------------------------------
_CHARACTER_HINTS = {
    ".": "attribute access and `.` outside numbers are not part of the language",
    ";": "`;` is not used: put each statement on its own line",
    '"': "strings are not part of the .fsl language (a spec never runs code)",
    "\\": "`\\` continues a line only as the last character of the line",
    "=": "unexpected `=`",
    "!": "`!` is not an operator: write `not` in formulas",
}


def _unexpected_character(exc: UnexpectedCharacters, source: Source) -> Diagnostic:
    char = exc.char
    span = Span(exc.line, exc.column, exc.line, exc.column + 1)
    if char in _CHARACTER_HINTS:
        return error(_CHARACTER_HINTS[char], span)
    if not char.isprintable() or char.isspace():
        return error(f"unexpected character U+{ord(char):04X} (not allowed in a spec)",
                     span)
    return error(f"unexpected character `{char}`", span)
