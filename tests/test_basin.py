"""A Lyapunov function shaped to the simulated basin (engine/basin.py), the first attempt
of a `region: largest` run: a candidate like any other, right at the origin by
construction, repeatable from the seed, and never trusted."""
from __future__ import annotations

from dataclasses import replace
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import fossil_dsl
from fossil_dsl.engine import basin
from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.logic import Compare
from fossil_dsl.kernel.obligations import Obligation
from fossil_dsl.kernel.prove import discharge
from fossil_dsl.plan.compile import compile_spec

SPEC = Path(__file__).resolve().parent.parent / "specs" / "roa_largest.fsl"
JACOBIAN = np.array([[0.0, -1.0], [1.0, -1.0]])  # of the reversed Van der Pol field at 0


@pytest.fixture
def small(monkeypatch):
    """Fewer samples and one degree: the same program, quicker."""
    for name, value in (("SAMPLES", 1500), ("NEAR_ORIGIN", 400), ("BOUNDARY_SAMPLES", 400),
                        ("CHECK_SAMPLES", 6000), ("DEGREES", (6,)), ("ROUNDS", 6)):
        monkeypatch.setattr(basin, name, value)


def test_the_shaped_function_is_a_lyapunov_function_near_the_origin(small):
    plan = compile_spec(fossil_dsl.load(SPEC))
    assert basin.applies(plan)
    found = basin.shaped_lyapunov(plan, deadline=float("inf"))
    assert found is not None and found.degree == 6
    V = P.polynomial(found.formula, plan.states)
    assert all(2 <= sum(m) <= 6 for m in V)  # V(0) = 0 and no linear part
    Q = np.array([[float(V.get((2, 0), 0)), float(V.get((1, 1), 0)) / 2],
                  [float(V.get((1, 1), 0)) / 2, float(V.get((0, 2), 0))]])
    assert np.linalg.eigvalsh(Q).min() > 0
    assert np.linalg.eigvalsh(JACOBIAN.T @ Q + Q @ JACOBIAN).max() < 0
    # level 1 reaches well beyond a quadratic's region (x = (1.5, 0) converges)
    at = np.asarray(evaluate(found.formula, state_env(plan.states, np.array([[1.5, 0.0]]))))
    assert float(at.reshape(-1)[0]) < 1
    assert found.coverage > 0.8 and "shaped to the simulated basin" in found.describe()
    again = basin.shaped_lyapunov(plan, deadline=float("inf"))
    assert again.formula == found.formula  # repeatable: the seed fixes every sample


def test_a_shaped_function_is_granted_only_levels_where_it_decreases(monkeypatch):
    """Whatever the attempt claims about its V (here the linearisation's quadratic, which
    stops decreasing near level 1.28), every level the kernel grants keeps dV/dt < 0 on
    Ω: checked on a dense grid."""
    quadratic = fossil_dsl.loads(SPEC.read_text().replace(
        "synthesis { region: largest }",
        "synthesis { candidate: 0.83*x0^2 - 0.554*x0*x1 + 0.553*x1^2 }")).synthesis.candidate
    claimed = basin.BasinFinding(quadratic, 2, 1.0, 1, 0.0)

    class Claiming:
        def __init__(self, plan):
            pass

        def find(self, deadline):
            return claimed

        def refine(self, points, deadline):
            return claimed
    monkeypatch.setattr(basin, "BasinSearch", Claiming)
    result = fossil_dsl.synthesise(fossil_dsl.load(SPEC), timeout=120)
    assert result.certified and result.strategy.startswith("V of degree 2 shaped")
    beta = float(result.levels["beta"])
    axes = np.meshgrid(np.linspace(-2.5, 2.5, 400), np.linspace(-3.5, 3.5, 400))
    points = np.stack([a.reshape(-1) for a in axes], 1)
    env = state_env(("x0", "x1"), points)
    v = np.asarray(evaluate(quadratic, env), float)
    dv = (1.66 * points[:, 0] - 0.554 * points[:, 1]) * -points[:, 1] + \
        (-0.554 * points[:, 0] + 1.106 * points[:, 1]) * (
            points[:, 0] - (1 - points[:, 0] ** 2) * points[:, 1])
    inside = (v <= beta) & (np.linalg.norm(points, axis=1) > 0.05)
    assert inside.sum() > 1000 and dv[inside].max() < 0
    assert 1.0 < beta < 1.3  # the bisection went past I's level, not past the failure


def test_high_degree_polynomials_go_to_the_interval_procedure_first():
    x0, x1 = E.Var("x0"), E.Var("x1")
    power = lambda v, k: E.Pow(v, E.Num(Fraction(k)))
    high = E.add(E.add(power(x0, 8), power(x1, 8)), E.Num(Fraction(1)))
    box = [Compare("<=", E.mul(v, v), E.Num(Fraction(4))) for v in (x0, x1)]
    from fossil_dsl.ir import logic as L
    query = L.And((*box, Compare("<=", high, E.ZERO)))
    proof = discharge(Obligation("fact", "x0^8 + x1^8 + 1 > 0", query), ("x0", "x1"), 30.0)
    assert proof.proved and proof.procedure == "interval"
    low = L.And((*box, Compare("<=", E.add(E.mul(x0, x0), E.Num(Fraction(1))), E.ZERO)))
    proof = discharge(Obligation("fact", "x0^2 + 1 > 0", low), ("x0", "x1"), 30.0)
    assert proof.proved and proof.procedure == "z3"


def test_only_where_it_applies():
    text = SPEC.read_text().replace("synthesis { region: largest }", "")
    assert not basin.applies(compile_spec(fossil_dsl.loads(text)))
    plan = compile_spec(fossil_dsl.load(SPEC))
    given = replace(plan.spec, synthesis=replace(plan.spec.synthesis, candidate=E.Var("x0")))
    assert not basin.applies(replace(plan, spec=given))


EULER_VDP = """\
state x0, x1
dynamics discrete {
    next(x0) = x0 - 0.1*x1
    next(x1) = x1 + 0.1*(x0 - (1 - x0^2)*x1)
}
domain box([-2.5, -3.5], [2.5, 3.5])
prove stable
synthesis { region: largest }
"""


def test_a_map_gets_a_function_with_the_step_conditions_at_the_origin(small):
    """For x+ = f(x): V's quadratic part Q has Q - A^T Q A positive definite (A: the
    map's Jacobian at 0), and {V <= 1} reaches past a quadratic's region."""
    plan = compile_spec(fossil_dsl.loads(EULER_VDP))
    assert basin.applies(plan)
    found = basin.shaped_lyapunov(plan, deadline=float("inf"))
    assert found is not None
    V = P.polynomial(found.formula, plan.states)
    Q = np.array([[float(V.get((2, 0), 0)), float(V.get((1, 1), 0)) / 2],
                  [float(V.get((1, 1), 0)) / 2, float(V.get((0, 2), 0))]])
    A = np.eye(2) + 0.1 * JACOBIAN
    assert np.linalg.eigvalsh(Q).min() > 0
    assert np.linalg.eigvalsh(Q - A.T @ Q @ A).min() > 0
    at = np.asarray(evaluate(found.formula, state_env(plan.states, np.array([[1.5, 0.0]]))))
    assert float(at.reshape(-1)[0]) < 1 and found.coverage > 0.8
