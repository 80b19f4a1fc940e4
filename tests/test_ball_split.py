"""A query that leaves out a ball round the origin, refuted inside a larger ball by a
sum-of-squares refutation and beyond it by bisection (solvers/ball_split.py)."""
import json
import math
from fractions import Fraction as F

from hypothesis import given, settings
from hypothesis import strategies as st

import fossil_dsl
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.kernel.obligations import Obligation
from fossil_dsl.kernel.prove import SUM_OF_SQUARES, discharge
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.solvers import arb_box, atom_facts, ball_split
from fossil_dsl.solvers.atom_facts import abstracted
from fossil_dsl.solvers.sos_refutation import refute

X, Y, Z = E.Var("x"), E.Var("y"), E.Var("z")
STATES = ("x", "y", "z")
SWING = "specs/probe46/a03_three_machine_swing_roa.fsl"


def _box(*names):
    return [L.Compare(op, E.Var(n), E.Num(F(sign))) for n in names
            for op, sign in (("<=", 1), (">=", -1))]


def _sin_facts_on_ball(radius: F):
    """The facts for sin(x - y) in a query that keeps (x, y) in the ball |.| <= radius."""
    ball = L.Compare("<=", E.add(E.power(X, E.Num(2)), E.power(Y, E.Num(2))),
                     E.Num(radius ** 2))
    query = L.conjunction(ball, L.Compare(">", E.apply("sin", E.add(X, E.neg(Y))), E.Num(5)))
    polynomial, names = abstracted(query, ["x", "y"])
    return list(polynomial.args[2:]), names[2]  # after the ball and sin(x - y) > 5


def _holds(fact: L.Compare, env: dict) -> bool:
    difference = E.add(fact.left, E.neg(fact.right))
    value = P.polynomial(difference, list(env))
    total = sum(c * math.prod(float(env[n]) ** k for n, k in zip(env, m))
                for m, c in value.items())
    return total <= 1e-12 if fact.relation in ("<", "<=") else total >= -1e-12


@settings(max_examples=200, deadline=None)
@given(angle=st.floats(0, 2 * math.pi), share=st.floats(0, 1))
def test_the_facts_on_a_ball_hold_at_its_points(angle, share):
    facts, atom = _sin_facts_on_ball(F(1, 2))
    x, y = 0.5 * share * math.cos(angle), 0.5 * share * math.sin(angle)
    env = {"x": x, "y": y, atom: math.sin(x - y)}
    assert all(_holds(f, env) for f in facts)


def test_a_linear_argument_on_a_ball_gets_the_ball_s_reach():
    # x - y reaches sqrt(2)/2 on the ball of radius 1/2, not the 1 of its box: the fact
    # sin(a) >= k a for a >= 0 then has k = sin(0.71)/0.71 = 0.92, not sin(1)/1 = 0.84
    facts, atom = _sin_facts_on_ball(F(1, 2))
    a = 0.7
    env = {"x": a / 2, "y": -a / 2, atom: 0.88 * a}
    assert not all(_holds(f, env) for f in facts)


def _outside_origin(query, radius=F(1, 100)):
    norm = E.squared_norm(STATES)
    return L.conjunction(query, L.Compare(">", norm, E.Num(radius ** 2)), *_box(*STATES))


def test_a_query_that_holds_beyond_the_ball_is_not_proved():
    # sin(x)^2 + y^2 + z^2 >= 1/4 holds nowhere near the origin, but at (0, 0.9, 0)
    grows = E.add(E.power(E.apply("sin", X), E.Num(2)), E.power(Y, E.Num(2)),
                  E.power(Z, E.Num(2)))
    query = _outside_origin(L.Compare(">=", grows, E.Num(F(1, 4))))
    assert ball_split.excluded_radius(query, STATES) is not None
    inner = ball_split.refuted_inside(query, STATES, ball_split.outer_radius(query, STATES),
                                      float("inf"))
    assert inner is not None and inner.radius < F(1, 2)  # the split is tried...
    obligation = Obligation("condition:decrease", "a false condition", query)
    proof = discharge(obligation, STATES, 20)
    assert not proof.proved and proof.evidence is None  # ...and does not prove it
    assert refute(query, STATES, float("inf")) is None


def test_the_swing_system_s_decrease_is_refuted_whole_on_its_sublevel_set():
    # since session 58 the sublevel set V <= beta narrows the ranges of the sines
    # (arb_box.quadratic_bounds): no split is needed
    result = fossil_dsl.synthesise(fossil_dsl.load(SWING), seed=0, timeout=120)
    assert result.certified, result.reason
    by_name = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert by_name["condition:decrease"] == SUM_OF_SQUARES


def test_the_swing_system_is_certified_by_a_split_and_rechecked(tmp_path, monkeypatch):
    # the ranges from the box alone (as before session 58, and without session 63's
    # ranges of linear arguments on the sublevel set): only a split proves it
    monkeypatch.setattr(arb_box, "quadratic_bounds", lambda polynomial, names: [])
    monkeypatch.setattr(atom_facts, "quadratic_ellipsoids", lambda formula, names: [])
    result = fossil_dsl.synthesise(fossil_dsl.load(SWING), seed=0, timeout=120)
    assert result.certified, result.reason
    by_name = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert "within |x| <=" in by_name["condition:decrease"]
    result.save(tmp_path)
    exported = tmp_path / "obligations" / "condition-decrease.split.json"
    checks = {c.condition: c for c in recheck(tmp_path, timeout=30)}
    assert all(c.reproved for c in checks.values()), [c for c in checks.values()
                                                      if not c.reproved]
    assert ".split.json" in checks["condition-decrease"].solver
    # the refutation is for its own ball: with another radius it proves nothing
    data = json.loads(exported.read_text())
    data["radius"] = str(F(data["radius"]) * 2)
    exported.write_text(json.dumps(data))
    checks = {c.condition: c for c in recheck(tmp_path, timeout=30)}
    assert not checks["condition-decrease"].reproved


def test_a_quadratic_is_compacted_and_a_quartic_is_not():
    # a network's sum of squared linear forms, as a quadratic network's formula is
    forms = [E.add(*(E.mul(E.Num(F(k + i, 3)), v) for i, v in enumerate((X, Y, Z))))
             for k in range(4)]
    squares = E.add(*(E.power(form, E.Num(2)) for form in forms))
    compact = P.compact(squares, STATES)
    assert P.polynomial(compact, STATES) == P.polynomial(squares, STATES)
    assert compact != squares
    quartic = E.power(squares, E.Num(2))
    assert P.compact(quartic, STATES) is quartic
    assert P.compact(E.apply("tanh", X), STATES) == E.apply("tanh", X)
