"""Reads back the SMT-LIB 2 scripts that `smtlib.query_text` writes (the proof
obligations), as a neutral formula that any backend can decide: so a solver without an
SMT-LIB front end (the interval verifier) can re-check an exported obligation too.

Only the subset the printer emits is accepted: `declare-const`, `define-fun` (numbers
and functions of the states), one `assert`, real arithmetic, exp/sin/cos/tan/arctan,
log/sqrt (dReal's names), real.pi, and `ite` in the printer's form of abs; the printer's
form of tanh is read back as tanh.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L

_TOKEN = re.compile(r"\s*(?:(;[^\n]*)|(\()|(\))|([^\s()]+))")
_UNARY = {"exp": "exp", "sin": "sin", "cos": "cos", "tan": "tan", "arctan": "atan",
          "log": "log", "sqrt": "sqrt"}
_RELATIONS = ("<", "<=", ">", ">=")


class SmtlibError(ValueError):
    pass


@dataclass(frozen=True)
class Script:
    variables: tuple[str, ...]  # the declared constants that stay free
    formula: L.Formula  # the conjunction of the assertions, definitions expanded


def read_script(text: str) -> Script:
    reader = _Reader()
    for command in _parse(text):
        reader.command(command)
    return Script(tuple(reader.variables), L.conjunction(*reader.assertions))


def _parse(text: str) -> list:
    stack: list[list] = [[]]
    for comment, opening, closing, atom in _TOKEN.findall(text):
        if comment:
            continue
        if opening:
            stack.append([])
        elif closing:
            if len(stack) == 1:
                raise SmtlibError("unbalanced `)`")
            finished = stack.pop()
            stack[-1].append(finished)
        elif atom:
            stack[-1].append(atom)
    if len(stack) != 1:
        raise SmtlibError("unbalanced `(`")
    return stack[0]


class _Reader:
    def __init__(self):
        self.variables: list[str] = []
        self.definitions: dict[str, tuple[tuple[str, ...], object]] = {}
        self.assertions: list[L.Formula] = []

    def command(self, command) -> None:
        head = command[0] if isinstance(command, list) and command else None
        if head in ("set-logic", "check-sat", "set-option", "set-info", "exit"):
            return
        if head == "declare-const":
            self.variables.append(command[1])
        elif head == "define-fun":
            _, name, parameters, _sort, body = command
            self.definitions[name] = (tuple(p[0] for p in parameters), body)
        elif head == "assert":
            self.assertions.append(self.formula(command[1], {}))
        else:
            raise SmtlibError(f"unsupported command {command!r}")

    def formula(self, node, scope) -> L.Formula:
        if node in ("true", "false"):
            return L.BoolConst(node == "true")
        head, *args = node
        if head in _RELATIONS:
            left, right = (self.term(a, scope) for a in args)
            return L.Compare(head, left, right)
        if head == "and":
            return L.conjunction(*(self.formula(a, scope) for a in args))
        if head == "or":
            return L.disjunction(*(self.formula(a, scope) for a in args))
        if head == "not":
            return L.negation(self.formula(args[0], scope))
        raise SmtlibError(f"unsupported formula {node!r}")

    def term(self, node, scope) -> E.Expr:
        if isinstance(node, str):
            return self.atom(node, scope)
        head, *args = node
        if head in self.definitions:
            parameters, body = self.definitions[head]
            values = [self.term(a, scope) for a in args]
            return self.term(body, dict(zip(parameters, values)))
        if head == "ite":
            return self.absolute(args, scope)
        argument = _tanh_argument(node)
        if argument is not None:
            return E.apply("tanh", self.term(argument, scope))
        terms = [self.term(a, scope) for a in args]
        if head == "+":
            return E.add(*terms)
        if head == "*":
            return E.mul(*terms)
        if head == "-":
            return E.neg(terms[0]) if len(terms) == 1 else \
                E.add(terms[0], *(E.neg(t) for t in terms[1:]))
        if head == "/":
            return E.div(terms[0], terms[1])
        if head in _UNARY:
            return E.apply(_UNARY[head], terms[0])
        raise SmtlibError(f"unsupported term {node!r}")

    def atom(self, token: str, scope) -> E.Expr:
        if token in scope:
            return scope[token]
        if token == "real.pi":
            return E.Pi()
        if token in self.definitions:
            parameters, body = self.definitions[token]
            if parameters:
                raise SmtlibError(f"`{token}` needs arguments")
            return self.term(body, {})
        if re.fullmatch(r"\d+(\.\d+)?", token):
            return E.Num(Fraction(token))
        if token in self.variables:
            return E.Var(token)
        raise SmtlibError(f"unknown symbol `{token}`")

    def absolute(self, args, scope) -> E.Expr:
        """(ite (>= a 0.0) a (- a)), the printer's abs(a)."""
        condition, then, otherwise = args
        if not (isinstance(condition, list) and condition[0] == ">=" and condition[2] == "0.0"
                and condition[1] == then and otherwise == ["-", then]):
            raise SmtlibError("only the printer's form of abs is supported for `ite`")
        return E.apply("abs", self.term(then, scope))


def _tanh_argument(node):
    """z where the node is the printer's tanh(z), (e^2z - 1) / (e^2z + 1), else None:
    read back as tanh, the re-checks get tanh's facts and enclosures rather than those
    of a quotient of exponentials (probe64/am04's decrease: no refutation, and Arb left
    12 boxes after 50 000 in 60 s)."""
    try:
        z = node[1][1][1][2]
    except (IndexError, TypeError):
        return None
    twice = ["exp", ["*", "2.0", z]]
    return z if node == ["/", ["-", twice, "1.0"], ["+", twice, "1.0"]] else None
