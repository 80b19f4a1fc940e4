"""A stability-type property refuted before anything is searched for.

Where the field is continuously differentiable near the origin and its linearisation
there has an eigenvalue with positive real part (for a map, of modulus above 1), the
origin is unstable: Lyapunov's indirect method (its instability half; for maps the same
theorem for fixed points). Then `stable`, `from I: stable` and `stable and always not U`
are false, and no certificate may be reported for them, not even the ε-stability that a
ball left out round the origin would give (docs/certificates.md: an unstable origin is
never certified). Without this, such a run searched for its whole timeout (a map with
eigenvalue 1.05: 116 s) and said only that it gave up.

The eigenvalues are computed in floating point, so an eigenvalue within MARGIN of the
boundary refutes nothing; nor does a field that is not differentiable at the origin
(abs or sqrt of something that is 0 there, a power below 1), nor a system with inputs (a
controller could move the eigenvalue). Nothing here can certify anything.
"""
from __future__ import annotations

import math

import numpy as np

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.enclosure import enclose
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.engine.linear import jacobians
from fossil_dsl.engine.loop import CegisOutcome, ExactCandidate
from fossil_dsl.plan.certificates.roa import ROA_FORMS
from fossil_dsl.plan.compile import Plan

FORMS = ("stability", "stable while avoid") + ROA_FORMS  # each claims the origin attracts
MARGIN = 1e-6  # relative to the Jacobian's size: an eigenvalue this close decides nothing
NOT_SMOOTH_AT_ZERO = ("abs", "sqrt")  # not differentiable where their argument is 0


def refutation(plan: Plan) -> str | None:
    """Why the property is false (the eigenvalue that makes the origin unstable), or None
    where this argument does not apply or decides nothing."""
    found = _linearisation(plan)
    if found is None:
        return None
    eigenvalues, tolerance = found
    if plan.spec.time is TimeDomain.DISCRETE:
        worst = eigenvalues[np.argmax(np.abs(eigenvalues))]
        if abs(worst) > 1 + tolerance:
            return (f"the property is false: the origin is unstable (the map's "
                    f"linearisation there has the eigenvalue {_text(worst)} of modulus "
                    f"{abs(worst):.4g} > 1)")
        return None
    worst = eigenvalues[np.argmax(eigenvalues.real)]
    if worst.real > tolerance:
        return (f"the property is false: the origin is unstable (the linearisation there "
                f"has the eigenvalue {_text(worst)} with positive real part)")
    return None


def marginal_note(plan: Plan) -> str | None:
    """Where a stability-type run was not certified and the linearisation at the origin
    has eigenvalues on the boundary (real part 0; modulus 1 for a map) and none beyond:
    why quadratic functions cannot serve (they decrease only as fast as the linear part,
    which is not at all along those eigenvalues), or None."""
    found = _linearisation(plan)
    if found is None:
        return None
    eigenvalues, tolerance = found
    discrete = plan.spec.time is TimeDomain.DISCRETE
    edge = np.abs(np.abs(eigenvalues) - 1) if discrete else np.abs(eigenvalues.real)
    on_edge = [e for e, d in zip(eigenvalues, edge) if d <= tolerance]
    if not on_edge:
        return None
    where = "on the unit circle" if discrete else "on the imaginary axis"
    return (f"the linearisation at the origin has eigenvalues {where} "
            f"({', '.join(_text(e) for e in on_edge)}): no quadratic V decreases strictly "
            f"near the origin, and a V of higher degree must be proved there without the "
            f"linear part's help")


def _linearisation(plan: Plan):
    """(the eigenvalues of the Jacobian at the origin, the tolerance that decides nothing
    within it) for a stability-type property of a system without inputs whose field is
    C^1 near the origin; else None."""
    spec, states = plan.spec, list(plan.states)
    if spec.inputs or plan.certificate.form not in FORMS or \
            not all(_smooth_at_origin(f, states) for f in spec.dynamics):
        return None
    found = jacobians(spec)
    if found is None:
        return None
    jacobian = found[0]
    return np.linalg.eigvals(jacobian), MARGIN * max(1.0, float(np.abs(jacobian).max()))


def refuted_outcome(plan: Plan, reason: str) -> CegisOutcome:
    """Not certified, for the reason given, with no function found (none was searched for)."""
    nothing = ExactCandidate({}, {}, {}, {}, plan.options.digits)
    return CegisOutcome(False, reason, nothing, {}, (), (), 0.0, 0.0, {},
                        strategy="the linearisation at the origin")


def _smooth_at_origin(f: E.Expr, states) -> bool:
    """Every function application and power in f is continuously differentiable near
    the origin: abs and sqrt only of arguments away from 0 there, powers with a
    natural exponent or of a base away from 0."""
    origin = {s: E.ZERO for s in states}
    for node in E.walk(f):
        if isinstance(node, E.Apply) and node.func in NOT_SMOOTH_AT_ZERO:
            argument = node.arg
        elif isinstance(node, E.Pow) and not _natural(node.exponent):
            argument = node.base
        else:
            continue
        low, high = _enclosure(traversal.substitute(argument, origin))
        if not (low > 0 or high < 0):
            return False
    return True


def _natural(exponent: E.Expr) -> bool:
    return isinstance(exponent, E.Num) and exponent.value.denominator == 1 and \
        exponent.value >= 1


def _enclosure(closed: E.Expr) -> tuple[float, float]:
    try:
        return enclose(closed)
    except (E.ExprError, ValueError, ZeroDivisionError, OverflowError):
        return math.nan, math.nan


def _text(eigenvalue: complex) -> str:
    if abs(eigenvalue.imag) < 1e-12:
        return f"{eigenvalue.real:.4g}"
    return f"{eigenvalue.real:.4g} {'+' if eigenvalue.imag > 0 else '-'} " \
           f"{abs(eigenvalue.imag):.4g}i"
