"""Facts about sets and dynamics, proved exactly before anything runs.

Set relations are decided by an SMT solver over the exact set descriptions (never by
sampling); a failed relation reports a witness point. f(0) = 0 is decided by exact
arithmetic, or by an outward-rounded enclosure that excludes 0.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from decimal import Decimal, localcontext
from fractions import Fraction
from typing import Sequence

from fossil_dsl.check.context import CheckContext
from fossil_dsl.diagnostics import Span
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.enclosure import sign
from fossil_dsl.ir.expr import to_text
from fossil_dsl.ir.numbers import number_text
from fossil_dsl.solvers import registry
from fossil_dsl.solvers.api import Answer, Backend, Status
from fossil_dsl.solvers.positivstellensatz import BEFORE_Z3_FROM

RELATION_TIMEOUT = 2.5  # seconds per query
RELATION_BUDGET = 5.0  # seconds for all of a spec's queries: checking is never slow


def point_text(values: Sequence[Fraction]) -> str:
    return "(" + ", ".join(_coordinate(v) for v in values) + ")"


def _coordinate(value: Fraction) -> str:
    text = number_text(value)
    if len(text) <= 12 and "/" not in text:
        return text
    with localcontext() as context:
        context.prec = 6
        return format(Decimal(value.numerator) / Decimal(value.denominator), "g")


@dataclass(frozen=True)
class Subject:
    """A set with the words that name it in messages and the place it is reported at."""

    value: S.SetExpr
    text: str
    span: Span | None


def _linear(formula: L.Formula) -> bool:
    return all(traversal.is_affine(side)
               for c in L.comparisons(formula) for side in (c.left, c.right))


class RelationProver:
    def __init__(self, context: CheckContext, states: Sequence[str], backend: Backend,
                 timeout: float = RELATION_TIMEOUT, budget: float = RELATION_BUDGET):
        self.context = context
        self.states = tuple(states)
        self.backend = backend
        self.timeout = timeout
        self.deadline = time.monotonic() + budget

    def _decide(self, formula: L.Formula) -> Answer:
        """The backend's answer; where it has none, a sum-of-squares refutation's, then
        the interval procedure's (each loaded only then: most relations are decided at
        once); with many states the refutation goes first (BEFORE_Z3_FROM), unless the
        query is linear, which Z3 decides at once (a 7-state box's relations took the
        refutation 1-3 s each on a loaded machine, and spent the budget: probe48/c11)."""
        early = len(self.states) >= BEFORE_Z3_FROM and not _linear(formula)
        if early and self._refuted(formula):
            return Answer(Status.UNSAT, solver="a sum-of-squares refutation")
        answer = self._ask(self.backend, formula)
        if answer.status is Status.UNKNOWN and not early and self._refuted(formula):
            return Answer(Status.UNSAT, solver="a sum-of-squares refutation")
        if answer.status is Status.UNKNOWN and registry.is_installed("interval"):
            second = self._ask(registry.load("interval"), formula)
            if second.status is not Status.UNKNOWN:
                return replace(second, solver="the interval procedure")
            answer = Answer(Status.UNKNOWN, reason=f"{answer.reason}; interval: "
                            f"{second.reason}")
        return answer

    def _refuted(self, formula: L.Formula) -> bool:
        from fossil_dsl.solvers.sos_refutation import SosBackend
        return self._ask(SosBackend(), formula).status is Status.UNSAT

    def _ask(self, backend: Backend, formula: L.Formula) -> Answer:
        remaining = self.deadline - time.monotonic()
        if remaining <= 0.05:
            return Answer(Status.UNKNOWN, reason="the time for checking set relations "
                          f"({RELATION_BUDGET:g} s) is spent")
        return backend.check(formula, self.states, min(self.timeout, remaining))

    def _member(self, subject: Subject) -> L.Formula:
        return subject.value.contains_formula(self.states)

    def _query(self, formula: L.Formula, claim: str, span: Span | None):
        """A witness if `formula` is satisfiable; None if UNSAT. Undecided is an error:
        the guarantee would rest on a fact nobody proved."""
        answer = self._decide(formula)
        if answer.status is Status.UNSAT:
            return None
        if answer.status is Status.SAT and not answer.approximate:
            return [answer.model[name] for name in self.states]
        if answer.status is Status.SAT:
            near = point_text([answer.model.get(name, 0) for name in self.states])
            why = f"{answer.solver or 'a solver'} found a point near {near} where it may " \
                "fail, but could not decide it exactly" + (f" ({answer.reason})"
                                                           if answer.reason else "")
        else:
            why = answer.reason or "no answer"
        self.context.error(f"cannot prove that {claim}: {why}; every relation the "
                           "guarantee uses must be proved (rewrite the sets so that a "
                           "solver can decide it)", span)
        return None

    def inside(self, a: Subject, b: Subject) -> None:
        query = L.conjunction(self._member(a), L.negation(self._member(b)))
        witness = self._query(query, f"{a.text} is inside {b.text}", a.span)
        if witness is not None:
            self.context.error(f"{a.text} is not inside {b.text}: {point_text(witness)} is "
                               f"in {a.text} but not in {b.text}", a.span)

    def inside_interior(self, a: Subject, b: Subject) -> None:
        interior = L.open_inner(self._member(b))
        query = L.conjunction(self._member(a), L.negation(interior))
        witness = self._query(query, f"{a.text} is inside the interior of {b.text}", a.span)
        if witness is not None:
            self.context.error(f"{a.text} is not inside the interior of {b.text}: "
                               f"{point_text(witness)} is in {a.text} but on the boundary "
                               "or outside", a.span)

    def disjoint(self, a: Subject, b: Subject) -> None:
        query = L.conjunction(self._member(a), self._member(b))
        witness = self._query(query, f"{a.text} and {b.text} are disjoint", a.span)
        if witness is not None:
            self.context.error(f"{a.text} and {b.text} overlap: {point_text(witness)} is "
                               "in both", a.span)

    def contains_origin(self, a: Subject) -> None:
        origin = [E.ZERO] * len(self.states)
        try:
            query = L.negation(a.value.membership(origin))
        except E.ExprError as exc:
            self.context.error(f"{a.text} is undefined at the origin ({exc}), so it cannot "
                               "contain the equilibrium that the controller keeps", a.span)
            return
        if self._query(query, f"{a.text} contains the origin", a.span) is not None:
            self.context.error(f"{a.text} does not contain the origin, the equilibrium that "
                               "the controller (with k(0) = 0) keeps", a.span)

    def refute(self, query: L.Formula, claim: str, span: Span | None) -> None:
        """An error unless `query` is proved unsatisfiable."""
        witness = self._query(query, claim, span)
        if witness is not None:
            self.context.error(f"it is not true that {claim}: {point_text(witness)} is a "
                               "counterexample", span)

    def bounded(self, a: Subject) -> None:
        """The set lies in its bounding box (every proof and every sample needs one)."""
        box = a.value.bounding_box()
        if box is None or not all(math.isfinite(v) for v in (*box[0], *box[1])):
            self.context.error(f"{a.text} must be bounded, and no bound can be read from "
                               "it: intersect it with a box, e.g. `{ ... } & box([-1, -1], "
                               "[1, 1])`", a.span)
            return
        # one unit of room, as the kernel's obligation: a set touching its box (a ball in
        # 8 dimensions) stalled Z3 and cannot be refuted by the interval procedure
        lower = tuple(E.Num(Fraction(v) - 1) for v in box[0])
        upper = tuple(E.Num(Fraction(v) + 1) for v in box[1])
        query = L.conjunction(self._member(a), L.negation(S.Box(lower, upper).contains_formula(
            self.states)))
        witness = self._query(query, f"{a.text} is bounded", a.span)
        if witness is not None:
            self.context.error(f"{a.text} is not inside its bounding box widened by 1: "
                               f"{point_text(witness)} is in it", a.span)

    def origin_interior(self, a: Subject) -> None:
        """The origin is an interior point (stable-type properties need a neighbourhood
        of the equilibrium)."""
        try:
            inner = L.substitute(L.open_inner(self._member(a)), {s: E.ZERO for s in self.states})
        except E.ExprError as exc:
            self.context.error(f"{a.text} is undefined at the origin ({exc}), so it cannot "
                               "show that the origin is stable", a.span)
            return
        if self._query(L.negation(inner), f"the origin is an interior point of {a.text}",
                       a.span) is not None:
            self.context.error(f"{a.text} contains no neighbourhood of the origin, so it "
                               "cannot show that the origin is stable (a domain with a hole "
                               "round the origin, or without the origin)", a.span)

    def nonempty(self, a: Subject) -> None:
        answer = self._decide(self._member(a))
        if answer.status is Status.UNSAT:
            self.context.error(f"{a.text} is empty: no point satisfies its description",
                               a.span)

    def prove(self, kind: str, a: Subject, b: Subject) -> None:
        {"inside": self.inside, "inside_interior": self.inside_interior,
         "disjoint": self.disjoint}[kind](a, b)


def check_equilibrium(context: CheckContext, states: Sequence[str], inputs: Sequence[str],
                      dynamics: Sequence[E.Expr], spans: Sequence[Span],
                      discrete: bool) -> None:
    """f(0) = 0 (an error if it fails for an autonomous system, a warning with inputs)."""
    zeros = {name: E.ZERO for name in (*states, *inputs)}
    where = "f(0, 0)" if inputs else "f(0)"
    for state, value, span in zip(states, dynamics, spans):
        lhs = f"next({state})" if discrete else f"{state}'"
        try:
            at_origin = traversal.substitute(value, zeros)
        except E.ExprError as exc:
            context.error(f"{lhs} = {to_text(value)} is undefined at the origin ({exc})", span)
            continue
        verdict = sign(at_origin) if not E.free_vars(at_origin) else None
        if verdict == 0:
            continue
        if verdict is None and inputs:
            context.warning(f"could not prove {where} = 0 for {lhs} (= {to_text(at_origin)} "
                            "at the origin)", span)
        elif verdict is None:
            context.error(f"cannot prove that the origin is an equilibrium: {lhs} = "
                          f"{to_text(at_origin)} at x = 0 could not be decided exactly", span)
        elif inputs:
            context.warning(f"the origin is not an equilibrium of the open loop: {lhs} = "
                            f"{to_text(at_origin)} at x = 0, u = 0", span)
        else:
            context.error(f"the origin is not an equilibrium: {lhs} = {to_text(at_origin)} "
                          "at x = 0, but stability is about the equilibrium at the origin",
                          span)
