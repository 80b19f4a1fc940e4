"""Comparisons with divisions by expressions whose sign is proved (2 - cos(q)^2 > 0) are
multiplied through before a refutation is looked for (solvers/cleared.py), so the
decrease of a mechanical system with its inertia inverted is refuted, and checked, as a
polynomial in the states, sin q and cos q."""
import time
from fractions import Fraction as F

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

import fossil_dsl
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import traversal
from fossil_dsl.kernel.obligations import Claim
from fossil_dsl.kernel.prove import SUM_OF_SQUARES, discharge
from fossil_dsl.kernel.verdict import list_obligations
from fossil_dsl.solvers.cleared import cleared, common_denominator, fraction, has_division
from fossil_dsl.solvers.positivstellensatz import refutation_problem

X, Y = E.Var("x"), E.Var("y")
BOX = L.conjunction(*(L.Compare(relation, v, E.Num(bound)) for v in (X, Y)
                      for relation, bound in ((">=", -1), ("<=", 1))))


@st.composite
def rational_forms(draw, depth: int = 3):
    """Sums, products, quotients and integer powers (negative ones too) of x, y and
    numbers."""
    if depth == 0 or draw(st.booleans()):
        return draw(st.sampled_from([X, Y, E.Num(F(3, 2)), E.Num(F(-2)), E.Num(F(1, 3))]))
    a, b = draw(rational_forms(depth=depth - 1)), draw(rational_forms(depth=depth - 1))
    kind = draw(st.sampled_from(["add", "mul", "div", "pow", "neg"]))
    if kind == "div":
        return E.Div(a, b)
    if kind == "pow":
        return E.Pow(a, E.Num(draw(st.sampled_from([2, 3, -1, -2]))))
    return {"add": lambda: E.add(a, b), "mul": lambda: E.mul(a, b),
            "neg": lambda: E.neg(a)}[kind]()


def _value(expr: E.Expr, x: F, y: F) -> F | None:
    """The exact value at (x, y), or None where a division by 0 occurs."""
    try:
        folded = traversal.substitute(expr, {"x": E.Num(x), "y": E.Num(y)})
    except (E.ExprError, ZeroDivisionError):
        return None
    return folded.value if isinstance(folded, E.Num) else _fold(folded)


def _fold(expr: E.Expr) -> F | None:
    """Raw Div and Pow nodes that substitution left unfolded."""
    if isinstance(expr, E.Num):
        return expr.value
    parts = [_fold(child) for child in E.children(expr)]
    if any(p is None for p in parts):
        return None
    try:
        if isinstance(expr, E.Div):
            return parts[0] / parts[1]
        if isinstance(expr, E.Pow):
            return parts[0] ** int(parts[1])
        if isinstance(expr, E.Add):
            return sum(parts, F(0))
        if isinstance(expr, E.Mul):
            return np.prod(parts, dtype=object)
        if isinstance(expr, E.Neg):
            return -parts[0]
    except ZeroDivisionError:
        return None
    return None


fractions = st.fractions(min_value=-2, max_value=2, max_denominator=20)


@settings(max_examples=150, deadline=None)
@given(rational_forms(), fractions, fractions)
def test_an_expression_is_its_numerator_over_its_denominators(expr, x, y):
    numerator, factors = fraction(expr)
    assert not has_division(L.Compare(">=", numerator, E.ZERO))
    values = [_value(f, x, y) for f in factors]
    whole = _value(expr, x, y)
    if whole is None or any(v is None or v == 0 for v in values):
        return  # the identity is claimed only where every factor is non-zero
    top = _value(numerator, x, y)
    assert top == whole * np.prod(values, dtype=object)


def test_a_denominator_of_proved_sign_is_multiplied_through_and_another_is_not():
    q = E.Var("q")
    box = L.conjunction(L.Compare(">=", q, E.Num(-1)), L.Compare("<=", q, E.Num(1)))
    inertia = E.add(E.Num(2), E.neg(E.power(E.apply("cos", q), E.Num(2))))
    query = L.conjunction(box, L.Compare(">", E.div(q, inertia), E.Num(F(1, 2))))
    rewritten = cleared(query)
    assert not has_division(rewritten)
    # x / (x - 1/2) changes sign on [-1, 1]: that comparison stays as it was
    shifted = E.add(q, E.Num(F(-1, 2)))
    undecided = L.conjunction(box, L.Compare(">", E.div(q, shifted), E.Num(1)))
    assert cleared(undecided) == undecided


@settings(max_examples=80, deadline=None)
@given(fractions, fractions, st.sampled_from(["<=", "<", ">=", ">"]))
def test_a_negative_denominator_reverses_the_comparison(x, y, relation):
    # y - 3 < 0 on the box: x / (y - 3) ~ 1/2 holds exactly where the cleared form does
    comparison = L.Compare(relation, E.div(X, E.add(Y, E.Num(-3))), E.Num(F(1, 2)))
    rewritten = cleared(L.conjunction(BOX, comparison))
    assert not has_division(rewritten)
    point = {"x": E.Num(x), "y": E.Num(y)}
    assert L.truth(L.substitute(rewritten, point)) == L.truth(L.substitute(
        L.conjunction(BOX, comparison), point))


