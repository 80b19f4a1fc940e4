"""Syntax-tree set expressions -> neutral sets (fossil_dsl.ir.sets).

Declared sets are built on first use, so they may be declared in any order; a set
defined in terms of itself is an error. A failed set is None, and so is anything
built from it, so one mistake is reported once.
"""
from __future__ import annotations

from fossil_dsl.check.context import CheckContext
from fossil_dsl.check.expressions import ExpressionChecker
from fossil_dsl.diagnostics import Span, article, did_you_mean
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.syntax import ast

MAX_SET_DEPTH = 50  # sets are expanded recursively, and their formulas grow with depth
_SIGNATURE_WORDS = {"vector": "a vector [...]", "scalar": "a number"}
_SET_OPERATORS = {"|": S.Union, "&": S.Intersection, "-": S.Difference}


class SetChecker:
    def __init__(self, context: CheckContext, declarations: dict[str, ast.SetDecl]):
        self.context = context
        self.declarations = declarations
        self.built: dict[str, S.SetExpr | None] = {}
        self.depths: dict[str, int] = {}  # 1 + the depth of the deepest set it uses
        self.building: list[str] = []
        self.deepest_reference: list[int] = []  # per set being built
        self.domain: S.SetExpr | None = None
        self.in_domain = False
        self.parameters = ExpressionChecker(context, {"constant"}, "parameter")
        self.constraints = ExpressionChecker(context, {"state", "constant"}, "set")

    def build_domain(self, node: ast.SetExpr) -> S.SetExpr | None:
        self.in_domain = True
        try:
            self.domain = self.convert(node)
        finally:
            self.in_domain = False
        return self.domain

    def named(self, name: str, span: Span) -> S.SetExpr | None:
        if name in self.building:
            self.context.error(f"set `{name}` is defined in terms of itself", span)
            return None
        if name not in self.built and len(self.building) >= MAX_SET_DEPTH:
            self.context.error(f"sets defined through more than {MAX_SET_DEPTH} levels of "
                               "other sets are not supported", span)
            return None
        if name not in self.built:
            self.building.append(name)
            self.deepest_reference.append(0)
            value = self.convert(self.declarations[name].value)
            self.building.pop()
            self.depths[name] = self.deepest_reference.pop() + 1
            if self.depths[name] > MAX_SET_DEPTH and value is not None:
                self.context.error(f"set `{name}` is defined through more than "
                                   f"{MAX_SET_DEPTH} levels of other sets; write it more "
                                   "directly", self.declarations[name].name.span)
                value = None
            self.built[name] = S.Named(name, value) if value is not None else None
        if self.deepest_reference:
            self.deepest_reference[-1] = max(self.deepest_reference[-1],
                                             self.depths.get(name, 0))
        return self.built[name]

    def convert(self, node: ast.SetExpr) -> S.SetExpr | None:
        if isinstance(node, ast.Shape):
            return self.shape(node)
        if isinstance(node, ast.Semialgebraic):
            return self.semialgebraic(node)
        if isinstance(node, ast.SetRef):
            return self.reference(node)
        if isinstance(node, ast.SetBinary):
            left, right = self.convert(node.left), self.convert(node.right)
            if left is None or right is None:
                return None
            return _SET_OPERATORS[node.op](left, right)
        if isinstance(node, ast.SetComplement):
            return self.complement(node)
        raise TypeError(f"not a set node: {node!r}")

    def complement(self, node: ast.SetComplement) -> S.SetExpr | None:
        if self.in_domain:
            self.context.error("`~` (complement relative to the domain) cannot be used "
                               "in the domain itself", node.span)
            return None
        operand = self.convert(node.operand)
        if operand is None or self.domain is None:
            return None
        return S.Complement(operand, self.domain)

    def reference(self, node: ast.SetRef) -> S.SetExpr | None:
        self.context.used.add(node.name)
        if node.name in self.declarations:
            return self.named(node.name, node.span)
        kind = self.context.kind_of(node.name)
        if kind:
            self.context.error(f"`{node.name}` is {article(kind)}, not a set", node.span)
        else:
            hint = did_you_mean(node.name, self.declarations)
            self.context.error(f"undeclared set `{node.name}`{hint}", node.span)
        return None

    def semialgebraic(self, node: ast.Semialgebraic) -> S.SetExpr | None:
        constraints = tuple(
            L.Compare(c.relation, self.constraints.convert(c.left),
                      self.constraints.convert(c.right))
            for c in node.constraints)
        return S.Semialgebraic(constraints, tuple(self.context.states))

    def shape(self, node: ast.Shape) -> S.SetExpr | None:
        cls = S.SHAPES.get(node.kind)
        if cls is None:
            hint = did_you_mean(node.kind, list(S.SHAPES))
            self.context.error(f"unknown set shape `{node.kind}`{hint}; the shapes are "
                               + ", ".join(S.SHAPES), node.span)
            return None
        if len(node.args) != len(cls.SIGNATURE):
            expected = ", ".join(_SIGNATURE_WORDS[k] for k in cls.SIGNATURE)
            self.context.error(f"`{node.kind}` takes {len(cls.SIGNATURE)} arguments "
                               f"({expected}), not {len(node.args)}", node.span)
            return None
        values = [self.argument(node, arg, kind) for arg, kind in zip(node.args, cls.SIGNATURE)]
        if any(value is None for value in values):
            return None
        shape = cls(*values, is_open=node.is_open)
        try:
            problems = shape.problems()
            for arg_index, component, message in problems:
                self.context.error(message, _argument_span(node.args[arg_index], component))
            if not problems:
                shape.membership([E.Var(s) for s in self.context.states])
        except E.ExprError as exc:
            self.context.error(f"`{node.kind}` parameters out of range: {exc}", node.span)
            return None
        return shape if not problems else None

    def argument(self, shape: ast.Shape, arg, kind: str):
        if kind == "vector":
            if not isinstance(arg, ast.Vector):
                self.context.error(f"`{shape.kind}` needs a vector [...] here", arg.span)
                return None
            return self.vector(arg)
        if isinstance(arg, ast.Vector):
            self.context.error(f"`{shape.kind}` needs a single number here, not a vector",
                               arg.span)
            return None
        return self.parameters.convert(arg)

    def vector(self, node: ast.Vector):
        n = len(self.context.states)
        if n and len(node.items) != n:
            self.context.error(f"this vector has {len(node.items)} entries but there "
                               f"{'is 1 state' if n == 1 else f'are {n} states'}", node.span)
            return None
        return tuple(self.parameters.convert(item) for item in node.items)


def set_reference_names(node: ast.SetExpr | None) -> set[str]:
    names, stack = set(), [node] if node is not None else []
    while stack:
        item = stack.pop()
        if isinstance(item, ast.SetRef):
            names.add(item.name)
        elif isinstance(item, ast.SetBinary):
            stack.extend((item.left, item.right))
        elif isinstance(item, ast.SetComplement):
            stack.append(item.operand)
    return names


def _argument_span(arg, component: int | None) -> Span:
    if component is not None and isinstance(arg, ast.Vector):
        return arg.items[component].span
    return arg.span
