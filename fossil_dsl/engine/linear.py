"""The linearisation's quadratic Lyapunov function (and LQR gain), as the networks'
starting point.

Where the linearisation at the origin is stable (or stabilisable through the inputs),
x^T P x with A^T P + P A = -I (P - A^T P A = I in discrete time) is a Lyapunov function
near the origin, and u = -K x from the Riccati equation stabilises it. A one-layer
square network computes exactly such a form (rows of the Cholesky factor of P as the
first layer), and a linear controller network computes -K x; seeding them so lets the
first iteration verify the textbook certificate, and learning start from it where it
does not suffice. Nothing here is trusted: the seed is verified like any candidate.
"""
from __future__ import annotations

import math
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np

from fossil_dsl.engine import quadratic_layers
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.calculus import derivative
from fossil_dsl.ir.enclosure import enclose
from fossil_dsl.ir.spec import CheckedSpec, TimeDomain
from fossil_dsl.plan.certificates.roa import ROA_FORMS

if TYPE_CHECKING:  # torch only where a network is set: the linearisation itself is numpy
    from fossil_dsl.engine.networks import Network

STABLE_FORMS = ("stability", "stable while avoid") + ROA_FORMS
# where between the largest x^T P x on I and the smallest on U (sampled) the barrier's
# zero level goes: low, since the quadratic's decrease is surest near the origin
LEVEL_POSITION = 0.25
OPERATING_STEPS = 20
MAX_CONDITION = 1e6  # a P this ill-conditioned would not survive rounding to decimals
STEP = 1e-7  # of the one-sided difference quotients, where an exact derivative is 0/0
SIDES_AGREE = 1e-4  # relative: the two quotients agree within this (a kink does not)


def jacobians(spec: CheckedSpec, inputs=None, state=None) -> tuple[np.ndarray, np.ndarray] | None:
    """A = df/dx and B = df/du at x = `state` (default 0) and u = `inputs` (default 0),
    or None where a derivative is not a finite number there."""
    point = _point(spec, inputs, state)
    try:
        rows = [[_partial(f, v, point) for v in (*spec.states, *spec.inputs)]
                for f in spec.dynamics]
    except (E.ExprError, ValueError, ZeroDivisionError):
        return None
    matrix = np.array(rows, dtype=float).reshape(len(spec.states), -1)
    if not np.all(np.isfinite(matrix)):
        return None
    n = len(spec.states)
    return matrix[:, :n], matrix[:, n:]


def _partial(f: E.Expr, var: str, point: dict) -> float:
    """df/dvar at the point: the exact derivative's value, or where that is undefined
    there (w |w| gives |w| + w (w/|w|), 0/0 at w = 0) the two one-sided difference
    quotients where they agree (the linearisation only seeds candidates)."""
    try:
        return _value_at(derivative(f, var), point)
    except (E.ExprError, ValueError, ZeroDivisionError):
        pass
    here = float(point[var].value)
    at = lambda x: _value_at(f, {**point, var: E.Num(Fraction(x))})  # noqa: E731
    centre = at(here)
    right = (at(here + STEP) - centre) / STEP
    left = (centre - at(here - STEP)) / STEP
    if abs(right - left) > SIDES_AGREE * (1 + abs(right)):
        raise ValueError(f"no derivative in {var} at the point")
    return (right + left) / 2


def _point(spec: CheckedSpec, inputs=None, state=None) -> dict[str, E.Expr]:
    values = [0.0] * len(spec.inputs) if inputs is None else inputs
    where = [0.0] * len(spec.states) if state is None else state
    point = {name: E.Num(Fraction(float(x))) for name, x in zip(spec.states, where)}
    point.update({name: E.Num(Fraction(float(v))) for name, v in zip(spec.inputs, values)})
    return point


