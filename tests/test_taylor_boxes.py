"""The batched Taylor-form search (solvers/taylor_boxes.py) and the interval arrays it
rests on (solvers/vector_intervals.py, vector_elementary.py): every enclosure holds the
true values (mpmath at 50 digits), a query with a solution is never refuted, and the
acrobot's decrease condition, out of reach of codac's bisection, is refuted."""
from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers import vector_elementary as F
from fossil_dsl.solvers import vector_intervals as V
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.taylor_boxes import Search, Side, _Boxes, refute

mpmath.mp.dps = 50

REFERENCE = {"sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan, "exp": mpmath.exp,
             "log": mpmath.log, "sqrt": mpmath.sqrt, "tanh": mpmath.tanh,
             "atan": mpmath.atan, "abs": abs}
DOMAIN = {"log": lambda x: x > 0, "sqrt": lambda x: x >= 0,
          "tan": lambda x: abs(mpmath.cos(x)) > 1e-12}
finite = st.floats(min_value=-800, max_value=800, allow_nan=False)
tiny_or_huge = st.floats(min_value=-1e300, max_value=1e300, allow_nan=False)


def _holds(name, low, high, x) -> bool:
    value = REFERENCE[name](mpmath.mpf(x))
    low, high = float(low), float(high)
    if np.isnan(low) or np.isnan(high):
        return True  # the whole line
    return mpmath.mpf(low) <= value <= mpmath.mpf(high)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.one_of(finite, tiny_or_huge), min_size=1, max_size=20))
def test_every_function_encloses_its_value_at_points(points):
    xs = np.array(points)
    for name, function in F.FUNCTIONS.items():
        low, high = function((xs, xs))
        for x, lo, hi in zip(points, low, high):
            if DOMAIN.get(name, lambda _: True)(x):
                assert _holds(name, lo, hi, x), (name, x, lo, hi)


@settings(max_examples=150, deadline=None)
@given(finite, st.floats(min_value=0, max_value=10), st.lists(
    st.floats(min_value=0, max_value=1), min_size=1, max_size=8))
# found by this test in session 71: exp's lower bound above 709 was the largest double,
# above exp(709.5) = 1.35e308
@example(709.5, 0.0, [0.0])
@example(709.0, 0.7, [0.5, 1.0])
def test_every_function_encloses_its_range_on_an_interval(start, width, fractions):
    low, high = np.array([start]), np.array([start + width])
    for name, function in F.FUNCTIONS.items():
        lo, hi = function((low, high))
        for fraction in fractions:
            x = start + fraction * width
            if all(DOMAIN.get(name, lambda _: True)(p) for p in (start, x, start + width)):
                assert _holds(name, lo[0], hi[0], x), (name, start, width, x)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.fractions(min_value=-100, max_value=100, max_denominator=1000),
                min_size=4, max_size=4))
def test_arithmetic_is_outward(values):
    a, b, c, d = values
    pairs = [V.constant(v) for v in values]
    exact = {"add": a + b, "mul": a * b, "sub": a - c, "square": d * d}
    computed = {"add": V.add(pairs[0], pairs[1]), "mul": V.mul(pairs[0], pairs[1]),
                "sub": V.sub(pairs[0], pairs[2]), "square": V.square(pairs[3])}
    if b != 0:
        exact["div"] = a / b
        computed["div"] = V.div(pairs[0], pairs[1])
    for key, value in exact.items():
        low, high = computed[key]
        assert Fraction(float(low)) <= value <= Fraction(float(high)), key


X, Y = E.Var("x"), E.Var("y")
SMOOTH = [E.add(E.mul(X, E.apply("sin", Y)), E.neg(E.mul(E.Num(Fraction(3, 10)), Y, Y))),
          E.div(E.apply("tanh", X), E.add(E.ONE, E.power(Y, E.Num(Fraction(2))))),
          E.mul(E.apply("exp", E.neg(X)), E.apply("cos", E.add(X, Y))),
          E.add(E.apply("atan", E.mul(X, Y)), E.apply("log", E.add(E.Num(Fraction(3)), X)))]


@pytest.mark.parametrize("expr", SMOOTH, ids=range(len(SMOOTH)))
@settings(max_examples=40, deadline=None)
@given(st.floats(min_value=-2, max_value=2), st.floats(min_value=-2, max_value=2),
       st.floats(min_value=1e-6, max_value=1.5), st.floats(min_value=1e-6, max_value=1.5))
