"""Sets over the state space: shapes, semialgebraic sets and their combinations.

Every set gives its membership as a solver-neutral formula over given coordinates.
A new shape is one class with SIGNATURE, `problems` and `membership`, registered
in SHAPES; the checker and the solvers need no other change.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, ClassVar, Sequence

from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import enclose, sign
from fossil_dsl.ir.expr import Expr, Var, add, mul, power, div, Num, free_vars
from fossil_dsl.ir.expr import to_text
from fossil_dsl.ir.set_bounds import constraint_box

Point = Sequence[Expr]


Bounds = tuple[tuple[float, ...], tuple[float, ...]]


def _low(value: Expr) -> float:
    return enclose(value)[0]


def _high(value: Expr) -> float:
    return enclose(value)[1]


def _hull(a: Bounds | None, b: Bounds | None) -> Bounds | None:
    if a is None or b is None:
        return None
    return (tuple(map(min, a[0], b[0])), tuple(map(max, a[1], b[1])))


def _meet(a: Bounds | None, b: Bounds | None) -> Bounds | None:
    if a is None or b is None:
        return a or b
    return (tuple(map(max, a[0], b[0])), tuple(map(min, a[1], b[1])))


class SetExpr:
    def membership(self, point: Point) -> L.Formula:
        raise NotImplementedError

    def bounding_box(self) -> Bounds | None:
        """A box containing the set (for sampling), or None if the set does not say."""
        return None

    def contains_formula(self, states: Sequence[str]) -> L.Formula:
        return self.membership([Var(name) for name in states])

    def __str__(self) -> str:
        return self.text()

    def text(self) -> str:
        raise NotImplementedError

    def own_samples(self, count: int, generator):
        """Points of the set from a sampler of its own, or None to sample its box."""
        return None


# ---- shapes ---------------------------------------------------------------------
@dataclass(frozen=True)
class Shape(SetExpr):
    """A parametrised shape; arguments are vectors (tuples) or scalars (Expr)."""

    SIGNATURE: ClassVar[tuple[str, ...]] = ()
    NAME: ClassVar[str] = ""

    def problems(self) -> list[tuple[int, int | None, str]]:
        """(argument index, component index or None, message) for each invalid value."""
        return []

    def args_text(self) -> str:
        raise NotImplementedError

    def text(self) -> str:
        prefix = "open " if getattr(self, "is_open", False) else ""
        return f"{prefix}{self.NAME}({self.args_text()})"


def _vector_text(values: Sequence[Expr]) -> str:
    return "[" + ", ".join(to_text(v) for v in values) + "]"


def _le(is_open: bool) -> str:
    return "<" if is_open else "<="


@dataclass(frozen=True)
class Box(Shape):
    lower: tuple[Expr, ...]
    upper: tuple[Expr, ...]
    is_open: bool = False
    SIGNATURE: ClassVar = ("vector", "vector")
    NAME: ClassVar = "box"

    def problems(self):
        found = []
        for i, (lo, hi) in enumerate(zip(self.lower, self.upper)):
            gap = sign(add(hi, mul(Num(-1), lo)))
            if gap == -1 or (gap == 0 and self.is_open):
                relation = ">" if gap == -1 else "="
                found.append((0, i, f"empty box: lower bound {to_text(lo)} {relation} "
                                    f"upper bound {to_text(hi)} in coordinate {i + 1}"))
        return found

    def bounding_box(self):
        return tuple(map(_low, self.lower)), tuple(map(_high, self.upper))

    def membership(self, point):
        rel = _le(self.is_open)
        return L.conjunction(*(
            L.conjunction(L.Compare(rel, lo, x), L.Compare(rel, x, hi))
            for x, lo, hi in zip(point, self.lower, self.upper)))

    def args_text(self):
        return f"{_vector_text(self.lower)}, {_vector_text(self.upper)}"


def _positive_problems(values: Sequence[Expr], arg: int, what: str, vector: bool):
    found = []
    for i, value in enumerate(values):
        if sign(value) in (-1, 0):
            found.append((arg, i if vector else None,
                          f"{what} must be positive, not {to_text(value)}"))
    return found


def _squared_distance(point: Point, centre: Sequence[Expr], scales=None) -> Expr:
    terms = []
    for i, (x, c) in enumerate(zip(point, centre)):
        offset = add(x, mul(Num(-1), c))
        if scales is not None:
            offset = div(offset, scales[i])
        terms.append(power(offset, Num(2)))
    return add(*terms)


@dataclass(frozen=True)
class Ball(Shape):
    centre: tuple[Expr, ...]
    radius: Expr
    is_open: bool = False
    SIGNATURE: ClassVar = ("vector", "scalar")
    NAME: ClassVar = "ball"

    def problems(self):
        return _positive_problems([self.radius], 1, "the radius", vector=False)

    def bounding_box(self):
        r = _high(self.radius)
        return (tuple(_low(c) - r for c in self.centre), tuple(_high(c) + r for c in self.centre))

    def membership(self, point):
        return L.Compare(_le(self.is_open), _squared_distance(point, self.centre),
                         power(self.radius, Num(2)))

    def args_text(self):
        return f"{_vector_text(self.centre)}, {to_text(self.radius)}"


@dataclass(frozen=True)
class Ellipsoid(Shape):
    centre: tuple[Expr, ...]
    semi_axes: tuple[Expr, ...]
    is_open: bool = False
    SIGNATURE: ClassVar = ("vector", "vector")
    NAME: ClassVar = "ellipsoid"

    def problems(self):
        return _positive_problems(self.semi_axes, 1, "a semi-axis", vector=True)

    def bounding_box(self):
        return (tuple(_low(c) - _high(a) for c, a in zip(self.centre, self.semi_axes)),
                tuple(_high(c) + _high(a) for c, a in zip(self.centre, self.semi_axes)))

    def membership(self, point):
        return L.Compare(_le(self.is_open),
                         _squared_distance(point, self.centre, self.semi_axes), Num(1))

    def args_text(self):
        return f"{_vector_text(self.centre)}, {_vector_text(self.semi_axes)}"


SHAPES: dict[str, type[Shape]] = {cls.NAME: cls for cls in (Box, Ball, Ellipsoid)}


# ---- other sets -------------------------------------------------------------------
@dataclass(frozen=True)
class Semialgebraic(SetExpr):
    """{ C1, C2, ... }: the points satisfying every comparison, written over the states."""

    constraints: tuple[L.Compare, ...]
    states: tuple[str, ...]

    def bounding_box(self):
        """The box the constraints bound every state in (set_bounds.py), if they do."""
        return constraint_box(self.constraints, self.states)

    def membership(self, point):
        mapping = dict(zip(self.states, point))
        return L.conjunction(*(L.substitute(c, mapping) for c in self.constraints))

    def text(self):
        return "{ " + ", ".join(str(c) for c in self.constraints) + " }"


@dataclass(frozen=True, eq=False)
class Bespoke(Semialgebraic):
    """A set given in Python (the reference's "bespoke domains"): its constraints for
    the solvers and the checker, and a sampler of its own for the learner.
    `sampler(count, generator)` returns a (count, states) tensor of points in the set."""

    name: str = ""
    sampler: Callable | None = None
    box: Bounds | None = None

    def bounding_box(self):
        return self.box

    def own_samples(self, count: int, generator):
        if type(generator).__module__.startswith("numpy"):
            # a verifier-only run draws with numpy; the sampler was written for torch
            import torch
            seed = int(generator.integers(2 ** 31))
            return self.sampler(count, torch.Generator().manual_seed(seed)).numpy()
        return self.sampler(count, generator)


@dataclass(frozen=True)
class Union(SetExpr):
    left: SetExpr
    right: SetExpr

    def bounding_box(self):
        return _hull(self.left.bounding_box(), self.right.bounding_box())

    def membership(self, point):
        return L.disjunction(self.left.membership(point), self.right.membership(point))

    def text(self):
        return f"({self.left.text()} | {self.right.text()})"


@dataclass(frozen=True)
class Intersection(SetExpr):
    left: SetExpr
    right: SetExpr

    def bounding_box(self):
        return _meet(self.left.bounding_box(), self.right.bounding_box())

    def membership(self, point):
        return L.conjunction(self.left.membership(point), self.right.membership(point))

    def text(self):
        return f"({self.left.text()} & {self.right.text()})"


@dataclass(frozen=True)
class Difference(SetExpr):
    left: SetExpr
    right: SetExpr

    def bounding_box(self):
        return self.left.bounding_box()

    def membership(self, point):
        return L.conjunction(self.left.membership(point),
                             L.negation(self.right.membership(point)))

    def text(self):
        return f"({self.left.text()} - {self.right.text()})"


@dataclass(frozen=True)
class Complement(SetExpr):
    """~A: the points of the domain that are not in A."""

    operand: SetExpr
    domain: SetExpr

    def bounding_box(self):
        return self.domain.bounding_box()

    def membership(self, point):
        return L.conjunction(self.domain.membership(point),
                             L.negation(self.operand.membership(point)))

    def text(self):
        return f"~{self.operand.text()}"


@dataclass(frozen=True)
class Named(SetExpr):
    """A declared set; keeps its name for messages and reports."""

    name: str
    value: SetExpr

    def bounding_box(self):
        return self.value.bounding_box()

    def membership(self, point):
        return self.value.membership(point)

    def own_samples(self, count: int, generator):
        return self.value.own_samples(count, generator)

    def text(self):
        return self.name



@dataclass(frozen=True)
class Boundary(SetExpr):
    """∂A, or rather a closed set containing it (see logic.boundary_outer): proving a
    condition there proves it on the boundary."""

    inner: SetExpr

    def bounding_box(self):
        return self.inner.bounding_box()

    def membership(self, point):
        return L.boundary_outer(self.inner.membership(point))

    def text(self):
        inner = self.inner.text()
        return f"∂{inner}" if isinstance(self.inner, Named) else f"∂({inner})"
