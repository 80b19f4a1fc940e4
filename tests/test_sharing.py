"""Named repeated subexpressions (ir/sharing.py) in the interval procedure: which terms
are named, and that naming them changes no answer."""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from fossil_dsl.engine.evaluate import evaluate
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sharing import worth_naming
from fossil_dsl.ir.traversal import tree_size
from fossil_dsl.solvers import interval_backend
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.interval_backend import IntervalBackend

X, Y = E.Var("x0"), E.Var("x1")
NEURONS = 10


def num(value) -> E.Num:
    return E.Num(Fraction(value).limit_denominator(1000))


def next_state() -> tuple[E.Expr, E.Expr]:
    """A map with a three-neuron tanh controller in each component."""
    neurons = [E.apply("tanh", E.add(E.mul(num(k), X), E.mul(num(-0.5), Y), num(k / 4)))
               for k in (0.2, 0.5, 0.9)]

    def component(a, b, c):
        control = E.add(*(E.mul(num(c * (i + 1)), n) for i, n in enumerate(neurons)))
        return E.add(E.mul(num(a), X), E.mul(num(b), Y), E.mul(num(0.1), control))
    return component(0.7, 0.2, 0.1), component(0.3, 0.6, -0.1)


def barrier(at: tuple[E.Expr, E.Expr]) -> E.Expr:
    """A tanh network of NEURONS neurons, evaluated at `at`: each neuron holds `at`."""
    rng = np.random.default_rng(3)
    neurons = []
    for _ in range(NEURONS):
        a, b, bias, weight = rng.uniform(-1, 1, 4)
        inner = E.add(E.mul(num(a), at[0]), E.mul(num(b), at[1]), num(bias))
        neurons.append(E.mul(num(weight), E.apply("tanh", inner)))
    return E.add(*neurons)


def in_box(bound: float) -> L.Formula:
    return L.conjunction(*(L.Compare(op, v, num(s * bound)) for v in (X, Y)
                           for op, s in (("<=", 1), (">=", -1))))


def test_the_next_state_held_by_every_neuron_is_named():
    f0, f1 = next_state()
    named = worth_naming([barrier((f0, f1))])
    assert set(named) == {f0, f1}


def test_small_repetitions_are_not_named():
    neuron = E.apply("tanh", E.add(X, Y))
    assert worth_naming([E.add(E.mul(neuron, X), E.mul(neuron, Y), E.power(X, E.Num(3)))]) == []


def test_named_terms_come_inner_first():
    inner = E.add(E.apply("tanh", E.add(X, E.mul(num(0.5), Y))), E.apply("sin", X), E.mul(X, Y))
    outer = barrier((inner, E.add(inner, X)))
    named = worth_naming([E.add(*(E.mul(num(k + 1), E.apply("tanh", E.add(outer, num(k))))
                                   for k in range(6)))])
    assert len(named) >= 2
    for i, term in enumerate(named):  # no term holds one named after it
        later = set(named[i + 1:])
        assert not any(node in later for node in E.walk(term))


def test_naming_makes_the_tree_smaller():
    f0, f1 = next_state()
    root = barrier((f0, f1))
    named = worth_naming([root])
    assert tree_size(root) > 3 * (tree_size(root) - (NEURONS - 1) * sum(
        tree_size(term) - 1 for term in named))


def _maximum_on_grid(expr: E.Expr, bound: float) -> float:
    grid = np.linspace(-bound, bound, 201)
    xs, ys = np.meshgrid(grid, grid)
    return float(np.max(evaluate(expr, {"x0": xs.ravel(), "x1": ys.ravel()})))


@pytest.mark.parametrize("named", [True, False])
def test_answers_are_the_same_with_and_without_names(named, monkeypatch):
    if not named:
        monkeypatch.setattr(interval_backend, "worth_naming", lambda roots: [])
    b_next = barrier(next_state())
    highest = _maximum_on_grid(b_next, 1.0)
    above = L.conjunction(in_box(1.0), L.Compare(">=", b_next, num(highest + 0.05)))
    answer = IntervalBackend().check(above, ["x0", "x1"], 60)
    assert answer.status is Status.UNSAT
    below = L.conjunction(in_box(1.0), L.Compare(">=", b_next, num(highest - 0.05)))
    answer = IntervalBackend().check(below, ["x0", "x1"], 60)
    assert answer.status is Status.SAT
    point = {k: float(v) for k, v in answer.model.items()}
    assert max(abs(v) for v in point.values()) <= 1.0 + 1e-3
    assert evaluate(b_next, point) >= highest - 0.05 - 1e-3


def test_a_named_query_split_into_pieces_keeps_its_answer():
    b_next = barrier(next_state())
    highest = _maximum_on_grid(b_next, 1.0)
    backend = IntervalBackend()
    query = L.conjunction(in_box(1.0), L.Compare(">=", b_next, num(highest + 0.05)))
    for low in (-1.0, 0.0):
        piece = L.conjunction(L.Compare(">=", X, num(low)), L.Compare("<=", X, num(low + 1)))
        assert backend.check_within(query, piece, ["x0", "x1"], 60).status is Status.UNSAT
    assert len(next(iter(backend._compiled.values()))[1]) == 2  # both terms named
