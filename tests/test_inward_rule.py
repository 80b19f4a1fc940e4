"""The kernel's variant for a region of attraction that reaches the boundary of D
(kernel/inward_rules.py): where I touches ∂D no sublevel set holding I has V > β on
∂D, and the field pointing strictly into D where Ω meets ∂D keeps Ω instead."""
from __future__ import annotations

import json
import time
from fractions import Fraction

import fossil_dsl
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.kernel import Claim, judge, list_obligations
from fossil_dsl.kernel.inward_rules import INWARD, literals
from fossil_dsl.kernel.prove import Outcome, discharge
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.plan.certificates.roa import initial_reaches_boundary
from fossil_dsl.plan.compile import compile_spec

# specs/probe69/as10 (an AdEx neuron below threshold): the ball I touches w = +-0.5
NEURON = """
spec neuron
state v, w
dynamics continuous {
    v' = -v + 0.1*(exp(2*v) - 1) - w
    w' = 0.2*(0.5*v - w)
}
domain box([-1, -0.5], [1, 0.5])
set init = ball([0, 0], 0.5)
prove from init: stable
"""


def quadratic(a, b, c) -> E.Expr:
    """a v^2 + b v w + c w^2"""
    v, w = E.Var("v"), E.Var("w")
    return E.add(E.mul(E.Num(Fraction(a)), E.power(v, E.Num(2))), E.mul(E.Num(Fraction(b)), v, w),
                 E.mul(E.Num(Fraction(c)), E.power(w, E.Num(2))))


def neuron_claim(text=NEURON, beta="0.927") -> Claim:
    # the Lyapunov equation's P for the linearisation, rounded; β just over V on I
    V = quadratic("0.5962", "-0.4616", "3.654")
    return Claim(fossil_dsl.loads(text), {"V": V}, {}, {"beta": Fraction(beta)},
                 Fraction(1, 100))


def test_a_region_reaching_the_boundary_is_proved_by_the_variant():
    verdict = judge(neuron_claim())
    assert verdict.certified, verdict.reason
    assert verdict.variant == INWARD
    inward = [p for p in verdict.proofs if p.obligation.name.startswith("condition:inward")]
    assert len(inward) == 4  # the box's four faces
    assert "points strictly into D" in verdict.guarantee


def test_the_main_rule_fails_where_i_touches_the_boundary():
    names = [o.name for o in list_obligations(neuron_claim())]
    assert "condition:boundary" in names and not any("inward" in n for n in names)
    verdict = judge(neuron_claim())
    assert "condition:boundary" not in [p.obligation.name for p in verdict.proofs]


def test_a_field_leaving_through_a_face_is_refused():
    # the face w = 0.5 moved to v's side: at (0.9, 0.5) w' = 0.2 (0.45 - 0.5) < 0 still,
    # but with w' = 0.2 (2 v - w) the field leaves D through w = 0.5 where v > 0.25
    leaving = NEURON.replace("w' = 0.2*(0.5*v - w)", "w' = 0.2*(2*v - w)")
    claim = neuron_claim(leaving)
    assert not judge(claim).certified
    faces = [o for o in list_obligations(claim, variant=INWARD)
             if o.name.startswith("condition:inward")]
    outcomes = {o.text: discharge(o, claim.spec.states, 10).outcome for o in faces}
    assert outcomes["the field points into D where w = 0.5 in Ω"] is Outcome.FAILS
    assert outcomes["the field points into D where -1 = v in Ω"] is Outcome.PROVED


def test_literals_move_negations_onto_comparisons():
    x, one = E.Var("x"), E.Num(1)
    hole = L.negation(L.conjunction(L.Compare("<=", x, one), L.Compare("<", E.neg(x), one)))
    found = {(c.relation, c.left, c.right) for c in literals(hole)}
    # outside the hole: x > 1 or -x >= 1
    assert found == {(">", x, one), (">=", E.neg(x), one)}


def test_the_engine_learns_the_variant_where_i_touches_d():
    spec = fossil_dsl.loads(NEURON)
    assert initial_reaches_boundary(spec)
    plan = compile_spec(spec)
    names = [c.name for c in plan.conditions]
    assert "boundary" not in names and sum(n.startswith("inward:") for n in names) == 4
    assert plan.levels[0].above is None  # β is just over V on I
    inside = fossil_dsl.loads(NEURON.replace("ball([0, 0], 0.5)", "ball([0, 0], 0.4)"))
    assert not initial_reaches_boundary(inside)
    assert "boundary" in [c.name for c in compile_spec(inside).conditions]


def test_the_neuron_is_certified_and_rechecked(tmp_path):
    result = fossil_dsl.synthesise(fossil_dsl.loads(NEURON), seed=0, timeout=60)
    assert result.certified, result.reason
    assert result.kernel.variant == INWARD
    assert "quadratic V" in result.strategy  # the linearisation's, Ω reaching ∂D
    result.save(tmp_path)
    data = json.loads((tmp_path / "result.json").read_text())
    assert data["kernel"]["variant"] == INWARD
    checks = recheck(tmp_path, timeout=30)
    assert all(c.reproved for c in checks), [c for c in checks if not c.reproved]


def test_a_quadratic_region_reaches_the_boundary_only_where_none_fits_inside():
    from fossil_dsl.engine import quadratic_roa
    found = list(quadratic_roa.candidates(compile_spec(fossil_dsl.loads(NEURON)),
                                          time.monotonic() + 20))
    assert found and all(f.reaches_boundary for f in found)
    inside = NEURON.replace("box([-1, -0.5], [1, 0.5])", "box([-1, -1], [1, 1])")
    found = list(quadratic_roa.candidates(compile_spec(fossil_dsl.loads(inside)),
                                          time.monotonic() + 20))
    assert found and not any(f.reaches_boundary for f in found)


def test_an_equilibrium_on_the_face_is_not_certified():
    spec = fossil_dsl.load("specs/false/f98_equilibrium_on_the_domain_face_roa.fsl")
    assert not fossil_dsl.synthesise(spec, seed=0, timeout=30).certified
