"""Syntax-tree expressions -> neutral expressions: names resolved, constants folded
exactly, functions checked. Problems become diagnostics; a bad part becomes 0 so that
checking goes on and every problem is reported."""
from __future__ import annotations

import re
from fractions import Fraction
from typing import Iterable

from fossil_dsl.check.context import CheckContext
from fossil_dsl.diagnostics import article, did_you_mean
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.syntax import ast

MAX_DECIMAL_EXPONENT = 1000
# The largest magnitude of a number in the model (docs/language.md): the learner computes
# in float64 next to values of order 1 (1e300 * x^2 overflows), and rounded weights
# cannot balance such a term; candidates are exempt (never learned, proved exactly).
LARGEST_NUMBER = Fraction(10) ** 12
_NUMBER = re.compile(r"(?P<mantissa>[0-9.]+)(?:[eE](?P<exponent>[+-]?\d+))?$")

_ALLOWED_WORDS = {
    "constant": "numbers and earlier constants",
    "dynamics": "states, inputs and constants",
    "set": "states and constants",
    "parameter": "numbers and constants",
    "candidate": "states and constants",
}


def _magnitude_text(value: Fraction) -> str:
    """A short text for a number of any size (float() overflows past 1e308)."""
    digits = len(str(abs(value.numerator))) - len(str(value.denominator))
    if abs(digits) < 300:
        return f"{float(value):.6g}"
    return f"{'-' if value < 0 else ''}about 1e{digits}"


class ExpressionChecker:
    """Converts expressions where the names of `allowed` kinds may appear."""

    def __init__(self, context: CheckContext, allowed: Iterable[str], where: str):
        self.context = context
        self.allowed = frozenset(allowed)
        self.where = where  # one of _ALLOWED_WORDS

    def convert(self, node: ast.Expr) -> E.Expr:
        try:
            value = self._convert(node)
        except E.ExprError as exc:
            self.context.error(str(exc), node.span)
            return E.ZERO
        if traversal.degree(value) > E.MAX_DEGREE:
            self.context.error(f"this expression has degree up to {traversal.degree(value)}; at most "
                               f"{E.MAX_DEGREE} is supported (solvers stall beyond)", node.span)
            return E.ZERO
        extreme = None if self.where == "candidate" else next(
            (n.value for n in E.walk(value)
             if isinstance(n, E.Num) and abs(n.value) > LARGEST_NUMBER), None)
        if extreme is not None:
            self.context.error(
                f"the number {_magnitude_text(extreme)} is larger than the learner and the "
                "solvers handle faithfully (magnitudes up to 1e12); rescale the units of "
                "the model", node.span)
            return E.ZERO
        return value

    def _convert(self, node: ast.Expr) -> E.Expr:
        if isinstance(node, ast.Number):
            return self.number(node)
        if isinstance(node, ast.Pi):
            return E.Pi()
        if isinstance(node, ast.Name):
            return self.name(node)
        if isinstance(node, ast.Unary):
            operand = self._convert(node.operand)
            return E.neg(operand) if node.op == "-" else operand
        if isinstance(node, ast.Binary):
            return self._located(node, self._binary, node)
        if isinstance(node, ast.Call):
            return self.call(node)
        raise TypeError(f"not an expression node: {node!r}")

    def _located(self, node, build, *args) -> E.Expr:
        """Run `build`, reporting an exact-arithmetic failure at this node."""
        try:
            return build(*args)
        except E.ExprError as exc:
            self.context.error(str(exc), node.span)
            return E.ZERO

    def _binary(self, node: ast.Binary) -> E.Expr:
        left, right = self._convert(node.left), self._convert(node.right)
        if node.op == "+":
            return E.add(left, right)
        if node.op == "-":
            return E.add(left, E.neg(right))
        if node.op == "*":
            return E.mul(left, right)
        if node.op == "/":
            return E.div(left, right)
        return E.power(left, right)

    def number(self, node: ast.Number) -> E.Expr:
        match = _NUMBER.match(node.text)
        exponent = int(match.group("exponent") or 0) if match else 0
        if abs(exponent) > MAX_DECIMAL_EXPONENT:
            self.context.error(f"number {node.text} is out of range (exponents are "
                               f"limited to ±{MAX_DECIMAL_EXPONENT})", node.span)
            return E.ZERO
        try:
            value = Fraction(node.text)
        except ValueError:
            value = None
        if value is None or E.too_large(value):
            self.context.error(f"number {node.text[:20]}... has too many digits", node.span)
            return E.ZERO
        return E.Num(value)

    def name(self, node: ast.Name) -> E.Expr:
        kind = self.context.kind_of(node.name)
        if kind is None:
            self._undeclared(node)
            return E.ZERO
        self.context.used.add(node.name)
        if kind not in self.allowed:
            self.context.error(
                f"`{node.name}` is {article(kind)}; here only {_ALLOWED_WORDS[self.where]} "
                "may be used", node.span)
            return E.ZERO
        if kind == "constant":
            return self.context.constants.get(node.name, E.ZERO)
        return E.Var(node.name)

    def _undeclared(self, node: ast.Name) -> None:
        if node.name in E.FUNCTIONS:
            self.context.error(f"`{node.name}` is a function: write `{node.name}(...)`",
                               node.span)
            return
        candidates = [n for n, d in self.context.names.items() if d.kind in self.allowed]
        hint = did_you_mean(node.name, candidates)
        extra = ""
        if not hint and self.where == "dynamics":
            extra = "; declare it with `state`, `input` or `const`"
        self.context.error(f"undeclared name `{node.name}`{hint}{extra}", node.span)

    def call(self, node: ast.Call) -> E.Expr:
        name = node.func.text
        if name not in E.FUNCTIONS:
            kind = self.context.kind_of(name)
            if kind:
                self.context.error(f"`{name}` is {article(kind)}, not a function",
                                   node.func.span)
            else:
                self.context.error(f"unknown function `{name}`"
                                   f"{did_you_mean(name, E.FUNCTIONS)}; the functions are: "
                                   + ", ".join(E.FUNCTIONS), node.func.span)
            return E.ZERO
        if len(node.args) != 1:
            self.context.error(f"`{name}` takes 1 argument, not {len(node.args)}", node.span)
            return E.ZERO
        arg = self._convert(node.args[0])
        return self._located(node, E.apply, name, arg)
