"""A Pygments lexer for .fsl specs, registered as the `fsl` lexer (pyproject's
`pygments.lexers` entry point), so docs, notebooks and `rich` highlight specs.

The words come from where the language defines them: the keywords of the syntax, the
registered set shapes and the functions of the IR.
"""
from __future__ import annotations

from pygments.lexer import RegexLexer, words
from pygments.token import Comment, Error, Keyword, Name, Number, Operator, Punctuation, Whitespace

from fossil_dsl.ir.functions import FUNCTIONS
from fossil_dsl.ir.sets import SHAPES
from fossil_dsl.syntax.errors import KEYWORDS


class FslLexer(RegexLexer):
    name = "FSL"
    aliases = ["fsl"]
    filenames = ["*.fsl"]
    mimetypes = ["text/x-fsl"]

    tokens = {"root": [
        (r"#[^\r\n]*", Comment.Single),
        (r"\s+", Whitespace),
        (words(tuple(KEYWORDS), suffix=r"\b"), Keyword),
        (words(tuple(SHAPES), suffix=r"\b"), Name.Builtin),
        (words(tuple(FUNCTIONS), suffix=r"\b"), Name.Function),
        (r"(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", Number),
        (r"[A-Za-z_][A-Za-z0-9_]*", Name),
        (r"<=|>=|\*\*|[-+*/^<>=|&~:']", Operator),
        (r"[()\[\]{},]", Punctuation),
        (r".", Error),
    ]}
