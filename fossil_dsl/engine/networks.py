"""Feed-forward networks for certificates, and their exact rational formulas."""
from __future__ import annotations

import math
from fractions import Fraction
from typing import Sequence

import torch

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.activations import ACTIVATIONS
from fossil_dsl.ir.numbers import rational
from fossil_dsl.ir.spec import Layer


class Network(torch.nn.Module):
    """Hidden layers as given, then a linear output (one value, or `outputs` values for a
    controller). With `zero_at_origin`, there are no biases and the value at 0 is
    subtracted, so C(0) = 0 exactly, for any activation.

    With a `centre` (the middle of the domain), the first layer's biases start so that
    it sees x - centre: torch's initial weights suit inputs around 0, and on a domain
    such as [18, 23]^2 the first steps would otherwise only undo the offset.

    With an `input_divisor` (one power of ten per input), the first layer sees x_j / d_j:
    its trained weight w stands for the weight w / d_j on x_j. Where one component of
    the vector field is orders of magnitude larger than the others, the certificate's
    weight on that coordinate must be as many orders smaller and exact to a few percent
    of itself; Adam's steps, about the learning rate in every weight, cannot reach that,
    but they can on w. The divisor is kept in the state dict ("input_divisor")."""

    def __init__(self, inputs: int, layers: Sequence[Layer], zero_at_origin: bool,
                 outputs: int = 1, centre: Sequence[float] | None = None,
                 input_divisor: Sequence[int] | None = None):
        super().__init__()
        self.activations = [ACTIVATIONS[layer.activation] for layer in layers]
        widths = [inputs] + [layer.width for layer in layers]
        bias = not zero_at_origin
        self.linears = torch.nn.ModuleList(
            torch.nn.Linear(a, b, bias=bias, dtype=torch.float64)
            for a, b in zip(widths, widths[1:]))
        self.output = torch.nn.Linear(widths[-1], outputs, bias=bias, dtype=torch.float64)
        self.outputs = outputs
        self.zero_at_origin = zero_at_origin
        self.subtract_origin = zero_at_origin and not all(a.zero_at_zero
                                                         for a in self.activations)
        self.centre = torch.tensor(centre, dtype=torch.float64) \
            if centre is not None and any(centre) else None
        self.divisors = tuple(input_divisor) if input_divisor is not None \
            and any(d != 1 for d in input_divisor) else None
        if self.divisors is not None:
            self.register_buffer("input_divisor",
                                 torch.tensor(self.divisors, dtype=torch.float64))
        self._centre_first_layer()

    def reset(self) -> None:
        """New initial weights (centred as at construction)."""
        for layer in [*self.linears, self.output]:
            layer.reset_parameters()
        self._centre_first_layer()

    def _centre_first_layer(self) -> None:
        first = self.linears[0] if len(self.linears) else self.output
        if self.centre is None or first.bias is None:
            return
        centre = self.centre if self.divisors is None else self.centre / self.input_divisor
        with torch.no_grad():
            first.bias.sub_(first.weight @ centre)

    def raw(self, x: torch.Tensor) -> torch.Tensor:
        if self.divisors is not None:
            x = x / self.input_divisor
        for linear, activation in zip(self.linears, self.activations):
            x = activation.tensor(linear(x))
        x = self.output(x)
        return x.squeeze(-1) if self.outputs == 1 else x

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        value = self.raw(x)
        if self.subtract_origin:
            value = value - self.raw(torch.zeros(1, x.shape[-1], dtype=x.dtype))
        return value

    def round_weights(self, digits: int) -> None:
        """Round every weight to `digits` decimals, so the torch network is exactly the
        rational one that is verified and reported."""
        with torch.no_grad():
            for parameter in self.parameters():
                parameter.copy_(torch.round(parameter * 10 ** digits) / 10 ** digits)

    def formula(self, states: Sequence[str], digits: int) -> E.Expr:
        """The exact formula of the network with weights rounded to `digits` decimals."""
        return self.formulas(states, digits)[0]

    def exact_layers(self, digits: int) -> list[tuple[list[list[Fraction]], list[Fraction]]]:
        """Each affine layer's weights and biases (zero where it has none) as exact
        rationals: the weights on x itself, so the first layer's are divided by the
        input divisor."""
        layers = [_exact(linear, digits) for linear in [*self.linears, self.output]]
        if self.divisors is not None:
            weights, biases = layers[0]
            layers[0] = ([[w / d for w, d in zip(row, self.divisors)] for row in weights],
                         biases)
        return layers

    def formulas(self, states: Sequence[str], digits: int) -> list[E.Expr]:
        """One exact formula per output."""
        values: list[E.Expr] = [E.Var(s) for s in states]
        *hidden, output = self.exact_layers(digits)
        for layer, activation in zip(hidden, self.activations):
            pre = _affine(layer, values)
            values = [activation.apply(z, i, len(pre)) for i, z in enumerate(pre)]
        results = _affine(output, values)
        if self.subtract_origin:
            origin = {s: E.ZERO for s in states}
            results = [E.add(r, E.neg(traversal.substitute(r, origin))) for r in results]
        return results


STIFF_RATIO = 100  # a field component this many times the median one is scaled down


def input_divisors(field_scales: Sequence[float]) -> tuple[int, ...] | None:
    """A power of ten per coordinate, for a certificate network's input: 10^k where the
    field component is 10^k to 10^(k+1) times the median component's size, for k >= 2
    (STIFF_RATIO); 1 elsewhere. None where no coordinate needs one."""
    ordered = sorted(field_scales)
    median = (ordered[(len(ordered) - 1) // 2] + ordered[len(ordered) // 2]) / 2
    if not ordered or not median > 0 or not all(map(math.isfinite, ordered)):
        return None
    divisors = tuple(10 ** int(math.floor(math.log10(scale / median)))
                     if scale >= STIFF_RATIO * median else 1 for scale in field_scales)
    return divisors if any(d != 1 for d in divisors) else None


def _exact(linear: torch.nn.Linear, digits: int):
    weights = [[rational(w, digits) for w in row] for row in linear.weight.detach().tolist()]
    biases = [rational(b, digits) for b in linear.bias.detach().tolist()] \
        if linear.bias is not None else [Fraction(0)] * len(weights)
    return weights, biases


def _affine(layer, values: list[E.Expr]) -> list[E.Expr]:
    weights, biases = layer
    return [E.add(*(E.mul(E.Num(w), v) for w, v in zip(row, values)), E.Num(b))
            for row, b in zip(weights, biases)]