def test_the_taylor_form_holds_every_value_on_the_box(expr, x, y, wx, wy):
    low, high = np.array([[x, y]]), np.array([[x + wx, y + wy]])
    boxes = _Boxes(("x", "y"), low, high)
    form = boxes.taylor(Side(expr, ">=", ("x", "y")))
    for fx in np.linspace(0, 1, 4):
        for fy in np.linspace(0, 1, 4):
            point = {X: mpmath.mpf(x + fx * wx), Y: mpmath.mpf(y + fy * wy)}
            value = _exact(expr, point)
            assert mpmath.mpf(float(form[0][0])) <= value <= mpmath.mpf(float(form[1][0]))


def _exact(expr, point):
    if expr in point:
        return point[expr]
    if isinstance(expr, E.Num):
        return mpmath.mpf(expr.value.numerator) / expr.value.denominator
    if isinstance(expr, E.Neg):
        return -_exact(expr.operand, point)
    if isinstance(expr, E.Add):
        return sum(_exact(t, point) for t in expr.terms)
    if isinstance(expr, E.Mul):
        return mpmath.fprod(_exact(f, point) for f in expr.factors)
    if isinstance(expr, E.Div):
        return _exact(expr.numerator, point) / _exact(expr.denominator, point)
    if isinstance(expr, E.Pow):
        return _exact(expr.base, point) ** int(expr.exponent.value)
    return REFERENCE[expr.func](_exact(expr.arg, point))


def _box(names, low, high):
    return [L.Compare(">=", E.Var(n), E.Num(Fraction(low))) for n in names] + \
        [L.Compare("<=", E.Var(n), E.Num(Fraction(high))) for n in names]


def test_a_query_without_solutions_is_refuted():
    # sin x < x for x > 0
    query = L.conjunction(*_box("x", Fraction(1, 10), 1),
                          L.Compare(">=", E.apply("sin", X), X))
    assert refute(query, ["x"], 10).status is Status.UNSAT


@pytest.mark.parametrize("relation", [">=", ">", "="])
def test_a_query_with_solutions_is_never_refuted(relation):
    # sin x >= x holds for x <= 0, sin x > x for x < 0; sin x = x at 0 only
    query = L.conjunction(*_box("x", -1, 1), L.Compare(relation, E.apply("sin", X), X))
    answer = refute(query, ["x"], 5)
    assert answer.status is (Status.UNKNOWN if relation == "=" else Status.SAT)
    if answer.status is Status.SAT:  # a true solution
        x = mpmath.mpf(answer.model["x"].numerator) / answer.model["x"].denominator
        assert mpmath.sin(x) > x


def test_undefined_values_refute_nothing():
    # sqrt(x) <= -1 holds nowhere sqrt is defined; x < 0 is left unrefuted
    query = L.conjunction(*_box("x", -1, 1),
                          L.Compare("<=", E.apply("sqrt", X), E.Num(Fraction(-1))))
    assert refute(query, ["x"], 3).status is Status.UNKNOWN
    inside = L.conjunction(*_box("x", 0, 1),
                           L.Compare("<=", E.apply("sqrt", X), E.Num(Fraction(-1))))
    assert refute(inside, ["x"], 3).status is Status.UNSAT


def test_unit_curvature_coordinates_give_an_equivalent_query():
    # x^2 + 100 y^2 + 19 x y <= 1 and x + y >= 1/5: curvatures 1 to 100 (transformed)
    quadratic = E.add(E.mul(X, X), E.mul(E.Num(Fraction(100)), Y, Y),
                      E.mul(E.Num(Fraction(19)), X, Y))
    query = L.conjunction(*_box("xy", -2, 2), L.Compare("<=", quadratic, E.ONE),
                          L.Compare(">=", E.add(X, Y), E.Num(Fraction(1, 5))))
    search = Search(query, ["x", "y"])
    assert search.transform is not None
    T = np.array(search.transform, dtype=float)
    curvature = T.T @ np.array([[2.0, 19.0], [19.0, 200.0]]) @ T
    assert np.allclose(np.abs(np.diag(curvature)), 1, atol=1e-3)
    assert np.allclose(curvature - np.diag(np.diag(curvature)), 0, atol=1e-3)
    answer = search.run(10)
    assert answer.status is Status.SAT  # a point of the original query, exactly
    point = {"x": answer.model["x"], "y": answer.model["y"]}
    assert point["x"] + point["y"] >= Fraction(1, 5)
    assert point["x"] ** 2 + 100 * point["y"] ** 2 + 19 * point["x"] * point["y"] <= 1
    tighter = L.conjunction(*_box("xy", -2, 2), L.Compare("<=", quadratic, E.ONE),
                            L.Compare(">=", E.add(X, Y), E.Num(Fraction(3))))
    assert refute(tighter, ["x", "y"], 10).status is Status.UNSAT


