"""A quadratic V(x) = (x - c)^T P (x - c) - level written into a network's weights, for
templates of several hidden layers: the layers before the last pass x on, the last
(square, or the power-2 neurons of a polyN layer) squares L^T x (P = L L^T).

How a layer passes x on: the pre-activations A x of its supported neurons, and a readout
R with R h = x for their outputs h:
- linear, and the power-1 neurons of polyN: A = I, R = I (exact);
- relu and softplus: A = [I; -I], R = [I, -I], since relu(z) - relu(-z) = z and
  softplus(z) - softplus(-z) = z (exact);
- tanh: A = eps I, R = I / eps; sigmoid: A = [eps I; -eps I], R = (2 / eps) [I, -I],
  since 2 sigmoid(z) - 1 = tanh(z / 2): close to x only while eps x is small, a seed
  for the learner to improve, never trusted (every seed is verified like any candidate).
Neurons outside the support keep their weights, and the next layer gives them weight 0:
the learner can use them from there.
"""
from __future__ import annotations

import numpy as np

from fossil_dsl.ir.activations import poly_neurons

EPS = 0.05  # tanh(0.05 x) is within 1.3 % of 0.05 x for |x| <= 4


def _passing(activation, width: int, n: int):
    """(rows, A, R) for a layer passing x on, or None where it cannot."""
    eye = np.eye(n)
    name = activation.name
    if name == "linear" and width >= n:
        return list(range(n)), eye, eye
    if name.startswith("poly"):
        rows = poly_neurons(width, activation.polynomial_degree, 1)[:n]
        return (rows, eye, eye) if len(rows) == n else None
    if name in ("relu", "softplus") and width >= 2 * n:
        return list(range(2 * n)), np.vstack([eye, -eye]), np.hstack([eye, -eye])
    if name == "tanh" and width >= n:
        return list(range(n)), EPS * eye, eye / EPS
    if name == "sigmoid" and width >= 2 * n:
        return (list(range(2 * n)), np.vstack([EPS * eye, -EPS * eye]),
                (2 / EPS) * np.hstack([eye, -eye]))
    return None


def _squaring_rows(activation, width: int, n: int) -> list[int] | None:
    if activation.name == "square":
        return list(range(n)) if width >= n else None
    if activation.name.startswith("poly"):
        rows = poly_neurons(width, activation.polynomial_degree, 2)[:n]
        return rows if len(rows) == n else None
    return None


def route(network, n: int):
    """([(rows, A, R)] for the passing layers, the squaring rows), or None."""
    layers = [(activation, linear.out_features)
              for activation, linear in zip(network.activations, network.linears)]
    if not layers:
        return None
    passes = [_passing(activation, width, n) for activation, width in layers[:-1]]
    squares = _squaring_rows(*layers[-1], n)
    if squares is None or any(p is None for p in passes):
        return None
    return passes, squares


def write(network, P: np.ndarray, level: float = 0.0, centre=None) -> None:
    """V(x) = (x - c)^T P (x - c) - level (exactly, or closely for tanh and sigmoid
    layers); the network must hold a route (and biases where c or level is given)."""
    import torch
    n = len(P)
    passes, squares = route(network, n)
    readout = np.diag(network.divisors) if network.divisors is not None else np.eye(n)
    shift = None if centre is None else np.asarray(centre, dtype=float)
    with torch.no_grad():
        for linear in network.linears:
            if linear.bias is not None:
                linear.bias.zero_()
        for linear, (rows, A, R) in zip(network.linears, passes):
            _set_rows(linear, rows, A @ readout)
            shift, readout = _first_shift(linear, rows, A, shift), R
        factor = np.linalg.cholesky(P).T
        last = network.linears[len(passes)]
        _set_rows(last, squares, factor @ readout)
        _first_shift(last, squares, factor, shift)
        output = network.output
        output.weight.zero_()
        output.weight[0, squares] = 1.0
        if output.bias is not None:
            output.bias.zero_()
            output.bias[0] = -level


def _set_rows(linear, rows, weights: np.ndarray) -> None:
    """The rows' weights; a later layer also gives 0 to the columns outside them."""
    import torch
    block = np.zeros((len(rows), linear.in_features))
    block[:, :weights.shape[1]] = weights
    linear.weight[rows] = torch.as_tensor(block, dtype=torch.float64)


def _first_shift(linear, rows, A: np.ndarray, shift):
    """The first layer's biases -A c (so it sees x - c); None for the layers after."""
    import torch
    if shift is not None:
        linear.bias[rows] = torch.as_tensor(-A @ shift, dtype=torch.float64)
    return None
