"""The activation functions a network layer may use, by name.

Each activation has two faces in one place: `symbolic` builds its exact neutral
expression (for the verifier) and `tensor` applies it to a batch (for the learner).
A new activation is one entry in ACTIVATIONS.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable

from fossil_dsl.ir import expr as E


# sigmoid(z) = 1/2 + tanh(z/2)/2, the same function as 1/(1 + exp(-z)) but with a
# derivative, 1/4 (1 - tanh(z/2)^2), that holds z once where the quotient's holds it
# twice: a two-layer network's flow query is a tree half the size, and its enclosures
# are tighter (f1_barr3's flow proof: 2628 -> 1284 contractions)
HALF = E.Num(Fraction(1, 2))


def _chunk_power(index: int, width: int, degree: int) -> int:
    """polyN splits a layer's neurons into N chunks with powers 1..N."""
    return 1 + (index * degree) // width


def poly_neurons(width: int, degree: int, power: int) -> list[int]:
    """The neurons of a polyN layer (N = degree) that raise their input to `power`."""
    return [i for i in range(width) if _chunk_power(i, width, degree) == power]


@dataclass(frozen=True)
class Activation:
    name: str
    polynomial_degree: int | None  # None: not a polynomial
    zero_at_zero: bool
    symbolic: Callable[[E.Expr, int, int], E.Expr]  # (pre-activation, neuron, width)
    tensor: Callable  # (batch, width) tensor -> same shape
    # whether a(z) - a(0) is odd in z, for the neuron (index, width)
    odd: Callable[[int, int], bool] = lambda i, w: False

    def apply(self, z: E.Expr, index: int, width: int) -> E.Expr:
        return self.symbolic(z, index, width)


def _power(n: int) -> Activation:
    name = {1: "linear", 2: "square", 3: "cube"}[n]
    return Activation(name, n, True, lambda z, i, w: E.power(z, E.Num(n)),
                      lambda t: t if n == 1 else t ** n, lambda i, w: n % 2 == 1)


def _poly(degree: int) -> Activation:
    def tensor(t):
        import torch
        width = t.shape[-1]
        powers = torch.tensor([_chunk_power(i, width, degree) for i in range(width)],
                              dtype=t.dtype)
        return t ** powers

    return Activation(f"poly{degree}", degree, True,
                      lambda z, i, w: E.power(z, E.Num(_chunk_power(i, w, degree))), tensor,
                      lambda i, w: _chunk_power(i, w, degree) % 2 == 1)


def _softplus(t):
    import torch.nn.functional as F
    return F.softplus(t)


ACTIVATIONS: dict[str, Activation] = {a.name: a for a in (
    _power(1), _power(2), _power(3), _poly(2), _poly(3), _poly(4),
    Activation("relu", None, True,
               lambda z, i, w: E.mul(E.Num(Fraction(1, 2)), E.add(z, E.apply("abs", z))),
               lambda t: t.relu()),
    Activation("sigmoid", None, False,
               lambda z, i, w: E.add(HALF, E.mul(HALF, E.apply("tanh", E.mul(HALF, z)))),
               lambda t: t.sigmoid(), lambda i, w: True),
    Activation("tanh", None, True, lambda z, i, w: E.apply("tanh", z), lambda t: t.tanh(),
               lambda i, w: True),
    Activation("softplus", None, False,
               lambda z, i, w: E.apply("log", E.add(E.ONE, E.apply("exp", z))), _softplus),
)}


def odd_without_biases(layers) -> bool:
    """Whether a network of these hidden layers (name, width), a linear output, no biases
    and its value at 0 subtracted, is an odd function of its input for every weight:
    every neuron's a(z) - a(0) odd, and a(0) = 0 in each layer before the last (a
    constant passed on acts as a bias)."""
    *inner, last = [(ACTIVATIONS[layer.activation], layer.width) for layer in layers]
    return (all(a.zero_at_zero for a, _ in inner)
            and all(a.odd(i, w) for a, w in (*inner, last) for i in range(w)))
