"""The activation functions a network layer may use, by name.

The learner and the solvers attach their own implementations to these names; the
checker only needs to know which names exist and which are polynomial.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Activation:
    name: str
    polynomial_degree: int | None  # None: not a polynomial
    zero_at_zero: bool


ACTIVATIONS: dict[str, Activation] = {a.name: a for a in (
    Activation("linear", 1, True),
    Activation("square", 2, True),
    Activation("cube", 3, True),
    Activation("poly2", 2, True),
    Activation("poly3", 3, True),
    Activation("poly4", 4, True),
    Activation("relu", None, True),
    Activation("sigmoid", None, False),
    Activation("tanh", None, True),
    Activation("softplus", None, False),
)}
