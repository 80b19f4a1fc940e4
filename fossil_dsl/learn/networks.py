"""Feed-forward networks for certificates, and their exact rational formulas."""
from __future__ import annotations

from fractions import Fraction
from typing import Sequence

import torch

from fossil_dsl.ir import expr as E
from fossil_dsl.ir.activations import ACTIVATIONS
from fossil_dsl.ir.spec import Layer


class Network(torch.nn.Module):
    """Hidden layers as given, then a linear output (one value, or `outputs` values for a
    controller). With `zero_at_origin`, there are no biases and the value at 0 is
    subtracted, so C(0) = 0 exactly, for any activation.

    With a `centre` (the middle of the domain), the first layer's biases start so that
    it sees x - centre: torch's initial weights suit inputs around 0, and on a domain
    such as [18, 23]^2 the first steps would otherwise only undo the offset."""

    def __init__(self, inputs: int, layers: Sequence[Layer], zero_at_origin: bool,
                 outputs: int = 1, centre: Sequence[float] | None = None):
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
        with torch.no_grad():
            first.bias.sub_(first.weight @ self.centre)

    def raw(self, x: torch.Tensor) -> torch.Tensor:
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

    def formulas(self, states: Sequence[str], digits: int) -> list[E.Expr]:
        """One exact formula per output."""
        values: list[E.Expr] = [E.Var(s) for s in states]
        for linear, activation in zip(self.linears, self.activations):
            pre = _affine(linear, values, digits)
            values = [activation.apply(z, i, len(pre)) for i, z in enumerate(pre)]
        results = _affine(self.output, values, digits)
        if self.subtract_origin:
            origin = {s: E.ZERO for s in states}
            results = [E.add(r, E.neg(E.substitute(r, origin))) for r in results]
        return results


def rational(value: float, digits: int) -> Fraction:
    return Fraction(round(value * 10 ** digits), 10 ** digits)


def _affine(linear: torch.nn.Linear, values: list[E.Expr], digits: int) -> list[E.Expr]:
    weights = linear.weight.detach().tolist()
    biases = linear.bias.detach().tolist() if linear.bias is not None else [0.0] * len(weights)
    return [E.add(*(E.mul(E.Num(rational(w, digits)), v) for w, v in zip(row, values)),
                  E.Num(rational(b, digits)))
            for row, b in zip(weights, biases)]
