"""Lie derivatives and a step's change: equal to the textbook forms wherever evaluated,
and written in the form that is smaller as a tree (what the interval procedure
evaluates)."""
import random
from fractions import Fraction

import pytest
import torch

from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.networks import Network
from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.spec import Layer

STATES = ("x0", "x1")
X0, X1 = E.Var("x0"), E.Var("x1")
CUBIC_FIELD = (X1, E.add(E.neg(X0), E.neg(X1), E.mul(E.Num(Fraction(1, 3)),
                                                     E.power(X0, E.Num(3)))))


def _network(layers, seed=3):
    torch.manual_seed(seed)
    network = Network(2, layers, True)
    network.round_weights(3)
    return network.formula(STATES, digits=3)


def _sum_form(expr, field):
    return E.add(*(E.mul(g, f) for g, f in
                   zip(calculus.gradient(expr, STATES), field)))


def _agree(a, b, points=40):
    rng = random.Random(0)
    for _ in range(points):
        env = {s: rng.uniform(-2, 2) for s in STATES}
        assert float(evaluate(a, env)) == pytest.approx(float(evaluate(b, env)),
                                                        rel=1e-9, abs=1e-9)


def test_tree_size_counts_every_occurrence():
    shared = E.apply("tanh", X0)  # 2 nodes, used three times
    expr = E.mul(E.add(shared, E.mul(shared, X1)), E.add(shared, X1))
    assert traversal.tree_size(expr) == len(list(E.walk(expr))) == 12
    assert len(list(traversal.distinct_nodes(expr))) == 7


def test_a_two_layer_networks_lie_derivative_is_taken_along_the_field():
    """f1_barr3's shape: sigmoid(10), sigmoid(10) under a cubic field. The derivative
    along the field is the smaller tree; it equals the sum of partials times the field."""
    V = _network((Layer("sigmoid", 10), Layer("sigmoid", 10)))
    lie = calculus.lie_derivative(V, STATES, CUBIC_FIELD)
    summed = _sum_form(V, CUBIC_FIELD)
    assert lie != summed
    assert traversal.tree_size(lie) < 0.9 * traversal.tree_size(summed)
    _agree(lie, summed)


def test_a_field_holding_a_network_keeps_the_sum_of_partials():
    """row05's shape: a controller network in the field would be copied into every
    neuron's derivative along the field; the sum copies it once per variable."""
    V = _network((Layer("tanh", 3),))
    controller = _network((Layer("tanh", 12), Layer("tanh", 12)), seed=5)
    field = (X1, E.add(E.neg(X0), controller))
    lie = calculus.lie_derivative(V, STATES, field)
    assert lie == _sum_form(V, field)
    along = calculus.directional(V, dict(zip(STATES, field)))
    assert traversal.tree_size(along) > traversal.tree_size(lie)
    _agree(lie, along)


def test_a_polynomial_keeps_the_sum_of_partials():
    V = _network((Layer("square", 6),))
    assert calculus.lie_derivative(V, STATES, CUBIC_FIELD) == _sum_form(V, CUBIC_FIELD)


def test_sigmoid_is_written_with_tanh_and_equals_the_logistic_function():
    V = _network((Layer("sigmoid", 4),))
    assert any(isinstance(n, E.Apply) and n.func == "tanh" for n in E.walk(V))
    assert not any(isinstance(n, E.Apply) and n.func == "exp" for n in E.walk(V))
    points = torch.rand(30, 2, dtype=torch.float64) * 6 - 3
    z = E.add(E.mul(E.Num(Fraction(7, 4)), X0), E.neg(X1))
    from fossil_dsl.ir.activations import ACTIVATIONS
    sigmoid = ACTIVATIONS["sigmoid"].apply(z, 0, 1)
    got = evaluate(sigmoid, state_env(STATES, points))
    expected = torch.sigmoid(1.75 * points[:, 0] - points[:, 1])
    assert torch.allclose(torch.as_tensor(got), expected, rtol=1e-12, atol=1e-12)


def test_a_networks_step_change_is_not_expanded():
    """Expanding V(f(x)) - V(x) pays where V is a polynomial (its large terms cancel);
    for a network with functions it only enlarges the query (row17: 17 534 -> 21 654
    nodes)."""
    V = _network((Layer("tanh", 4), Layer("square", 3)))
    step = (E.add(X0, E.mul(E.Num(Fraction(1, 10)), X1)),
            E.add(X1, E.mul(E.Num(Fraction(1, 10)), E.apply("sin", X0))))
    change = calculus.change(V, STATES, step, discrete=True)
    assert change == E.add(calculus.compose(V, STATES, step), E.neg(V))
