"""What a certificate rule provides: the functions to learn, the levels chosen from data,
and the conditions they must satisfy, as neutral formulas over placeholders.

A condition holds when `region ∧ guard ∧ ¬claim` is unsatisfiable; the placeholders
`$V` and `$dV` (per function) and `$beta` (per level) are replaced by exact formulas and
numbers only when verifying. The learner's loss is one hinge term per condition, so a
certificate rule gets its losses from its conditions.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import ClassVar

from fossil_dsl.diagnostics import FslError
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sets import SetExpr
from fossil_dsl.ir.spec import CheckedSpec, Layer, TimeDomain


def value_of(function: str) -> E.Var:
    """The placeholder for a learned function's value at x."""
    return E.Var(f"${function}")


def change_of(function: str) -> E.Var:
    """The placeholder for its derivative along the flow (continuous time) or its
    one-step difference C(f(x)) - C(x) (discrete time)."""
    return E.Var(f"$d{function}")


def next_value(state: str) -> E.Var:
    """The placeholder for the closed loop's next state, coordinate `state` (discrete
    time): f(x)_state."""
    return E.Var(f"$next_{state}")


def next_in(states, region: SetExpr) -> L.Formula:
    """f(x) ∈ region, over the next-state placeholders: a discrete step can jump over a
    set's boundary, so staying in a set is a claim about where each step lands."""
    formula = region.contains_formula(states)
    return L.substitute(formula, {s: next_value(s) for s in states})


def velocity_of(state: str) -> E.Var:
    """The placeholder for the closed loop's velocity, coordinate `state` (continuous
    time): f(x)_state, for claims such as "the field points into D on its face"."""
    return E.Var(f"$velocity_{state}")


def level_of(name: str) -> E.Var:
    """The placeholder for a level (a number chosen from data at each iteration)."""
    return E.Var(f"${name}")


@dataclass(frozen=True)
class Level:
    """A number in the conditions, such as the β of a sublevel set {V <= β}, chosen
    from data at each iteration: halfway between the largest value of `function` on the
    samples of condition `below` and the smallest on the samples of condition `above`,
    or, with only one of them, as close under that smallest value (over that largest
    value) as the learning margin allows. The verifier then decides the conditions with
    it."""

    name: str
    function: str
    above: str | None
    below: str | None = None
    text: str = ""


@dataclass(frozen=True)
class LearnedFunction:
    name: str  # "V", "B"
    layers: tuple[Layer, ...]
    zero_at_origin: bool  # C(0) = 0 by construction (no biases, C(x) - C(0))
    candidate: E.Expr | None = None  # given by the user: verify only


@dataclass(frozen=True)
class Condition:
    name: str
    text: str  # in plain mathematics
    region: SetExpr  # x ranges over this set
    claim: L.Formula  # must hold there; over states and placeholders
    guard: L.Formula = L.TRUE  # further hypotheses over placeholders (e.g. B(x) = 0)
    exclude_origin: bool = False
    scaled_margin: bool = False  # learn with a margin growing as |x|^2 (near 0)
    weight: float = 1.0  # of this condition's loss term
    # the learner may also meet it by making the guard false there,
    # e.g. by lowering V below a level where V cannot decrease
    escapable_guard: bool = False

    def query(self, states, origin_radius: Fraction = Fraction(0)) -> L.Formula:
        """Satisfiable exactly when the condition fails (before substitution); with
        `exclude_origin`, the points within `origin_radius` of the origin (or the origin
        alone) are left out."""
        parts = [self.region.contains_formula(states), self.guard, L.negation(self.claim)]
        if self.exclude_origin:
            norm = E.squared_norm(states)
            parts.insert(1, L.Compare(">", norm, E.Num(origin_radius ** 2)))
        return L.conjunction(*parts)


def level_set(function: str, level: E.Expr = E.ZERO) -> L.Formula:
    value = value_of(function)
    return L.conjunction(L.Compare("<=", value, level), L.Compare(">=", value, level))


