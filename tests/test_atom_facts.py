"""Refuting transcendental queries through their polynomial form (solvers/atom_facts.py):
every fact holds where it is claimed to (checked against sympy's values at 60 digits,
independent of the Arb enclosures the facts' constants come from), the polynomial query
keeps every point of the original, a refutation proves, and what is false stays
unproved."""
import math
import time
from fractions import Fraction as F
from pathlib import Path

import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

import fossil_dsl
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.symbolic import to_sympy
from fossil_dsl.kernel.obligations import Claim
from fossil_dsl.kernel.prove import SUM_OF_SQUARES, discharge
from fossil_dsl.kernel.verdict import list_obligations
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.solvers.atom_facts import abstracted
from fossil_dsl.solvers.positivstellensatz import refutation_problem
from fossil_dsl.solvers.sos_refutation import refute

A = E.Var("a")
FUNCTIONS = ("sin", "cos", "tanh", "atan", "exp")


PRECISION = 60  # digits: a fact that holds with equality (exp's chord at its ends)
TOLERANCE = sympy.Rational(1, 10 ** 40)  # leaves a residue far below any real failure


def _at(a: F, func: str, atom: str) -> dict:
    """The values of a and of func(a), exact (sympy evaluates them to any precision)."""
    value = sympy.Rational(a.numerator, a.denominator)
    return {"a": value, atom: getattr(sympy, func)(value)}


def _not_refuted(comparison: L.Compare, env: dict) -> bool:
    """The fact is not shown false at the point (evaluated to PRECISION digits)."""
    difference = to_sympy(E.add(comparison.left, E.neg(comparison.right)))
    value = difference.subs({sympy.Symbol(k, real=True): v for k, v in env.items()})
    value = sympy.N(value, PRECISION)
    if comparison.relation in ("<", "<="):
        return value <= TOLERANCE
    return value >= -TOLERANCE


def _facts(func: str, low: F, high: F) -> tuple[list[L.Compare], str]:
    """The facts added for func(a) in a query that bounds a to [low, high]."""
    query = L.conjunction(L.Compare(">=", A, E.Num(low)), L.Compare("<=", A, E.Num(high)),
                          L.Compare(">", E.apply(func, A), E.Num(F(5))))
    polynomial, names = abstracted(query, ["a"])
    return [c for c in polynomial.args[3:]], names[1]


@settings(max_examples=300, deadline=None)
@given(func=st.sampled_from(FUNCTIONS),
       ends=st.tuples(st.fractions(-6, 6, max_denominator=1000),
                      st.fractions(-6, 6, max_denominator=1000)),
       share=st.fractions(0, 1, max_denominator=1000))
def test_every_fact_holds_at_every_point_of_its_range(func, ends, share):
    low, high = min(ends), max(ends)
    facts, atom = _facts(func, low, high)
    a = low + share * (high - low)
    env = _at(a, func, atom)
    for fact in facts:
        assert _not_refuted(fact, env), (func, low, high, a, L.formula_text(fact))


@settings(max_examples=300, deadline=None)
@given(func=st.sampled_from(("sin", "cos", "tanh")),
       low=st.fractions(-7, 7, max_denominator=1000),
       width=st.fractions(F(1, 10 ** 6), F(1, 2), max_denominator=10 ** 6),
       share=st.fractions(0, 1, max_denominator=1000))
def test_taylor_facts_hold_on_every_narrow_range(func, low, width, share):
    high = low + width
    facts, atom = _facts(func, low, high)
    # away from 0 the narrow range gets the Taylor facts, with 0 inside the sector ones
    assert any("^2" in L.formula_text(f) and atom in L.formula_text(f) for f in facts) \
        or low < 0 < high
    for a in (low, high, low + share * width):
        env = _at(a, func, atom)
        for fact in facts:
            assert _not_refuted(fact, env), (func, low, high, a, L.formula_text(fact))