def operating_point(spec: CheckedSpec, state=None) -> np.ndarray | None:
    """Inputs u* that make `state` (default the origin) an equilibrium, f(x, u*) = 0 (x+
    = x in discrete time; Gauss-Newton from u = 0; an empty vector without inputs), or
    None where none is found."""
    u = np.zeros(len(spec.inputs))
    for _ in range(OPERATING_STEPS):
        residual = _residual(spec, u, state)
        if residual is None:
            return None
        if np.abs(residual).max(initial=0.0) < 1e-10:
            return u
        found = jacobians(spec, u, state)
        if found is None or not u.size:
            return None
        u = u - np.linalg.lstsq(found[1], residual, rcond=None)[0]
    return None


def equilibrium(spec: CheckedSpec, start) -> np.ndarray | None:
    """An equilibrium of the system with every input 0 found by Newton's method from
    `start`, or None where it does not converge."""
    x = np.asarray(start, dtype=float)
    n = len(x)
    for _ in range(OPERATING_STEPS):
        residual = _residual(spec, None, x)
        if residual is None or not np.all(np.isfinite(residual)):
            return None
        if np.abs(residual).max(initial=0.0) < 1e-10:
            return x
        found = jacobians(spec, None, x)
        if found is None:
            return None
        A = found[0] - np.eye(n) if spec.time is TimeDomain.DISCRETE else found[0]
        x = x - np.linalg.lstsq(A, residual, rcond=None)[0]
    return None


def _residual(spec: CheckedSpec, inputs, state) -> np.ndarray | None:
    """f(x, u), minus x in discrete time (zero at an equilibrium)."""
    point = _point(spec, inputs, state)
    try:
        values = np.array([_value_at(f, point) for f in spec.dynamics])
    except (E.ExprError, ValueError, ZeroDivisionError):
        return None
    if spec.time is TimeDomain.DISCRETE:
        values = values - (np.zeros(len(values)) if state is None else np.asarray(state))
    return values


def _value_at(expr: E.Expr, point) -> float:
    value = traversal.substitute(expr, point)
    if isinstance(value, E.Num):
        return float(value.value)
    low, high = enclose(value)
    if not low <= high:
        raise ValueError("undefined at the point")
    return (low + high) / 2


def local_certificate(spec: CheckedSpec, controlled: bool, inputs=None):
    """(P, K): P positive definite with a negative definite change along the linearised
    closed loop u = inputs - K x (K None without inputs); None where the linearisation is
    not stable (not stabilisable) or P is too ill-conditioned to round."""
    found = closed_loop(spec, controlled, inputs)
    if found is None:
        return None
    A, K = found
    P = lyapunov_matrix(A, spec.time is TimeDomain.DISCRETE)
    return None if P is None else (P, K)


def closed_loop(spec: CheckedSpec, controlled: bool, inputs=None, state_weight=None,
                input_weight=None, state=None):
    """(A - B K, K): the linearisation at `state` (default the origin) closed by the LQR
    gain for the weights (identities by default; K None without control), or None where
    it is not stable (not stabilisable) or has no finite Jacobian."""
    from scipy import linalg
    found = jacobians(spec, inputs, state)
    if found is None:
        return None
    A, B = found
    discrete = spec.time is TimeDomain.DISCRETE
    K = None
    try:
        if controlled and B.size:
            Q = np.eye(len(A)) if state_weight is None else state_weight
            R = np.eye(B.shape[1]) if input_weight is None else input_weight
            if discrete:
                S = linalg.solve_discrete_are(A, B, Q, R)
                K = np.linalg.solve(R + B.T @ S @ B, B.T @ S @ A)
            else:
                S = linalg.solve_continuous_are(A, B, Q, R)
                K = np.linalg.solve(R, B.T @ S)
            A = A - B @ K
    except (np.linalg.LinAlgError, ValueError):
        return None
    return (A, K) if is_stable(A, discrete) else None


def is_stable(A: np.ndarray, discrete: bool) -> bool:
    """Every eigenvalue inside the unit circle (a map) or in the left half-plane."""
    eigenvalues = np.linalg.eigvals(A)
    return bool(np.all(np.abs(eigenvalues) < 1) if discrete else np.all(eigenvalues.real < 0))