def level_set_parts(guard: L.Formula) -> tuple[E.Expr, E.Expr] | None:
    """(f, c) where the guard is the level set f = c as `level_set` writes it, else None."""
    if isinstance(guard, L.And) and len(guard.args) == 2:
        below, above = guard.args
        if isinstance(below, L.Compare) and isinstance(above, L.Compare) \
                and (below.relation, above.relation) == ("<=", ">=") \
                and (below.left, below.right) == (above.left, above.right):
            return below.left, below.right
    return None


class Certificate:
    """A certificate rule for one property form.

    A subclass gives `functions` and `conditions`, and, where it needs them, `levels`.
    Registering it (`@register`) makes the compiler use it for `form`. What is proved,
    and the guarantee in words, are the kernel's rule's (kernel/rules.py), not this
    class's: the engine only searches.
    """

    form: ClassVar[str]  # the property form it proves (check.properties.FORMS)
    title: ClassVar[str]
    discrete_time: ClassVar[bool] = False  # its conditions are sound in discrete time
    keeps_equilibrium: ClassVar[bool] = True  # a controller must keep k(0) = 0

    def __init__(self, spec: CheckedSpec):
        self.spec = spec

    def functions(self) -> tuple[LearnedFunction, ...]:
        raise NotImplementedError

    def first_function(self, name: str, default: tuple[Layer, ...],
                       zero_at_origin: bool) -> LearnedFunction:
        """The function that `certificate:` (or `candidate:`) in the spec describes."""
        options = self.spec.synthesis
        return LearnedFunction(name, options.certificate or default, zero_at_origin,
                               options.candidate)

    def second_function(self, name: str, default: tuple[Layer, ...],
                        zero_at_origin: bool) -> LearnedFunction:
        """The function that `certificate2:` (or `candidate2:`) describes; without
        `certificate2`, it has the layers of `certificate`."""
        options = self.spec.synthesis
        layers = options.certificate2 or options.certificate or default
        return LearnedFunction(name, layers, zero_at_origin, options.candidate2)

    def conditions(self) -> tuple[Condition, ...]:
        raise NotImplementedError

    def levels(self) -> tuple[Level, ...]:
        return ()

    def variant_conditions(self) -> tuple[Condition, ...] | None:
        """The conditions of a variant of the kernel's rule (kernel/registry.py), to
        try where the main ones cannot be met; None where there is none."""
        return None

    def chosen_conditions(self) -> tuple[tuple[Condition, ...], tuple[Level, ...]]:
        """The conditions and levels to learn: the main rule's, or the variant's where
        the main ones evidently cannot be met (roa.py: I touches ∂D)."""
        return self.conditions(), self.levels()

    def variant_levels(self) -> tuple[Level, ...]:
        """The levels that go with the variant's conditions."""
        return self.levels()

    @property
    def discrete(self) -> bool:
        return self.spec.time is TimeDomain.DISCRETE

    def role(self, name: str) -> SetExpr:
        return self.spec.property.role(name)

    def control_target(self) -> SetExpr | None:
        """Where a learned controller should steer the state: the property's goal if it
        has one (None: the origin)."""
        return self.spec.property.role("goal")

    def change_word(self, function: str) -> str:
        return f"{function}(f(x)) - {function}(x)" if self.discrete else f"d{function}/dt"

    def lands_in(self, name: str, text: str, region: SetExpr, target: SetExpr,
                 guard: L.Formula) -> Condition:
        """Discrete time: every step from `region` where `guard` holds lands in `target`;
        the learner may also meet it at a point by making the guard false there (by
        keeping the point out of the sublevel set the guard names)."""
        return Condition(name, text, region, next_in(self.spec.states, target), guard=guard,
                         escapable_guard=True)


class UnsupportedProperty(FslError):
    pass


CERTIFICATES: dict[str, type[Certificate]] = {}


def register(cls: type[Certificate]) -> type[Certificate]:
    """Class decorator: this certificate proves properties of form `cls.form` (it
    replaces any certificate registered for that form before)."""
    CERTIFICATES[cls.form] = cls
    return cls


def certificate_for(spec: CheckedSpec) -> Certificate:
    form = spec.property.form
    if form not in CERTIFICATES:
        raise UnsupportedProperty(
            f"no certificate is implemented yet for {form}; available: "
            + ", ".join(sorted(CERTIFICATES)))
    return CERTIFICATES[form](spec)
