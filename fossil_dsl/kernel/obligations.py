"""Every fact a guarantee rests on, derived from the checked spec and the exact functions
alone (never from a list the engine hands over).

An obligation is a query that is satisfiable exactly when the fact fails; it is proved
when the query is shown unsatisfiable. The rules follow docs/certificates.md: the
certificate's conditions, and the side facts the argument uses (set relations, bounded
regions, a neighbourhood of the origin in D, the equilibrium, definedness of every
partial operation where it is evaluated, and the excluded ball of a delta-decision
verifier).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Mapping

from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.spec import CheckedSpec, TimeDomain
from fossil_dsl.kernel.definedness import undefined_where

GAMMA = Fraction(1, 100)  # the decrease rate that forces a goal to be reached
NEIGHBOURHOOD_RADII = tuple(Fraction(1, 10 ** k) for k in range(1, 7))
BALL_ROOM = 10  # the excluded ball's radius times this must still fit in D


@dataclass(frozen=True)
class Claim:
    """What the engine proposes: exact functions ("V", "B"), the controller (input ->
    formula), the levels ("beta") and the radius of the ball a delta-decision verifier
    left out round the origin (0: only the origin itself). `procedures` names, per
    condition, the procedure that proved it during the run: the kernel tries it first,
    which changes only how soon it answers, never what it accepts. `refutations` are
    evidence for obligations, which the kernel checks exactly before any solver."""

    spec: CheckedSpec
    functions: Mapping[str, E.Expr]
    controller: Mapping[str, E.Expr] = field(default_factory=dict)
    levels: Mapping[str, Fraction] = field(default_factory=dict)
    ball_radius: Fraction = Fraction(0)
    procedures: Mapping[str, str] = field(default_factory=dict)
    # obligation name -> a sum-of-squares refutation of its query (positivstellensatz.py),
    # checked exactly; one that does not check is ignored and the solvers are asked
    refutations: Mapping[str, object] = field(default_factory=dict)


@dataclass(frozen=True)
class Obligation:
    name: str
    text: str
    query: L.Formula  # satisfiable exactly when the fact fails
    first: str = ""  # the procedure to try first (only the order changes, never a verdict)
    # the query's closure holds at the origin (x != 0 near it): a procedure that reads
    # strict comparisons as non-strict, as the interval procedure does, cannot prove it
    closure_holds: bool = False

    @property
    def file_stem(self) -> str:
        """The name as a file stem: `relation:initial in domain` ->
        `relation-initial_in_domain`."""
        return file_stem(self.name)


def file_stem(name: str) -> str:
    return name.replace(":", "-").replace(" ", "_").replace("/", "_")


class NoRule(Exception):
    """The kernel has no sound rule for this property in this time domain."""


class Facts:
    """The spec's sets and the claim's functions as formulas over the states."""

    def __init__(self, claim: Claim):
        spec = self.spec = claim.spec
        self.claim = claim
        self.states = spec.states
        self.x = [E.Var(s) for s in self.states]
        self.field = tuple(traversal.substitute(f, dict(claim.controller)) for f in spec.dynamics)
        self.discrete = spec.time is TimeDomain.DISCRETE
        self.r = claim.ball_radius
        self.obligations: list[Obligation] = []
        self.ball_left_out = False  # some obligation excludes the ball |x| <= r
        self.ball_covered = False  # ... and the Taylor lemma's obligations cover it

    # ---- sets and functions ----
    def role(self, name: str) -> S.SetExpr:
        found = self.spec.property.role(name)
        if found is None:
            raise NoRule(f"the property has no {name} set")
        return found

    def member(self, region: S.SetExpr) -> L.Formula:
        return region.contains_formula(self.states)

    def closure(self, region: S.SetExpr) -> L.Formula:
        return L.closed_outer(self.member(region))

    def boundary(self, region: S.SetExpr) -> L.Formula:
        return L.boundary_outer(self.member(region))

    def interior(self, region: S.SetExpr) -> L.Formula:
        return L.open_inner(self.member(region))

    def value(self, name: str) -> E.Expr:
        if name not in self.claim.functions:
            raise NoRule(f"the claim has no function {name}")
        return self.claim.functions[name]

    def change(self, name: str) -> E.Expr:
        """dC/dt along the closed loop, or C(f(x)) - C(x) in discrete time."""
        return calculus.change(self.value(name), self.states, self.field, self.discrete)

    def level(self, name: str) -> E.Num:
        if name not in self.claim.levels:
            raise NoRule(f"the claim has no level {name}")
        return E.Num(self.claim.levels[name])

    def squared_norm(self) -> E.Expr:
        return E.squared_norm(self.states)

    def away_from_origin(self) -> L.Formula:
        """x outside the excluded ball (or x != 0)."""
        self.ball_left_out = self.ball_left_out or self.r > 0
        return L.Compare(">", self.squared_norm(), E.Num(self.r ** 2))

    def ball(self, radius: Fraction) -> L.Formula:
        return L.Compare("<=", self.squared_norm(), E.Num(radius ** 2))

    # ---- obligations ----
    def never(self, name: str, text: str, region: L.Formula, failure: L.Formula,
              first: str = "", closure_holds: bool = False) -> None:
        """`failure` never happens in `region`; the expressions of `failure` are also
        obligated to be defined throughout `region`."""
        self.defined(name, region, _expressions(failure))
        self.obligations.append(Obligation(name, text, L.conjunction(region, failure), first,
                                           closure_holds))

    def lands_in(self, name: str, text: str, region: L.Formula, target: S.SetExpr) -> None:
        """Every x in `region` is mapped into `target` by one step of the closed loop."""
        image = L.substitute(self.member(target), dict(zip(self.states, self.field)))
        self.never(name, text, region, L.negation(image))

    def defined(self, name: str, region: L.Formula, expressions) -> None:
        undefined = undefined_where(expressions)
        if undefined is not None:
            self.obligations.append(Obligation(
                f"defined:{name}", f"every expression of {name} is defined where it is "
                "evaluated", L.conjunction(region, undefined)))

    def holds(self, name: str, text: str, region: L.Formula, claim: L.Formula) -> None:
        self.never(name, text, region, L.negation(claim))

    def inside(self, name: str, text: str, a: L.Formula, b: L.Formula) -> None:
        self.obligations.append(Obligation(name, text, L.conjunction(a, L.negation(b))))

    def disjoint(self, name: str, text: str, a: L.Formula, b: L.Formula) -> None:
        self.obligations.append(Obligation(name, text, L.conjunction(a, b)))

    def bounded(self, name: str, words: str, region: S.SetExpr) -> None:
        """The region lies in its bounding box (an unbounded set has none, or leaves it)."""
        box = region.bounding_box()
        if box is None or not all(map(_finite, (*box[0], *box[1]))):
            self.obligations.append(Obligation(
                f"bounded:{name}", f"{words} is bounded (it gives no bounding box)", L.TRUE))
            return
        # one unit of room: a set that touches its box is still proved inside it by a
        # procedure that reads strict comparisons as closed ones
        lower = tuple(E.Num(Fraction(v) - 1) for v in box[0])
        upper = tuple(E.Num(Fraction(v) + 1) for v in box[1])
        shown = " x ".join(f"[{low - 1:g}, {high + 1:g}]" for low, high in zip(*box))
        self.inside(f"bounded:{name}", f"{words} lies in the box {shown}",
                    self.member(region), S.Box(lower, upper).contains_formula(self.states))


def _finite(value: float) -> bool:
    return value == value and abs(value) != float("inf")


def _expressions(formula: L.Formula):
    for comparison in L.comparisons(formula):
        yield comparison.left
        yield comparison.right


def common(facts: Facts) -> None:
    """Every property: D bounded, the sets' descriptions and the closed loop defined."""
    domain = facts.spec.domain
    facts.bounded("domain", "the domain D", domain)
    hull = _hull(facts)
    for name, region in sorted(facts.spec.property.roles.items()):
        facts.defined(f"set {name}", hull, _expressions(facts.member(region)))
    facts.defined("the closed-loop dynamics", facts.closure(domain), facts.field)


def _hull(facts: Facts) -> L.Formula:
    """A box holding every set of the property (everything, if one has no box)."""
    boxes = [region.bounding_box() for region in facts.spec.property.roles.values()]
    if any(box is None for box in boxes):
        return L.TRUE
    lower = [min(b[0][i] for b in boxes) for i in range(len(facts.states))]
    upper = [max(b[1][i] for b in boxes) for i in range(len(facts.states))]
    if not all(map(_finite, lower + upper)):
        return L.TRUE
    box = S.Box(tuple(E.Num(Fraction(v)) for v in lower), tuple(E.Num(Fraction(v)) for v in upper))
    return box.contains_formula(facts.states)
