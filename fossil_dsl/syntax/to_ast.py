"""Lark parse tree -> syntax tree (fossil_dsl.syntax.ast), positions kept."""
from __future__ import annotations

from typing import NamedTuple

from lark import Token, Transformer, v_args

from fossil_dsl.diagnostics import Span
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.brackets import token_span


def meta_span(meta) -> Span:
    if getattr(meta, "empty", True):
        return Span(1, 1)
    return Span(meta.line, meta.column, meta.end_line, meta.end_column)


def _ident(token: Token) -> ast.Ident:
    return ast.Ident(str(token), token_span(token))


def _present(children) -> tuple:
    return tuple(child for child in children if child is not None)


class _OptionHead(NamedTuple):
    name: ast.Ident


def _options(pieces):
    """`NAME: item, item, NAME: item` (heads and items in source order) -> Options."""
    heads = [i for i, piece in enumerate(pieces) if isinstance(piece, _OptionHead)]
    for start, end in zip(heads, heads[1:] + [len(pieces)]):
        name, values = pieces[start].name, tuple(pieces[start + 1:end])
        last = values[-1].span
        span = Span(name.span.line, name.span.column, last.end_line, last.end_column)
        yield ast.Option(name, values, span)


@v_args(meta=True)
class ToAst(Transformer):
    """Lark parse tree -> frozen dataclasses. One method per grammar alternative."""

    def start(self, meta, children):
        return children

    # ---- declarations ----
    def spec_decl(self, meta, children):
        return ast.SpecDecl(_ident(children[0]), meta_span(meta))

    def state_decl(self, meta, children):
        return ast.StateDecl(tuple(map(_ident, children)), meta_span(meta))

    def input_decl(self, meta, children):
        return ast.InputDecl(tuple(map(_ident, children)), meta_span(meta))

    def const_decl(self, meta, children):
        return ast.ConstDecl(tuple(children), meta_span(meta))

    def const_def(self, meta, children):
        return ast.ConstDef(_ident(children[0]), children[1], meta_span(meta))

    def dynamics_decl(self, meta, children):
        time, *equations = _present(children)
        return ast.DynamicsDecl(str(time), tuple(equations), meta_span(meta))

    def derivative_eq(self, meta, children):
        return ast.Equation("derivative", _ident(children[0]), children[1], meta_span(meta))

    def next_eq(self, meta, children):
        return ast.Equation("next", _ident(children[0]), children[1], meta_span(meta))

    def plain_eq(self, meta, children):
        return ast.Equation("plain", _ident(children[0]), children[1], meta_span(meta))

    def domain_decl(self, meta, children):
        return ast.DomainDecl(children[0], meta_span(meta))

    def set_decl(self, meta, children):
        return ast.SetDecl(_ident(children[0]), children[1], meta_span(meta))

    def prove_decl(self, meta, children):
        return ast.ProveDecl(children[0], children[1], meta_span(meta))

    def synthesis_decl(self, meta, children):
        return ast.SynthesisDecl(tuple(_options(_present(children))), meta_span(meta))

    def option_head(self, meta, children):
        return _OptionHead(_ident(children[0]))

    def named_count(self, meta, children):
        name, count = children
        return ast.NamedCount(_ident(name), ast.Number(str(count), token_span(count)),
                              meta_span(meta))

    def domain_count(self, meta, children):
        count = children[0]
        span = meta_span(meta)
        return ast.NamedCount(ast.Ident("domain", span),
                              ast.Number(str(count), token_span(count)), span)

    # ---- sets ----
    def _set_binary(op):
        def build(self, meta, children):
            return ast.SetBinary(op, children[0], children[1], meta_span(meta))
        return build

    set_union = _set_binary("|")
    set_intersection = _set_binary("&")
    set_difference = _set_binary("-")

    def set_complement(self, meta, children):
        return ast.SetComplement(children[0], meta_span(meta))

    def shape(self, meta, children):
        kind, *args = children
        return ast.Shape(str(kind), _present(args), False, meta_span(meta))

    def open_shape(self, meta, children):
        shape = children[0]
        return ast.Shape(shape.kind, shape.args, True, meta_span(meta))

    def vector(self, meta, children):
        return ast.Vector(_present(children), meta_span(meta))

    def semialgebraic(self, meta, children):
        return ast.Semialgebraic(tuple(children), meta_span(meta))

    def constraint(self, meta, children):
        left, relation, right = children
        return ast.Constraint(left, str(relation), right, meta_span(meta))

    def set_ref(self, meta, children):
        return ast.SetRef(str(children[0]), token_span(children[0]))

    # ---- formulas ----
    def _formula_binary(op):
        def build(self, meta, children):
            return ast.FBinary(op, children[0], children[1], meta_span(meta))
        return build

    f_or = _formula_binary("or")
    f_and = _formula_binary("and")
    f_until = _formula_binary("until")

    def _formula_unary(op):
        def build(self, meta, children):
            return ast.FUnary(op, children[0], meta_span(meta))
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
            return ast.Binary(op, children[0], children[-1], meta_span(meta))
        return build

    add = _binary("+")
    sub = _binary("-")
    mul = _binary("*")
    div = _binary("/")
    pow = _binary("^")

    def neg(self, meta, children):
        return ast.Unary("-", children[0], meta_span(meta))

    def pos(self, meta, children):
        return ast.Unary("+", children[0], meta_span(meta))

    def number(self, meta, children):
        return ast.Number(str(children[0]), token_span(children[0]))

    def name(self, meta, children):
        return ast.Name(str(children[0]), token_span(children[0]))

    def pi(self, meta, children):
        return ast.Pi(token_span(children[0]))

    def call(self, meta, children):
        func, *args = children
        return ast.Call(_ident(func), _present(args), meta_span(meta))
