"""The syntax tree of a .fsl file: frozen dataclasses, every node with its span."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union

from fossil_dsl.diagnostics import Span


@dataclass(frozen=True)
class Ident:
    text: str
    span: Span


# ---- expressions -------------------------------------------------------------
@dataclass(frozen=True)
class Number:
    text: str
    span: Span


@dataclass(frozen=True)
class Name:
    name: str
    span: Span


@dataclass(frozen=True)
class Pi:
    span: Span


@dataclass(frozen=True)
class Unary:
    op: str  # "-" or "+"
    operand: "Expr"
    span: Span


@dataclass(frozen=True)
class Binary:
    op: str  # "+", "-", "*", "/", "^"
    left: "Expr"
    right: "Expr"
    span: Span


@dataclass(frozen=True)
class Call:
    func: Ident
    args: tuple["Expr", ...]
    span: Span


Expr = Union[Number, Name, Pi, Unary, Binary, Call]


# ---- sets --------------------------------------------------------------------
@dataclass(frozen=True)
class Vector:
    items: tuple[Expr, ...]
    span: Span


@dataclass(frozen=True)
class Shape:
    kind: str  # "box", "ball", "ellipsoid"
    args: tuple[Union[Vector, Expr], ...]
    is_open: bool
    span: Span


@dataclass(frozen=True)
class Constraint:
    left: Expr
    relation: str  # "<=", "<", ">=", ">"
    right: Expr
    span: Span


@dataclass(frozen=True)
class Semialgebraic:
    constraints: tuple[Constraint, ...]
    span: Span


@dataclass(frozen=True)
class SetRef:
    name: str
    span: Span


@dataclass(frozen=True)
class SetBinary:
    op: str  # "|", "&", "-"
    left: "SetExpr"
    right: "SetExpr"
    span: Span


@dataclass(frozen=True)
class SetComplement:
    operand: "SetExpr"
    span: Span


SetExpr = Union[Shape, Semialgebraic, SetRef, SetBinary, SetComplement]


# ---- temporal formulas -------------------------------------------------------
@dataclass(frozen=True)
class FSet:
    name: str
    span: Span


@dataclass(frozen=True)
class FStable:
    span: Span


@dataclass(frozen=True)
class FUnary:
    op: str  # "not", "always", "eventually"
    operand: "Formula"
    span: Span


@dataclass(frozen=True)
class FBinary:
    op: str  # "and", "or", "until"
    left: "Formula"
    right: "Formula"
    span: Span


Formula = Union[FSet, FStable, FUnary, FBinary]


# ---- statements --------------------------------------------------------------
@dataclass(frozen=True)
class SpecDecl:
    name: Ident
    span: Span


@dataclass(frozen=True)
class StateDecl:
    names: tuple[Ident, ...]
    span: Span


@dataclass(frozen=True)
class InputDecl:
    names: tuple[Ident, ...]
    span: Span


@dataclass(frozen=True)
class ConstDef:
    name: Ident
    value: Expr
    span: Span


@dataclass(frozen=True)
class ConstDecl:
    definitions: tuple[ConstDef, ...]
    span: Span


@dataclass(frozen=True)
class Equation:
    form: str  # "derivative" (x' =), "next" (next(x) =) or "plain" (x =)
    state: Ident
    value: Expr
    span: Span


@dataclass(frozen=True)
class DynamicsDecl:
    time: str  # "continuous" or "discrete"
    equations: tuple[Equation, ...]
    span: Span


@dataclass(frozen=True)
class DomainDecl:
    value: SetExpr
    span: Span


@dataclass(frozen=True)
class SetDecl:
    name: Ident
    value: SetExpr
    span: Span


@dataclass(frozen=True)
class ProveDecl:
    initial: SetExpr | None
    formula: Formula
    span: Span


@dataclass(frozen=True)
class NamedCount:
    """`init 500` inside `samples:`; `domain 500` has the name `domain`."""

    name: Ident
    count: Number
    span: Span


OptionItem = Union[Expr, NamedCount]


@dataclass(frozen=True)
class Option:
    key: Ident
    items: tuple[OptionItem, ...]
    span: Span


@dataclass(frozen=True)
class SynthesisDecl:
    options: tuple[Option, ...]
    span: Span


Statement = Union[SpecDecl, StateDecl, InputDecl, ConstDecl, DynamicsDecl,
                  DomainDecl, SetDecl, ProveDecl, SynthesisDecl]


@dataclass(frozen=True)
class SpecFile:
    statements: tuple[Statement, ...]
    path: str
