"""User templates of several layers hold the linearisation's quadratic seed
(engine/quadratic_layers.py), and templates that cannot give a certificate are refused
or warned about at check time."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from fossil_dsl import check_text
from fossil_dsl.engine.linear import holds_a_quadratic, set_quadratic
from fossil_dsl.engine.networks import Network
from fossil_dsl.ir.spec import Layer

P = np.array([[2.0, 0.3], [0.3, 1.0]])
POINTS = torch.tensor(np.random.default_rng(0).uniform(-2, 2, (300, 2)))


def quadratic(points: np.ndarray, centre=np.zeros(2), level=0.0) -> np.ndarray:
    shifted = points - centre
    return ((shifted @ P) * shifted).sum(1) - level


def layers(*pairs) -> tuple[Layer, ...]:
    return tuple(Layer(name, width) for name, width in pairs)


@pytest.mark.parametrize("template, tolerance", [
    (layers(("square", 8)), 1e-12),
    (layers(("relu", 8), ("square", 4)), 1e-12),
    (layers(("softplus", 4), ("square", 2)), 1e-12),
    (layers(("linear", 3), ("relu", 4), ("square", 2)), 1e-12),
    (layers(("poly4", 8),), 1e-12),
    (layers(("poly2", 4), ("square", 2)), 1e-12),
    (layers(("tanh", 6), ("square", 4)), 0.02),
    (layers(("sigmoid", 6), ("square", 6)), 0.02),
])
@pytest.mark.parametrize("zero_at_origin", [True, False])
def test_templates_hold_the_quadratic(template, tolerance, zero_at_origin):
    network = Network(2, template, zero_at_origin)
    assert holds_a_quadratic(network, 2)
    centre = None if zero_at_origin else np.array([0.5, -0.3])
    level = 0.0 if zero_at_origin else 0.7
    set_quadratic(network, P, level, centre)
    expected = quadratic(POINTS.numpy(), np.zeros(2) if centre is None else centre, level)
    error = np.abs(network(POINTS).detach().numpy() - expected)
    assert error.max() <= tolerance * np.abs(expected).max()


@pytest.mark.parametrize("template", [
    layers(("poly4", 6)),  # one square neuron
    layers(("cube", 4), ("square", 4)),
    layers(("relu", 3), ("square", 4)),  # relu needs a pair per state
    layers(("square", 4), ("tanh", 4)),  # the last layer does not square
    layers(("square", 1)),
])
def test_templates_that_cannot_hold_it(template):
    assert not holds_a_quadratic(Network(2, template, True), 2)


def test_a_relu_seed_passes_x_through_exactly():
    """relu(z) - relu(-z) = z: the seed is the quadratic itself, not an approximation."""
    network = Network(2, layers(("relu", 4), ("square", 2)), True)
    set_quadratic(network, np.eye(2))
    values = network(torch.tensor([[1.0, 0.0], [0.0, -2.0], [-1.0, 1.0]], dtype=torch.float64))
    assert values.detach().numpy() == pytest.approx([1.0, 4.0, 2.0])


MAP = """\
state x, y
dynamics discrete {
    next(x) = 0.5*x + 0.1*y
    next(y) = -0.2*x + 0.4*y
}
domain box([-1, -1], [1, 1])
prove stable
"""


def test_relu_certificate_is_accepted_for_maps_and_controllers():
    assert check_text(MAP + "synthesis { certificate: relu(8), square(4) }\n").ok
    flow = MAP.replace("discrete", "continuous").replace("next(x) =", "x' =") \
        .replace("next(y) =", "y' =").replace("0.5*x", "-x").replace("0.4*y", "-y")
    controlled = flow.replace("state x, y", "state x, y\ninput u").replace("-y\n", "-y + u\n")
    result = check_text(controlled + "synthesis { controller: relu(4) }\n")
    assert result.ok, result.render()
    refused = check_text(flow + "synthesis { certificate: relu(8), square(4) }\n")
    assert not refused.ok and "`relu` has a kink" in refused.render()


@pytest.mark.parametrize("width, warned", [(6, True), (8, False)])
def test_a_poly_layer_with_too_few_squares_is_warned_about(width, warned):
    result = check_text(MAP + f"synthesis {{ certificate: poly4({width}) }}\n")
    assert result.ok
    assert any("quadratic part is singular" in d.message for d in result.diagnostics) == warned
