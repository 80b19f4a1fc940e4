"""The exact formula that is verified is the function the learner trained: for every
activation, formula(x) equals the torch network at random points."""
from fractions import Fraction

import pytest
import torch

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.activations import ACTIVATIONS
from fossil_dsl.ir.spec import Layer
from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.networks import Network, input_divisors

STATES = ("x0", "x1", "x2")


@pytest.mark.parametrize("zero_at_origin", [True, False], ids=["no-bias", "bias"])
@pytest.mark.parametrize("activation", list(ACTIVATIONS))
def test_formula_equals_network(activation, zero_at_origin):
    torch.manual_seed(7)
    network = Network(3, (Layer(activation, 6), Layer("square", 4)), zero_at_origin)
    network.round_weights(3)
    formula = network.formula(STATES, digits=3)
    points = torch.rand(50, 3, dtype=torch.float64) * 4 - 2
    expected = network(points).detach()
    got = torch.as_tensor(evaluate(formula, state_env(STATES, points)), dtype=torch.float64)
    assert torch.allclose(got.expand(50), expected, rtol=1e-9, atol=1e-9)
    if zero_at_origin:
        assert traversal.substitute(formula, {s: E.ZERO for s in STATES}) == E.ZERO
        assert float(network(torch.zeros(1, 3, dtype=torch.float64)).detach()) == 0.0


def test_polynomial_activations_give_polynomials():
    for name, activation in ACTIVATIONS.items():
        network = Network(2, (Layer(name, 3),), zero_at_origin=True)
        formula = network.formula(("x0", "x1"), digits=3)
        assert traversal.is_arithmetic(formula) == (activation.polynomial_degree is not None
                                            or name == "relu")


def test_centred_network_sees_offset_inputs_as_a_plain_one_sees_the_origin():
    torch.manual_seed(3)
    plain = Network(2, [Layer("square", 4)], zero_at_origin=False)
    torch.manual_seed(3)
    centred = Network(2, [Layer("square", 4)], zero_at_origin=False, centre=[20.0, 20.0])
    offset = torch.tensor([[20.5, 19.0], [20.0, 20.0]], dtype=torch.float64)
    assert torch.allclose(centred(offset), plain(offset - 20.0))
    # the exact formula is the same function (the centring is in the biases)
    x = {"x0": offset[:, 0], "x1": offset[:, 1]}
    exact = evaluate(centred.formula(["x0", "x1"], 12), x)
    assert torch.allclose(torch.as_tensor(exact, dtype=torch.float64), centred(offset))
    centred.reset()
    first = centred.linears[0]
    assert torch.allclose(first.bias + first.weight @ torch.tensor([20.0, 20.0],
                          dtype=torch.float64), torch.zeros(4, dtype=torch.float64), atol=1.0)


def test_centring_leaves_networks_on_domains_around_the_origin_and_without_biases_alone():
    torch.manual_seed(5)
    plain = Network(2, [Layer("tanh", 3)], zero_at_origin=False)
    torch.manual_seed(5)
    centred = Network(2, [Layer("tanh", 3)], zero_at_origin=False, centre=[0.0, 0.0])
    assert all(torch.equal(a, b) for a, b in zip(plain.parameters(), centred.parameters()))
    no_bias = Network(2, [Layer("square", 3)], zero_at_origin=True, centre=[20.0, 20.0])
    assert no_bias(torch.zeros(1, 2, dtype=torch.float64)).item() == 0.0


def test_input_divisor_is_exact_in_the_formula_and_the_weights_on_x():
    torch.manual_seed(11)
    network = Network(3, [Layer("linear", 4), Layer("square", 2)], zero_at_origin=False,
                      centre=[1.0, 0.0, 0.0], input_divisor=(1, 1000, 1))
    network.round_weights(3)
    points = torch.rand(40, 3, dtype=torch.float64) * 4 - 2
    exact = evaluate(network.formula(STATES, 3), state_env(STATES, points))
    assert torch.allclose(torch.as_tensor(exact, dtype=torch.float64), network(points),
                          rtol=1e-12, atol=1e-12)
    weights, _ = network.exact_layers(3)[0]
    trained = network.linears[0].weight.detach()
    assert weights[0][1] == Fraction(round(float(trained[0, 1]) * 1000), 1000) / 1000
    assert weights[0][0] == Fraction(round(float(trained[0, 0]) * 1000), 1000)
    assert "input_divisor" in network.state_dict()
    from fossil_dsl.outputs.result import network_json
    reported = network_json(network, 3)["layers"][0]["weight"]
    assert reported == [[str(w) for w in row] for row in weights]


def test_no_divisor_when_every_field_component_is_of_one_size():
    assert input_divisors([1.3, 2.9, 0.2]) is None
    assert input_divisors([0.0, 0.0, 5.0]) is None  # median 0: no scale to compare with
    assert input_divisors([1.25, 1.27, 1.27, 8390.0]) == (1, 1, 1, 1000)
    assert input_divisors([1.0, 1.0, 99.0]) is None
    assert input_divisors([1.0, 1.0, 1.0, 150.0, 2.5e7]) == (1, 1, 1, 100, 10 ** 7)


def test_climb_moves_along_a_level_set_to_the_worst_point_in_the_box():
    from fossil_dsl.engine.ascent import climb

    def objective(x):  # violation x1, on the level set x0 + x1 = 1
        return x[:, 1], x[:, 0] + x[:, 1] - 1

    starts = torch.tensor([[0.5, 0.5], [1.5, -0.5], [0.0, 1.0]], dtype=torch.float64)
    moved = climb(starts, objective, ([-2.0, -2.0], [2.0, 2.0]), steps=30, step_fraction=0.02)
    assert torch.allclose(moved[:, 0] + moved[:, 1], torch.ones(3, dtype=torch.float64),
                          atol=1e-9)
    assert (moved[:, 1] > 1.9 - 1e-9).all() and (moved.abs() <= 2.0).all()
    free = climb(starts, lambda x: (-x.pow(2).sum(1), None), ([-2.0, -2.0], [2.0, 2.0]),
                 steps=30, step_fraction=0.02)
    assert free.abs().max() < 0.1  # no level set: plain ascent, to the origin here


@pytest.mark.parametrize("activation", list(ACTIVATIONS))
def test_formula_text_reads_back_as_the_same_expression(activation):
    """recheck derives the obligations again from the formulas' text in result.json and
    compares them with the exported ones: c*1/(u) used to read back as (c*1)/u, and
    every sigmoid certificate was reported altered."""
    from fossil_dsl.outputs.recheck import read_formulas
    torch.manual_seed(7)
    for zero_at_origin in (True, False):
        network = Network(3, (Layer(activation, 4), Layer("square", 3)), zero_at_origin)
        network.round_weights(3)
        formula = network.formula(STATES, digits=3)
        assert read_formulas({"V": E.to_text(formula)}, STATES)["V"] == formula


def test_a_quotient_after_a_factor_reads_back_as_the_same_expression():
    from fossil_dsl.outputs.recheck import read_formulas
    x0 = E.Var("x0")
    quotient = E.div(E.ONE, E.add(E.ONE, E.apply("exp", E.neg(x0))))
    product = E.mul(E.Num(Fraction(263, 1000)), quotient)
    assert E.to_text(product) == "0.263*(1/(exp(-x0) + 1))"
    assert read_formulas({"V": E.to_text(product)}, STATES)["V"] == product