def test_a_field_over_shared_denominators_keeps_one_of_them():
    q = E.Var("q")
    box = L.conjunction(L.Compare(">=", q, E.Num(-1)), L.Compare("<=", q, E.Num(1)))
    inertia = E.add(E.Num(2), E.neg(E.power(E.apply("cos", q), E.Num(2))))
    field = [E.div(E.apply("sin", q), inertia), E.div(E.neg(q), inertia), q]
    numerators, denominator = common_denominator(field, box)
    assert denominator == inertia
    assert numerators[2] == E.mul(q, inertia)


ELASTIC_JOINT = """\
state q1, w1, q2, w2
dynamics continuous {
    q1' = w1
    w1' = (-sin(q1) - 0.4*w1 - (q1 - q2))/(2 - cos(q1)^2)
    q2' = w2
    w2' = (q1 - q2) - 0.4*w2
}
domain box([-1, -1, -1, -1], [1, 1, 1, 1])
set init = ball([0, 0, 0, 0], 0.2)
prove from init: stable
"""


def _joint_decrease(text: str):
    """The decrease obligation of the linearisation's quadratic V (scaled to 1) on
    {V <= 1/10} for the joint with its inertia 2 - cos(q1)^2."""
    spec = fossil_dsl.loads(text)
    A = np.array([[0, 1, 0, 0], [-2, -0.4, 1, 0], [0, 0, 0, 1], [1, 0, -1, -0.4]])
    P = scipy.linalg.solve_continuous_lyapunov(A.T, -np.eye(4))
    P /= P.max()
    xs = [E.Var(s) for s in spec.states]
    V = E.add(*[E.mul(E.Num(F(round(P[i][j] * 1000), 1000)), xs[i], xs[j])
                for i in range(4) for j in range(4)])
    claim = Claim(spec, {"V": V}, levels={"beta": F(1, 10)}, ball_radius=F(1, 100))
    return spec, next(o for o in list_obligations(claim) if o.name == "condition:decrease")


def test_a_decrease_over_an_inverted_inertia_is_refuted_and_checks():
    # the interval procedure left this decrease unproved after 48 s; multiplied through
    # 2 - cos(q1)^2 > 0 it is a polynomial in 6 variables, refuted in about a second
    spec, decrease = _joint_decrease(ELASTIC_JOINT)
    started = time.monotonic()
    proof = discharge(decrease, spec.states, 60, first=SUM_OF_SQUARES)
    assert proof.proved and proof.procedure == SUM_OF_SQUARES, proof
    assert time.monotonic() - started < 30
    assert refutation_problem(proof.evidence, decrease.query, spec.states) is None
    # the same evidence is no proof for a joint whose inertia can vanish on D
    _, other = _joint_decrease(ELASTIC_JOINT.replace("2 - cos(q1)^2", "1.2 - 2*cos(q1)^2"))
    assert refutation_problem(proof.evidence, other.query, spec.states) is not None


@pytest.mark.parametrize("divisor", ["2 - cos(q1)^2", "1 + sin(q1)^2"])
def test_a_growing_joint_is_not_proved(divisor):
    # the joint pushed away from rest (+sin): no V decreases; nothing is proved
    text = ELASTIC_JOINT.replace("(-sin(q1) - 0.4*w1", "(3*sin(q1) - 0.4*w1") \
        .replace("2 - cos(q1)^2", divisor)
    spec, decrease = _joint_decrease(text)
    assert not discharge(decrease, spec.states, 5, first=SUM_OF_SQUARES).proved


def test_a_division_inside_a_divisor_must_be_proved_non_zero_too():
    # x / ((1 + y^2) / y) = x y / (1 + y^2): the one factor left, 1 + y^2, is positive
    # everywhere, but the identity also needs the inner divisor y != 0: proved on
    # [1/2, 1], not on [-1, 1]
    for low, changed in ((F(1, 2), True), (F(-1), False)):
        box = L.conjunction(L.Compare(">=", Y, E.Num(low)), L.Compare("<=", Y, E.Num(1)),
                            L.Compare(">=", X, E.Num(-1)), L.Compare("<=", X, E.Num(1)))
        divisor = E.div(E.add(E.Num(1), E.power(Y, E.Num(2))), Y)
        query = L.conjunction(box, L.Compare(">", E.div(X, divisor), E.Num(2)))
        assert (cleared(query) != query) == changed


def test_a_constant_divisor_is_proved_without_a_box():
    # pi - 3 > 0 and 3 - pi < 0 need no box; a divisor that is a constant expression
    # inside a divisor is one of the guards too
    inner = E.add(E.Pi(), E.Num(-3))
    divisor = E.div(E.add(E.Num(1), E.power(X, E.Num(2))), inner)
    query = L.conjunction(BOX, L.Compare(">", E.div(X, divisor), E.Num(1)))
    rewritten = cleared(query)
    assert not has_division(rewritten)
    assert str(rewritten).endswith("x*(pi - 3) - x^2 - 1 > 0"), str(rewritten)
