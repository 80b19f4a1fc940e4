"""A set shape is one class plus one registry line: nothing else in the pipeline changes.

The shape here (a diamond, the unit ball of the 1-norm) is defined only in this file and
registered for the duration of the test; the spec then checks, compiles, learns and is
proved by the kernel without any other code knowing about it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import pytest

from fossil_dsl import check_text, synthesise
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.enclosure import enclose


@dataclass(frozen=True)
class Diamond(S.Shape):
    centre: tuple[E.Expr, ...]
    radius: E.Expr
    is_open: bool = False
    SIGNATURE: ClassVar = ("vector", "scalar")
    NAME: ClassVar = "diamond"

    def problems(self):
        if enclose(self.radius)[1] <= 0:
            return [(1, None, "the radius must be positive")]
        return []

    def bounding_box(self):
        r = enclose(self.radius)[1]
        return (tuple(enclose(c)[0] - r for c in self.centre),
                tuple(enclose(c)[1] + r for c in self.centre))

    def membership(self, point):
        distance = E.add(*(E.apply("abs", E.add(x, E.mul(E.Num(-1), c)))
                           for x, c in zip(point, self.centre)))
        return L.Compare("<" if self.is_open else "<=", distance, self.radius)

    def args_text(self):
        return f"[{', '.join(map(E.to_text, self.centre))}], {E.to_text(self.radius)}"


SPEC = """\
state x, y
dynamics continuous {
  x' = -x + y
  y' = -x - y^3 - y
}
domain diamond([0, 0], 2)
prove stable
"""


@pytest.fixture
def diamond_registered(monkeypatch):
    monkeypatch.setitem(S.SHAPES, "diamond", Diamond)  # the one registry line


def test_an_unregistered_shape_is_refused_with_its_position():
    result = check_text(SPEC, "spec.fsl")
    assert not result.ok
    assert any("unknown set shape `diamond`" in d.message and d.span.line == 6
               for d in result.errors)


def test_a_registered_shape_checks_and_rejects_bad_parameters(diamond_registered):
    assert check_text(SPEC, "spec.fsl").ok
    bad = check_text(SPEC.replace("diamond([0, 0], 2)", "diamond([0, 0], -1)"), "spec.fsl")
    assert any("radius must be positive" in d.message for d in bad.errors)


def test_a_registered_shape_is_certified_end_to_end(diamond_registered):
    result = synthesise(check_text(SPEC, "spec.fsl").spec, seed=0, timeout=120)
    assert result.certified, result.summary()
