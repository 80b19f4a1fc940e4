"""Facts about sets and dynamics, proved exactly before anything runs.

Set relations are decided by an SMT solver over the exact set descriptions (never by
sampling); a failed relation reports a witness point. f(0) = 0 is decided by exact
arithmetic, or by an outward-rounded enclosure that excludes 0.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable, Sequence

from fossil_dsl.check.context import CheckContext
from fossil_dsl.diagnostics import Span
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.enclosure import sign
from fossil_dsl.ir.printing import number_text, to_text
from fossil_dsl.smt.api import Backend, Status

RELATION_TIMEOUT = 10.0  # seconds per query


def point_text(values: Sequence[Fraction]) -> str:
    return "(" + ", ".join(_coordinate(v) for v in values) + ")"


def _coordinate(value: Fraction) -> str:
    text = number_text(value)
    return text if len(text) <= 12 and "/" not in text else format(float(value), ".6g")


@dataclass
class SetLabel:
    """How a set is named in messages, and where it is reported."""

    text: str
    span: Span | None


class RelationProver:
    def __init__(self, context: CheckContext, states: Sequence[str], backend: Backend,
                 label: Callable[[S.SetExpr], SetLabel], timeout: float = RELATION_TIMEOUT):
        self.context = context
        self.states = tuple(states)
        self.backend = backend
        self.label = label
        self.timeout = timeout

    def _query(self, formula: L.Formula, claim: str, span: Span | None):
        """A witness if `formula` is satisfiable; None if UNSAT or undecided (warned)."""
        answer = self.backend.check(formula, self.states, self.timeout)
        if answer.status is Status.UNSAT:
            return None
        if answer.status is Status.SAT and not answer.approximate:
            return [answer.model[name] for name in self.states]
        why = answer.reason or ("constants such as pi were only bounded, and the bounded "
                                "query has a solution")
        self.context.warning(f"could not prove that {claim} ({self.backend.name}: {why})", span)
        return None

    def inside(self, inner: S.SetExpr, outer: S.SetExpr) -> None:
        a, b = self.label(inner), self.label(outer)
        query = L.conjunction(inner.contains_formula(self.states),
                              L.negation(outer.contains_formula(self.states)))
        witness = self._query(query, f"{a.text} is inside {b.text}", a.span)
        if witness is not None:
            self.context.error(f"{a.text} is not inside {b.text}: {point_text(witness)} is "
                               f"in {a.text} but not in {b.text}", a.span)

    def inside_interior(self, inner: S.SetExpr, outer: S.SetExpr) -> None:
        a, b = self.label(inner), self.label(outer)
        interior = L.open_inner(outer.contains_formula(self.states))
        query = L.conjunction(inner.contains_formula(self.states), L.negation(interior))
        claim = f"{a.text} is inside the interior of {b.text}"
        witness = self._query(query, claim, a.span)
        if witness is not None:
            self.context.error(f"{a.text} is not inside the interior of {b.text}: "
                               f"{point_text(witness)} is in {a.text} but on the boundary "
                               "or outside", a.span)

    def disjoint(self, first: S.SetExpr, second: S.SetExpr) -> None:
        a, b = self.label(first), self.label(second)
        query = L.conjunction(first.contains_formula(self.states),
                              second.contains_formula(self.states))
        witness = self._query(query, f"{a.text} and {b.text} are disjoint", a.span)
        if witness is not None:
            self.context.error(f"{a.text} and {b.text} overlap: {point_text(witness)} is "
                               "in both", a.span)

    def contains_origin(self, region: S.SetExpr) -> None:
        a = self.label(region)
        origin = [E.ZERO] * len(self.states)
        query = L.negation(region.membership(origin))
        if self._query(query, f"{a.text} contains the origin", a.span) is not None:
            self.context.error(f"{a.text} does not contain the origin, the equilibrium that "
                               "the controller (with k(0) = 0) keeps", a.span)

    def nonempty(self, region: S.SetExpr) -> None:
        a = self.label(region)
        answer = self.backend.check(region.contains_formula(self.states), self.states,
                                    self.timeout)
        if answer.status is Status.UNSAT:
            self.context.error(f"{a.text} is empty: no point satisfies its description",
                               a.span)

    def prove(self, kind: str, first: S.SetExpr, second: S.SetExpr | None) -> None:
        if kind == "inside":
            self.inside(first, second)
        elif kind == "inside_interior":
            self.inside_interior(first, second)
        elif kind == "disjoint":
            self.disjoint(first, second)
        else:
            raise ValueError(f"unknown relation {kind}")


def check_equilibrium(context: CheckContext, states: Sequence[str], inputs: Sequence[str],
                      dynamics: Sequence[E.Expr], spans: Sequence[Span],
                      discrete: bool) -> None:
    """f(0) = 0 (an error if it fails for an autonomous system, a warning with inputs)."""
    zeros = {name: E.ZERO for name in (*states, *inputs)}
    where = "f(0, 0)" if inputs else "f(0)"
    for state, value, span in zip(states, dynamics, spans):
        lhs = f"next({state})" if discrete else f"{state}'"
        try:
            at_origin = E.substitute(value, zeros)
        except E.ExprError as exc:
            context.error(f"{lhs} = {to_text(value)} is undefined at the origin ({exc})", span)
            continue
        verdict = sign(at_origin) if not E.free_vars(at_origin) else None
        if verdict == 0:
            continue
        if verdict is None:
            context.warning(f"could not prove {where} = 0 for {lhs} (= {to_text(at_origin)} "
                            "at the origin)", span)
        elif inputs:
            context.warning(f"the origin is not an equilibrium of the open loop: {lhs} = "
                            f"{to_text(at_origin)} at x = 0, u = 0", span)
        else:
            context.error(f"the origin is not an equilibrium: {lhs} = {to_text(at_origin)} "
                          "at x = 0, but stability is about the equilibrium at the origin",
                          span)
