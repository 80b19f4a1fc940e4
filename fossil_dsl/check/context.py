"""What the checker's passes share: the findings so far and the declared names."""
from __future__ import annotations

from dataclasses import dataclass, field

from fossil_dsl.diagnostics import Diagnostic, Span, article, error, warning
from fossil_dsl.ir.expr import Expr
from fossil_dsl.ir.sets import SHAPES
from fossil_dsl.syntax import ast


@dataclass
class Declared:
    kind: str  # "state", "input", "constant", "set"
    ident: ast.Ident


@dataclass
class CheckContext:
    diagnostics: list[Diagnostic] = field(default_factory=list)
    names: dict[str, Declared] = field(default_factory=dict)
    states: list[str] = field(default_factory=list)
    inputs: list[str] = field(default_factory=list)
    constants: dict[str, Expr] = field(default_factory=dict)
    used: set[str] = field(default_factory=set)

    def error(self, message: str, span: Span | None, *notes: str) -> None:
        self.diagnostics.append(error(message, span, *notes))

    def warning(self, message: str, span: Span | None, *notes: str) -> None:
        self.diagnostics.append(warning(message, span, *notes))

    def declare(self, kind: str, ident: ast.Ident) -> bool:
        """Record a name; a second declaration is an error and returns False."""
        if ident.text in SHAPES:
            self.error(f"`{ident.text}` is a reserved keyword (a set shape) and cannot be "
                       "used as a name", ident.span)
            return False
        previous = self.names.get(ident.text)
        if previous is not None:
            where = previous.ident.span
            self.error(f"`{ident.text}` is already declared as {article(previous.kind)} "
                       f"at {where.line}:{where.column}", ident.span)
            return False
        self.names[ident.text] = Declared(kind, ident)
        return True

    def kind_of(self, name: str) -> str | None:
        declared = self.names.get(name)
        return declared.kind if declared else None
