"""Neutral formulas as SMT-LIB 2 text: the verifier queries, and the proof obligations
written next to a result, which any SMT solver can re-check.

Learned functions appear as named functions: a placeholder `$V` becomes `(V x0 x1)`
and `$dV` becomes `(dV x0 x1)`, each with a `define-fun` (or `declare-fun` before
anything is learned).
"""
from __future__ import annotations

from fractions import Fraction
from typing import Mapping, Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import UnsupportedTheory

_FUNCTIONS = {"sin": "sin", "cos": "cos", "tan": "tan", "exp": "exp", "atan": "arctan",
              # not in SMT-LIB's theories: dReal's names, which Z3 and CVC5 do not read
              "log": "log", "sqrt": "sqrt"}
_MAX_EXPANDED_POWER = 16


def number(value: Fraction) -> str:
    magnitude = abs(value)
    text = f"{magnitude.numerator}.0" if magnitude.denominator == 1 else \
        f"(/ {magnitude.numerator}.0 {magnitude.denominator}.0)"
    return f"(- {text})" if value < 0 else text


class Printer:
    def __init__(self, states: Sequence[str], constants: Sequence[str] = ()):
        self.states = tuple(states)
        self.arguments = " ".join(self.states)
        self.constants = frozenset(constants)  # placeholders that are numbers, not functions

    def term(self, expr: E.Expr) -> str:
        if isinstance(expr, E.Num):
            return number(expr.value)
        if isinstance(expr, E.Var):
            if expr.name.startswith("$"):
                if expr.name[1:] in self.constants:
                    return expr.name[1:]
                return f"({expr.name[1:]} {self.arguments})"
            return expr.name
        if isinstance(expr, E.Pi):
            return "real.pi"
        if isinstance(expr, E.Add):
            return "(+ " + " ".join(self.term(t) for t in expr.terms) + ")"
        if isinstance(expr, E.Mul):
            return "(* " + " ".join(self.term(f) for f in expr.factors) + ")"
        if isinstance(expr, E.Neg):
            return f"(- {self.term(expr.operand)})"
        if isinstance(expr, E.Div):
            return f"(/ {self.term(expr.numerator)} {self.term(expr.denominator)})"
        if isinstance(expr, E.Pow):
            return self.power(expr)
        if isinstance(expr, E.Apply):
            return self.apply(expr)
        raise TypeError(f"not an expression: {expr!r}")

    def power(self, expr: E.Pow) -> str:
        exponent = expr.exponent
        if not (isinstance(exponent, E.Num) and exponent.value.denominator == 1
                and 0 < abs(exponent.value) <= _MAX_EXPANDED_POWER):
            raise UnsupportedTheory(f"SMT-LIB has no power `{expr}`")
        base = self.term(expr.base)
        product = f"(* {' '.join([base] * int(abs(exponent.value)))})" \
            if abs(exponent.value) > 1 else base
        return f"(/ 1.0 {product})" if exponent.value < 0 else product

    def apply(self, expr: E.Apply) -> str:
        arg = self.term(expr.arg)
        if expr.func == "abs":
            return f"(ite (>= {arg} 0.0) {arg} (- {arg}))"
        if expr.func == "tanh":  # (e^2z - 1) / (e^2z + 1)
            twice = f"(exp (* 2.0 {arg}))"
            return f"(/ (- {twice} 1.0) (+ {twice} 1.0))"
        if expr.func not in _FUNCTIONS:
            raise UnsupportedTheory(f"SMT-LIB 2 has no `{expr.func}`")
        return f"({_FUNCTIONS[expr.func]} {arg})"

    def formula(self, formula: L.Formula) -> str:
        if isinstance(formula, L.Compare):
            return f"({formula.relation} {self.term(formula.left)} {self.term(formula.right)})"
        if isinstance(formula, L.And):
            return "(and " + " ".join(self.formula(a) for a in formula.args) + ")"
        if isinstance(formula, L.Or):
            return "(or " + " ".join(self.formula(a) for a in formula.args) + ")"
        if isinstance(formula, L.Not):
            return f"(not {self.formula(formula.arg)})"
        if isinstance(formula, L.BoolConst):
            return "true" if formula.value else "false"
        raise TypeError(f"not a formula: {formula!r}")


def _logic(formula: L.Formula, definitions) -> str:
    """QF_NRA where it fits: CVC5 then uses its complete procedure for real arithmetic."""
    definitions = list(definitions)
    expressions = [side for c in L.comparisons(formula) for side in (c.left, c.right)]
    expressions += [d for d in definitions if d is not None]
    if not all(traversal.is_arithmetic(e) for e in expressions):
        return "ALL"
    return "QF_UFNRA" if None in definitions else "QF_NRA"


def query_text(formula: L.Formula, states: Sequence[str],
               functions: Mapping[str, E.Expr | None] = {}, comments: Sequence[str] = (),
               logic: str | None = None, levels: Mapping[str, Fraction | None] = {}) -> str:
    """A complete SMT-LIB 2 script: unsat means the condition holds.

    `functions` maps a placeholder name ("V", "dV") to its definition, or to None to
    declare it as an unknown function (a query before anything is learned); `levels`
    likewise maps a number placeholder ("beta") to its value or None."""
    printer = Printer(states, levels)
    logic = logic or _logic(formula, list(functions.values()) + [
        None if value is None else E.Num(value) for value in levels.values()])
    lines = [f"; {c}" for c in comments]
    lines.append(f"(set-logic {logic})")
    lines += [f"(declare-const {s} Real)" for s in states]
    for name, value in levels.items():
        lines.append(f"(declare-const {name} Real)" if value is None else
                     f"(define-fun {name} () Real {number(value)})")
    signature = " ".join(f"({s} Real)" for s in states)
    for name, definition in functions.items():
        if definition is None:
            lines.append(f"(declare-fun {name} ({' '.join(['Real'] * len(states))}) Real)")
        else:
            lines.append(f"(define-fun {name} ({signature}) Real {printer.term(definition)})")
    lines.append(f"(assert {printer.formula(formula)})")
    lines.append("(check-sat)")
    return "\n".join(lines) + "\n"