@pytest.mark.parametrize("func", ["sin", "tanh"])
def test_taylor_facts_are_tight_and_fail_off_the_function(func):
    facts, atom = _facts(func, F(2, 5), F(1, 2))
    upper, lower = facts[-2:]  # (after t^2 <= 1)
    # the band the facts leave sin a (tanh a) on [0.4, 0.5] is below 4e-4 (7e-4) wide,
    # so a value 1e-3 off the true value at the middle is refuted by one of them
    for offset in (F(1, 1000), F(-1, 1000)):
        env = _at(F(9, 20), func, atom)
        env[atom] = env[atom] + sympy.Rational(offset.numerator, offset.denominator)
        assert not (_not_refuted(upper, env) and _not_refuted(lower, env))


@pytest.mark.parametrize("func", FUNCTIONS)
def test_universal_facts_hold_far_out(func):
    # no range known: only the facts that hold for every real argument
    query = L.Compare(">", E.apply(func, A), E.Num(F(5)))
    polynomial, (_, atom) = abstracted(query, ["a"])
    for a in (F(-40), F(-7, 2), F(-1, 3), F(0), F(1, 7), F(3), F(25)):
        env = _at(a, func, atom)
        for fact in polynomial.args[1:]:
            assert _not_refuted(fact, env), (func, a, L.formula_text(fact))


def test_a_nested_application_becomes_two_variables():
    query = L.Compare(">", E.apply("sin", E.apply("tanh", A)), E.Num(F(1)))
    polynomial, names = abstracted(query, ["a"])
    assert names == ("a", "@tanh0", "@sin1")
    texts = [L.formula_text(fact) for fact in polynomial.args[1:]]
    # sin's facts are about its argument, the variable that stands for tanh(a)
    assert any("@sin1" in text and "@tanh0" in text for text in texts), texts


PENDULUM = """\
state x, y
dynamics continuous {
    x' = y
    y' = -sin(x) - 0.5*y
}
domain box([-1, -1], [1, 1])
prove stable
"""


def test_sin_bounds_refute_what_holds_and_not_what_fails():
    x = E.Var("x")
    inside = [L.Compare(">=", x, E.Num(F(-1))), L.Compare("<=", x, E.Num(F(1)))]
    sine = E.apply("sin", x)
    # sin(x) > x/2 + 3/5 nowhere in [-1, 1] (sin x <= x for x >= 0, < 0 for x < 0)
    never = L.conjunction(*inside, L.Compare(">", sine, E.add(E.mul(E.Num(F(1, 2)), x),
                                                              E.Num(F(3, 5)))))
    assert refute(never, ["x"], time.monotonic() + 30) is not None
    somewhere = L.conjunction(*inside, L.Compare(">", sine, E.mul(E.Num(F(9, 10)), x)),
                              L.Compare(">", x, E.Num(F(1, 10))))
    assert refute(somewhere, ["x"], time.monotonic() + 30) is None  # x = 0.5 satisfies it


def _quadratic_claim(text: str, matrix) -> Claim:
    spec = fossil_dsl.loads(text)
    xs = [E.Var(s) for s in spec.states]
    V = E.add(*[E.mul(E.Num(F(matrix[i][j])), xs[i], xs[j])
                for i in range(len(xs)) for j in range(len(xs))])
    return Claim(spec, {"V": V}, ball_radius=F(1, 100))


def test_the_kernel_proves_a_transcendental_decrease_by_refutation_and_checks_it():
    # V from the linearisation's Lyapunov equation; its decrease has sin in it
    claim = _quadratic_claim(PENDULUM, [[F(9, 4), F(1, 2)], [F(1, 2), F(2)]])
    decrease = next(o for o in list_obligations(claim) if o.name == "condition:decrease")
    proof = discharge(decrease, claim.spec.states, 30, first=SUM_OF_SQUARES)
    assert proof.proved and proof.procedure == SUM_OF_SQUARES
    assert refutation_problem(proof.evidence, decrease.query, claim.spec.states) is None
    # the same refutation does not prove the condition for a faster-falling pendulum
    other = _quadratic_claim(PENDULUM.replace("-sin(x)", "-2*sin(x)"),
                             [[F(9, 4), F(1, 2)], [F(1, 2), F(2)]])
    changed = next(o for o in list_obligations(other) if o.name == "condition:decrease")
    assert refutation_problem(proof.evidence, changed.query, other.spec.states) is not None