def test_a_search_stopped_by_its_deadline_goes_on():
    query = L.conjunction(*_box("xy", Fraction(1, 10), 3), L.Compare(
        ">=", E.apply("sin", E.mul(X, Y)), E.mul(X, Y)))
    search = Search(query, ["x", "y"])
    first = search.run(0.0)
    assert first.status is Status.UNKNOWN and first.reason.startswith("timeout")
    assert search.run(30).status is Status.UNSAT


def test_the_acrobots_decrease_is_refuted():
    """probe67/aq18 with the LQR loop and x^T P x of the Lyapunov equation: codac's
    bisection needs more than 3e7 boxes per doubling of the radius for this condition."""
    from fossil_dsl.engine.linear import local_certificate
    from fossil_dsl.frontends.checking import load
    from fossil_dsl.ir import traversal
    from fossil_dsl.ir.calculus import derivative
    spec = load("specs/probe67/aq18_acrobot_stab_ctrl_4d.fsl")
    P, K = local_certificate(spec, controlled=True)
    states = [E.Var(s) for s in spec.states]

    def num(value):
        return E.Num(Fraction(float(value)).limit_denominator(10 ** 6))
    control = E.add(*[E.mul(num(-k), s) for k, s in zip(K[0], states)])
    field = [traversal.substitute(f, {"u": control}) for f in spec.dynamics]
    V = E.add(*[E.mul(num(P[i, j]), a, b) for i, a in enumerate(states)
                for j, b in enumerate(states)])
    change = E.add(*[E.mul(derivative(V, s), f) for s, f in zip(spec.states, field)])
    query = L.conjunction(*_box(spec.states, -1, 1),
                          L.Compare("<=", V, E.Num(Fraction(1, 25))),
                          L.Compare(">=", E.squared_norm(spec.states),
                                    E.Num(Fraction(1, 160000))),
                          L.Compare(">=", change, E.ZERO))
    assert refute(query, spec.states, 120).status is Status.UNSAT


def test_recheck_takes_another_procedure_than_the_taylor_forms():
    from fossil_dsl.outputs import recheck
    query = L.conjunction(*_box("xyz", Fraction(1, 2), 1), L.Compare(
        ">=", E.apply("sin", E.mul(X, Y, E.Var("z"))), E.mul(X, Y, E.Var("z"))))
    others = recheck.other_solvers("taylor", query)
    assert "taylor" not in others and "interval" in others
    assert recheck._backend("interval").taylor is False  # codac alone
    assert "taylor" in recheck.other_solvers("interval", query)
    assert recheck._backend("taylor").check(query, ["x", "y", "z"], 10).status \
        is Status.UNSAT


def test_the_interval_verifier_names_the_taylor_forms_when_they_decide():
    # from 4 variables the Taylor forms go first (on 3, codac has a first slice)
    from fossil_dsl.solvers.interval_backend import IntervalBackend
    product = E.mul(X, Y, E.Var("z"), E.Var("w"))
    query = L.conjunction(*_box("xyzw", Fraction(1, 2), 1),
                          L.Compare(">=", E.apply("sin", product), product))
    answer = IntervalBackend().check(query, list("xyzw"), 10)
    assert answer.status is Status.UNSAT and answer.solver == "taylor"


def test_codac_settles_a_small_3_variable_query_before_the_taylor_forms():
    # x y z >= 2 on [1/2, 1]^3: codac's first contraction empties the box
    from fossil_dsl.solvers.interval_backend import IntervalBackend
    query = L.conjunction(*_box("xyz", Fraction(1, 2), 1),
                          L.Compare(">=", E.mul(X, Y, E.Var("z")), E.Num(Fraction(2))))
    answer = IntervalBackend().check(query, ["x", "y", "z"], 10)
    assert answer.status is Status.UNSAT and answer.solver != "taylor"


def test_a_side_without_variables_is_read_on_every_box():
    query = L.conjunction(*_box("xyz", -1, 1), L.Compare(">=", E.ONE, E.ZERO),
                          L.Compare(">=", E.mul(X, Y, E.Var("z")), E.Num(Fraction(2))))
    assert refute(query, ["x", "y", "z"], 10).status is Status.UNSAT
    holds = L.conjunction(*_box("xyz", -1, 1), L.Compare(">=", E.ONE, E.ZERO))
    assert refute(holds, ["x", "y", "z"], 10).status is Status.SAT
