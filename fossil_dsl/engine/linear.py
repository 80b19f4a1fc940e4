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

import numpy as np
import torch

from fossil_dsl.engine.networks import Network
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.calculus import derivative
from fossil_dsl.ir.enclosure import enclose
from fossil_dsl.ir.spec import CheckedSpec, TimeDomain

STABLE_FORMS = ("stability", "region of attraction", "stable while avoid")
MAX_CONDITION = 1e6  # a P this ill-conditioned would not survive rounding to decimals


def jacobians(spec: CheckedSpec) -> tuple[np.ndarray, np.ndarray] | None:
    """A = df/dx and B = df/du at x = 0, u = 0, or None where a derivative is not a
    finite number there."""
    origin = {name: E.ZERO for name in (*spec.states, *spec.inputs)}
    try:
        rows = [[_value_at(derivative(f, v), origin) for v in (*spec.states, *spec.inputs)]
                for f in spec.dynamics]
    except (E.ExprError, ValueError, ZeroDivisionError):
        return None
    matrix = np.array(rows, dtype=float).reshape(len(spec.states), -1)
    if not np.all(np.isfinite(matrix)):
        return None
    n = len(spec.states)
    return matrix[:, :n], matrix[:, n:]


def _value_at(expr: E.Expr, origin) -> float:
    value = traversal.substitute(expr, origin)
    if isinstance(value, E.Num):
        return float(value.value)
    low, high = enclose(value)
    if not low <= high:
        raise ValueError("undefined at the origin")
    return (low + high) / 2


def local_certificate(spec: CheckedSpec, controlled: bool):
    """(P, K): P positive definite with a negative definite change along the linearised
    closed loop u = -K x (K None without inputs); None where the linearisation is not
    stable (not stabilisable) or P is too ill-conditioned to round."""
    from scipy import linalg
    found = jacobians(spec)
    if found is None:
        return None
    A, B = found
    discrete = spec.time is TimeDomain.DISCRETE
    K = None
    try:
        if controlled and B.size:
            identity_u = np.eye(B.shape[1])
            if discrete:
                S = linalg.solve_discrete_are(A, B, np.eye(len(A)), identity_u)
                K = np.linalg.solve(identity_u + B.T @ S @ B, B.T @ S @ A)
            else:
                S = linalg.solve_continuous_are(A, B, np.eye(len(A)), identity_u)
                K = B.T @ S
            A = A - B @ K
        stable = (np.abs(np.linalg.eigvals(A)) < 1).all() if discrete \
            else (np.linalg.eigvals(A).real < 0).all()
        if not stable:
            return None
        P = linalg.solve_discrete_lyapunov(A.T, np.eye(len(A))) if discrete \
            else linalg.solve_continuous_lyapunov(A.T, -np.eye(len(A)))
    except (np.linalg.LinAlgError, ValueError):
        return None
    P = (P + P.T) / 2
    eigenvalues = np.linalg.eigvalsh(P)
    if eigenvalues[0] <= 0 or eigenvalues[-1] / eigenvalues[0] > MAX_CONDITION:
        return None
    return P / eigenvalues[-1], K


def seed(plan, network: Network | None, controller: Network | None) -> bool:
    """Set the V network to the quadratic form and the controller network to -K x,
    where the property is stable-type and the networks can hold them exactly. Whether
    it did."""
    if plan.spec.property.form not in STABLE_FORMS or network is None \
            or not _holds_a_quadratic(network, len(plan.states)):
        return False
    if controller is not None and not _is_linear(controller, len(plan.controller.inputs)):
        return False
    found = local_certificate(plan.spec, controller is not None)
    if found is None:
        return False
    P, K = found
    _set_quadratic(network, P)
    if controller is not None:
        _set_linear(controller, -K)
    return True


def _holds_a_quadratic(network: Network, n: int) -> bool:
    return (network.zero_at_origin and len(network.linears) == 1
            and network.activations[0].name == "square"
            and network.linears[0].out_features >= n and network.divisors is None)


def _is_linear(network: Network, outputs: int) -> bool:
    return (network.zero_at_origin and network.divisors is None
            and all(a.name == "linear" for a in network.activations)
            and len(network.linears) == 1 and network.linears[0].out_features >= outputs)


def _set_quadratic(network: Network, P: np.ndarray) -> None:
    """First layer: the rows of L^T (P = L L^T), then zero rows' worth of output, so
    V(x) = |L^T x|^2 = x^T P x exactly; the spare units start with output weight 0."""
    factor = np.linalg.cholesky(P).T
    n = len(P)
    with torch.no_grad():
        weight, output = network.linears[0].weight, network.output.weight
        weight[:n] = torch.as_tensor(factor, dtype=torch.float64)
        output.zero_()
        output[0, :n] = 1.0


def _set_linear(network: Network, gain: np.ndarray) -> None:
    """k(x) = gain x: the hidden layer holds the gain, the output passes it through."""
    m = gain.shape[0]
    with torch.no_grad():
        hidden, output = network.linears[0].weight, network.output.weight
        hidden.zero_()
        hidden[:m] = torch.as_tensor(gain, dtype=torch.float64)
        output.zero_()
        output[:, :m] = torch.eye(m, dtype=torch.float64)