def test_a_false_decrease_with_sin_is_not_proved():
    # x' = y, y' = +sin(x) - y: the upright pendulum; no V can decrease, this one does not
    claim = _quadratic_claim(PENDULUM.replace("-sin(x) - 0.5*y", "sin(x) - y"),
                             [[F(1), F(0)], [F(0), F(1)]])
    decrease = next(o for o in list_obligations(claim) if o.name == "condition:decrease")
    proof = discharge(decrease, claim.spec.states, 10, first=SUM_OF_SQUARES)
    assert not proof.proved


ELASTIC_JOINT = """\
state q1, q2, q3, q4
dynamics continuous {
    q1' = q2
    q2' = -sin(q1) - 0.4*q2 - (q1 - q3)
    q3' = q4
    q4' = (q1 - q3) - 0.4*q4
}
domain box([-1, -1, -1, -1], [1, 1, 1, 1])
prove stable
"""


def _decrease_refuted(spec, timeout: float):
    """The run's result, asserted certified with its decrease proved by a refutation."""
    result = fossil_dsl.synthesise(spec, seed=0, timeout=timeout)
    assert result.certified, result.reason
    by_name = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert by_name["condition:decrease"] == SUM_OF_SQUARES
    return result


def test_a_four_state_pendulum_is_certified_by_refutation_and_rechecked(tmp_path):
    # bisection left this decrease unproved for 118 s; its polynomial form is refuted
    # at once
    result = _decrease_refuted(fossil_dsl.loads(ELASTIC_JOINT), timeout=120)
    result.save(tmp_path)
    assert (tmp_path / "obligations" / "condition-decrease.sos.json").exists()
    checks = {c.condition: c for c in recheck(tmp_path, timeout=10)}
    assert checks["condition-decrease"].reproved
    assert checks["condition-decrease"].solver.endswith(".sos.json")


RING = """\
state t1, w1, t2, w2, t3, w3
dynamics continuous {
    t1' = w1
    w1' = -0.4*w1 - sin(t1) - 0.3*sin(t1 - t2) - 0.3*sin(t1 - t3)
    t2' = w2
    w2' = -0.4*w2 - sin(t2) - 0.3*sin(t2 - t1) - 0.3*sin(t2 - t3)
    t3' = w3
    w3' = -0.4*w3 - sin(t3) - 0.3*sin(t3 - t1) - 0.3*sin(t3 - t2)
}
domain box([-1.5, -1.5, -1.5, -1.5, -1.5, -1.5], [1.5, 1.5, 1.5, 1.5, 1.5, 1.5])
set init = ball([0, 0, 0, 0, 0, 0], 0.5)
prove from init: stable
"""


def test_a_sublevel_set_of_a_quadratic_v_narrows_the_ranges_of_the_sines(tmp_path):
    # probe58/ab02: the box alone gives |t1 - t2| <= 3, where sin(a)/a falls to 0.05 and
    # the sector facts say nothing; V <= beta gives |t_i| <= 0.55 (arb_box.py), and the
    # decrease that 60 000 boxes of bisection left unproved in 120 s is refuted at once
    result = _decrease_refuted(fossil_dsl.loads(RING), timeout=60)
    result.save(tmp_path)
    checks = {c.condition: c for c in recheck(tmp_path, timeout=10)}
    assert checks["condition-decrease"].reproved


def test_a_negated_conjunct_gives_no_range():
    # "outside the goal ball" must not be read as the ball (arb_box.py, session 38):
    # sin's range fact for |a| <= 0.2 is false at a = 0.9
    query = L.conjunction(L.Compare(">=", A, E.Num(F(-1))), L.Compare("<=", A, E.Num(F(1))),
                          L.negation(L.Compare("<=", E.power(A, E.Num(F(2))), E.Num(F(1, 25)))),
                          L.Compare(">", E.apply("sin", A), E.Num(F(5))))
    polynomial, (_, atom) = abstracted(query, ["a"])
    env = _at(F(9, 10), "sin", atom)
    for fact in polynomial.args[4:]:
        assert _not_refuted(fact, env), L.formula_text(fact)