def lyapunov_matrix(A: np.ndarray, discrete: bool, decrease=None) -> np.ndarray | None:
    """P (largest eigenvalue 1) with A^T P + P A = -Q (P - A^T P A = Q in discrete time)
    for a stable A and Q = `decrease` (default I); None where P is too ill-conditioned
    to round."""
    from scipy import linalg
    Q = np.eye(len(A)) if decrease is None else decrease
    try:
        P = linalg.solve_discrete_lyapunov(A.T, Q) if discrete \
            else linalg.solve_continuous_lyapunov(A.T, -Q)
    except (np.linalg.LinAlgError, ValueError):
        return None
    P = (P + P.T) / 2
    eigenvalues = np.linalg.eigvalsh(P)
    if not np.all(np.isfinite(P)) or eigenvalues[0] <= 0 \
            or eigenvalues[-1] / eigenvalues[0] > MAX_CONDITION:
        return None
    return P / eigenvalues[-1]


def separation(P: np.ndarray, inside, outside, floor: float | None = None,
               ceiling: float | None = None) -> tuple[float, float | None]:
    """(how many times the largest x^T P x on the sampled `inside` goes into the
    smallest on the sampled `outside` (or `floor`, where lower: a bound worked out for
    the outside set's shape; `ceiling` likewise bounds the inside set's from above),
    infinite where the first is 0, and a level c between them), or (0, None) where no
    level separates them."""
    if inside is None or outside is None or not len(inside) or not len(outside):
        return 0.0, None
    high = float(quadratic_values(P, inside).max())
    low = float(quadratic_values(P, outside).min())
    if floor is not None:
        low = min(low, floor)
    if ceiling is not None:
        high = max(high, ceiling)
    if not 0 <= high < low:
        return 0.0, None
    return (low / high if high > 0 else math.inf), high + LEVEL_POSITION * (low - high)


def quadratic_values(P: np.ndarray, points) -> np.ndarray:
    """x^T P x at each point (numpy, from torch tensors or arrays)."""
    points = as_array(points)
    return np.einsum("bi,ij,bj->b", points, P, points)


def as_array(points) -> np.ndarray:
    return np.asarray(points.detach() if hasattr(points, "detach") else points,
                      dtype=np.float64)


def holds_a_quadratic(network: Network, n: int) -> bool:
    """Whether the network's layers can hold x^T P x (quadratic_layers.py)."""
    return quadratic_layers.route(network, n) is not None


def is_linear(network: Network, outputs: int) -> bool:
    return (network.divisors is None
            and all(a.name == "linear" for a in network.activations)
            and len(network.linears) == 1 and network.linears[0].out_features >= outputs)


def set_quadratic(network: Network, P: np.ndarray, level: float = 0.0, centre=None) -> None:
    """V(x) = (x - c)^T P (x - c) - level in the network's weights: the last hidden layer
    squares the rows of L^T (P = L L^T), the layers before pass x on
    (quadratic_layers.py); the spare units start with output weight 0. A network with a
    `centre` c must have biases."""
    quadratic_layers.write(network, P, level, centre)


def set_linear(network: Network, gain: np.ndarray, offset=None) -> None:
    """k(x) = gain x + offset: the hidden layer holds the gain, the output passes it
    through and adds the offset."""
    import torch
    m = gain.shape[0]
    with torch.no_grad():
        hidden, output = network.linears[0].weight, network.output.weight
        hidden.zero_()
        hidden[:m] = torch.as_tensor(gain, dtype=torch.float64)
        output.zero_()
        output[:, :m] = torch.eye(m, dtype=torch.float64)
        _set_output_bias(network, offset)


def _set_output_bias(network: Network, values) -> None:
    """Hidden biases 0; the output's first biases `values` (a network without biases
    must not be given non-zero ones)."""
    import torch
    for layer in (network.linears[0], network.output):
        if layer.bias is not None:
            layer.bias.zero_()
    if values is not None and len(values) and network.output.bias is not None:
        network.output.bias[:len(values)] = torch.as_tensor(values, dtype=torch.float64)
