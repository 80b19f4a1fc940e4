"""The checked spec: what every stage after the checker consumes.

Plain, typed and immutable. Positions survive only in `spans` (for messages that later
stages attach to a spec element); no syntax-tree node is reachable from here.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from fractions import Fraction
from types import MappingProxyType
from typing import Callable, Mapping

from fossil_dsl.diagnostics import Span
from fossil_dsl.ir.expr import Expr
from fossil_dsl.ir.sets import SetExpr


class TimeDomain(Enum):
    CONTINUOUS = "continuous"
    DISCRETE = "discrete"


@dataclass(frozen=True)
class Layer:
    activation: str
    width: int

    def __str__(self) -> str:
        return f"{self.activation}({self.width})"


@dataclass(frozen=True)
class SampleCounts:
    default: int | None = None  # `samples: N`
    per_set: Mapping[str, int] = field(default_factory=lambda: MappingProxyType({}))

    def count(self, set_name: str, fallback: int) -> int:
        return self.per_set.get(set_name, self.default if self.default else fallback)


@dataclass(frozen=True)
class SynthesisOptions:
    """The synthesis block. None means: the compiler chooses for this property."""

    certificate: tuple[Layer, ...] | None = None
    certificate2: tuple[Layer, ...] | None = None
    candidate: Expr | None = None
    candidate2: Expr | None = None
    controller: tuple[Layer, ...] | None = None
    verifier: str | None = None
    samples: SampleCounts = SampleCounts()
    max_iters: int = 25
    seed: int = 0
    timeout: Fraction = Fraction(600)
    learning_rate: Fraction | None = None
    margin: Fraction | None = None
    delta: Fraction | None = None
    region: str | None = None  # "largest": the largest certified region of attraction


@dataclass(frozen=True)
class Property:
    """A normalised property: its form (from the reference's table) and its sets by role.

    Roles: domain, initial, unsafe, safe, goal, final (whichever the form uses). Where
    the form avoids something, `safe` is the domain minus `unsafe` (for `not U`) or the
    given safe set within the domain (for `S`, with `unsafe` the domain minus S).
    """

    form: str
    certificate: str
    roles: Mapping[str, SetExpr]
    text: str

    def role(self, name: str) -> SetExpr | None:
        return self.roles.get(name)


@dataclass(frozen=True)
class CheckedSpec:
    name: str
    path: str
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    constants: Mapping[str, Expr]
    time: TimeDomain
    dynamics: tuple[Expr, ...]  # in state order, constants substituted
    domain: SetExpr
    sets: Mapping[str, SetExpr]
    property: Property
    synthesis: SynthesisOptions
    spans: Mapping[str, Span]  # "state:x0", "set:init", "option:verifier", "prove", ...
    # for specs built in Python: the field as a torch function (points, inputs) -> values,
    # used for learning only; every proof uses `dynamics`
    torch_dynamics: Callable | None = None
    source: str = ""  # the spec's text (what `fossilc recheck` checks it again from)

    @property
    def has_controller(self) -> bool:
        return bool(self.inputs)

    def summary(self) -> str:
        plural = lambda n, word: f"{n} {word}{'' if n == 1 else 's'}"
        return (f"{self.property.form} ({self.property.certificate}), "
                f"{plural(len(self.states), 'state')}, {plural(len(self.inputs), 'input')}, "
                f"{self.time.value} time")