def test_the_first_quadratic_v_gets_a_program_large_enough_for_a_quadrotor():
    # probe44/y12 (6 states, 2 inputs, sin and cos): s0 of its decrease's refutation has
    # 1035 Gram entries, over the loop's limit of 1000; the first quadratic V's
    # refutations may take 3000 (engine/attempts.py), and it is certified by them (in
    # the kernel, where the refutation's share runs out on a loaded machine, the
    # interval verifier's Taylor forms prove the decrease since session 68)
    path = Path(__file__).resolve().parent.parent / "specs/probe44/y12_planar_quadrotor_roa_ctrl.fsl"
    result = fossil_dsl.synthesise(fossil_dsl.load(path), seed=0, timeout=60)
    assert result.certified, result.reason
    assert result.strategy.startswith("the linearisation's quadratic V")
    by_name = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert by_name["condition:decrease"] in (SUM_OF_SQUARES, "taylor")


def _sublevel_query(argument: E.Expr):
    """x^2 + x y + y^2 - 1 <= 0 (cross term: no axis-parallel ellipsoid), tanh(argument)
    above 2 (so the query is about the argument's range only)."""
    x, y = E.Var("x"), E.Var("y")
    quadratic = E.add(E.power(x, E.Num(F(2))), E.mul(x, y), E.power(y, E.Num(F(2))),
                      E.Num(F(-1)))
    return L.conjunction(L.Compare("<=", quadratic, E.Num(F(0))),
                         L.Compare(">", E.apply("tanh", argument), E.Num(F(2))))


def test_a_linear_argument_gets_its_range_on_a_quadratic_sublevel_set():
    """probe58/ab04: tanh(-K x) on a V <= 0 with cross terms. On x^2 + xy + y^2 <= 1,
    x + y reaches 2/sqrt(3) = 1.155 (at x = y); the per-variable box (|x|, |y| <=
    2/sqrt(3)) alone gives 2.31. The range is tight and holds every point of the set."""
    from fossil_dsl.solvers.atom_facts import _Ranges
    x, y = E.Var("x"), E.Var("y")
    argument = E.add(x, y, E.Num(F(1, 2)))
    low, high = _Ranges(_sublevel_query(argument)).of(argument)
    assert 0.5 + 2 / 3 ** 0.5 <= high <= 0.5 + 2 / 3 ** 0.5 + 1e-6
    assert 0.5 - 2 / 3 ** 0.5 - 1e-6 <= low <= 0.5 - 2 / 3 ** 0.5
    angles = [k * 0.01 for k in range(629)]
    for a in angles:  # the boundary: (u, v) on the unit circle mapped onto the ellipse
        u, v = math.cos(a), math.sin(a)
        px = (u / 1.5 ** 0.5 + v / 0.5 ** 0.5) / 2 ** 0.5
        py = (u / 1.5 ** 0.5 - v / 0.5 ** 0.5) / 2 ** 0.5
        assert abs(px * px + px * py + py * py - 1) < 1e-9
        assert low <= px + py + 0.5 <= high


def test_a_sublevel_set_that_is_not_an_ellipsoid_gives_no_quadratic_range():
    from fossil_dsl.solvers.atom_facts import _Ranges
    x, y = E.Var("x"), E.Var("y")
    saddle = E.add(E.power(x, E.Num(F(2))), E.mul(E.Num(F(3)), x, y),
                   E.power(y, E.Num(F(2))), E.Num(F(-1)))  # indefinite: unbounded
    query = L.conjunction(L.Compare("<=", saddle, E.Num(F(0))),
                          L.Compare(">", E.apply("tanh", E.add(x, y)), E.Num(F(2))))
    assert _Ranges(query).of(E.add(x, y)) is None
