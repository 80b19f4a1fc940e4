"""Comparisons with divisions by evidently positive polynomials (y / (1 + z^2)) get a
polynomial form, N >= 0 for N / D with D > 0 everywhere, so that a sum-of-squares
refutation proves them (ir/rational.py `over_positive`, positivstellensatz.py); and a
race's point that is no counterexample leaves the query undecided, not failed."""
import json
from fractions import Fraction as F

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import rational as R
from fossil_dsl.ir import traversal
from fossil_dsl.kernel.obligations import Obligation
from fossil_dsl.kernel.prove import SUM_OF_SQUARES, discharge
from fossil_dsl.solvers.evidence_json import refutation_from_json, refutation_json
from fossil_dsl.solvers.positivstellensatz import refutation_problem
from fossil_dsl.solvers.sos_refutation import refute

X, Y, Z = E.Var("x"), E.Var("y"), E.Var("z")
STATES = ("x", "y", "z")
ONE_PLUS_Z2 = E.add(E.Num(1), E.power(Z, E.Num(2)))
# a rational expression with divisions nested in sums, products, powers and a quotient
RATIONAL = E.add(
    E.power(E.add(E.mul(E.Num(F(1, 2)), X), E.div(E.mul(E.Num(F(1, 5)), Y), ONE_PLUS_Z2)),
            E.Num(2)),
    E.neg(E.div(E.mul(X, Y), E.add(E.Num(2), E.power(E.mul(X, Y), E.Num(2))))),
    E.power(E.add(E.Num(3), E.power(Y, E.Num(4))), E.Num(-2)),
    E.div(Z, E.div(E.add(E.Num(1), E.power(X, E.Num(2))), ONE_PLUS_Z2)))


def _at(p: P.Polynomial, point) -> F:
    total = F(0)
    for monomial, coefficient in p.items():
        term = coefficient
        for value, k in zip(point, monomial):
            term *= value ** k
        total += term
    return total


rationals = st.fractions(min_value=-3, max_value=3, max_denominator=50)


@settings(max_examples=60, deadline=None)
@given(rationals, rationals, rationals)
def test_the_form_is_the_expression_over_a_positive_denominator(x, y, z):
    top, bottom = R.over_positive(RATIONAL, STATES)
    point = (x, y, z)
    denominator = _at(bottom, point)
    assert denominator >= bottom[(0, 0, 0)] > 0  # evidently positive
    folded = traversal.substitute(RATIONAL, {"x": E.Num(x), "y": E.Num(y), "z": E.Num(z)})
    assert isinstance(folded, E.Num), folded
    assert folded.value == _at(top, point) / denominator


@pytest.mark.parametrize("divisor", [
    E.add(E.Num(1), Z),  # vanishes at z = -1
    E.power(Z, E.Num(2)),  # no positive constant: vanishes at 0
    E.add(E.Num(1), E.neg(E.power(Z, E.Num(2)))),  # a negative coefficient
    E.add(E.Num(1), E.mul(X, Y)),  # an odd exponent
])
def test_a_divisor_that_may_vanish_multiplies_the_numerator(divisor):
    """y / d >= 0 exactly where y * d >= 0, wherever d != 0 (the kernel proves every
    division defined where a condition is evaluated): no positive form, but a polynomial
    one, y * d."""
    with pytest.raises(P.NotPolynomial):
        R.over_positive(E.div(Y, divisor), STATES)
    expected = P.multiply(P.polynomial(Y, STATES), P.polynomial(divisor, STATES))
    assert R.numerator(E.div(Y, divisor), STATES) == expected


def _decrease_query(scale: F) -> L.Formula:
    """x06's map with V = x^2 + y^2 + z^2 scaled: V(f(x)) - V(x) >= 0 on the box, x != 0.
    Unsatisfiable for the map itself (it contracts); satisfiable where f is scaled up."""
    fx = E.mul(E.Num(scale), E.add(E.mul(E.Num(F(1, 2)), X),
                                   E.div(E.mul(E.Num(F(1, 5)), Y), ONE_PLUS_Z2)))
    fy = E.mul(E.Num(scale), E.add(E.mul(E.Num(F(3, 5)), Y),
                                   E.neg(E.mul(E.Num(F(1, 10)), X, Z))))
    fz = E.mul(E.Num(scale), E.add(E.mul(E.Num(F(7, 10)), Z), E.mul(E.Num(F(1, 10)), X, Y)))
    square = lambda *e: E.add(*(E.power(t, E.Num(2)) for t in e))  # noqa: E731
    box = [L.Compare(op, v, E.Num(F(sign))) for v in (X, Y, Z)
           for op, sign in (("<=", 1), (">=", -1))]
    return L.conjunction(*box, L.Compare(">", square(X, Y, Z), E.ZERO),
                         L.Compare(">=", E.add(square(fx, fy, fz), E.neg(square(X, Y, Z))),
                                   E.ZERO))


def test_a_rational_decrease_is_refuted_and_an_expanding_one_is_not():
    import time
    assert refute(_decrease_query(F(1)), STATES, time.monotonic() + 120) is not None
    # scaled by 2 the map expands near the origin: no refutation can exist
    assert refute(_decrease_query(F(2)), STATES, time.monotonic() + 120) is None


def test_the_kernel_proves_a_rational_decrease_by_a_refutation_that_checks_again():
    obligation = Obligation("condition:decrease", "V(f(x)) - V(x) < 0", _decrease_query(F(1)))
    proof = discharge(obligation, STATES, 120, first=SUM_OF_SQUARES)
    assert proof.proved and proof.procedure == SUM_OF_SQUARES, proof
    exported = json.loads(json.dumps(refutation_json(proof.evidence, STATES)))
    assert refutation_problem(refutation_from_json(exported), obligation.query, STATES) is None
    # the same refutation proves nothing about the expanding map
    assert refutation_problem(proof.evidence, _decrease_query(F(2)), STATES) is not None
    exported["constant"] = str(F(exported["constant"]) + 1)  # one coefficient altered
    assert refutation_problem(refutation_from_json(exported), obligation.query,
                              STATES) is not None


def test_an_undecided_condition_is_not_reported_as_failing():
    from dataclasses import replace
    import fossil_dsl
    from fossil_dsl.engine.loop import Verdict, failure_reason
    from fossil_dsl.outputs.result import ConditionReport
    from fossil_dsl.solvers.api import Status
    text = ("spec one\nstate x\ndynamics continuous {\n    x' = -x\n}\ndomain box([-1], [1])\n"
            "prove stable\nsynthesis {\n    candidate: x^2\n}\n")
    result = fossil_dsl.synthesise(fossil_dsl.loads(text), timeout=60)
    reason = "delta-sat (not a solution when evaluated exactly; neither solver decided)"
    undecided = ConditionReport("decrease", "dV/dt < 0", "unknown", reason, (F(1, 10**4),))
    lines = replace(result, conditions=(undecided,)).summary().splitlines()
    line = next(line for line in lines if "dV/dt < 0" in line)
    assert line.startswith("  [unknown]") and reason in line and "last point" in line
    verdict = Verdict("decrease", Status.UNKNOWN, reason, (F(1, 10**4),))
    assert failure_reason([verdict]).startswith("the given function is not proved")
    failing = Verdict("decrease", Status.SAT, "", (F(1),))
    assert failure_reason([verdict, failing]).startswith("the given function fails")


def test_a_division_by_a_negative_number_beside_a_positive_divisor_keeps_its_sign():
    expr = E.add(E.div(Y, ONE_PLUS_Z2), E.Div(X, E.Num(-2)))  # y/(1 + z^2) - x/2
    top, bottom = R.over_positive(expr, STATES)
    assert P.evidently_positive(bottom)
    for point in [(F(1), F(0), F(0)), (F(0), F(1), F(2)), (F(-3), F(1, 2), F(1))]:
        x, y, z = point
        assert _at(top, point) / _at(bottom, point) == y / (1 + z * z) - x / 2
    with pytest.raises(P.NotPolynomial):  # a divisor that is 0 gives no form
        R.over_positive(E.add(E.div(Y, ONE_PLUS_Z2), E.Div(X, E.Num(0))), STATES)


def test_a_rational_condition_proved_by_a_solver_is_rechecked_by_a_refutation():
    """On a loaded machine x06's decrease was proved by a solver in the run, and CVC5,
    Z3, the interval search and Arb all left it undecided in the re-check."""
    from fossil_dsl.outputs.recheck import _decide, other_solvers
    query = _decrease_query(F(1))
    order = other_solvers("cvc5", query)
    assert order.index(SUM_OF_SQUARES) < order.index("z3")
    check = _decide("condition-decrease", query, STATES, "cvc5", 60, None)
    assert check.status == "unsat" and check.solver == SUM_OF_SQUARES, check
    # and it never re-proves the expanding map
    check = _decide("condition-decrease", _decrease_query(F(2)), STATES, "cvc5", 10, None)
    assert check.status != "unsat", check


@pytest.mark.parametrize("divisor", [
    E.add(E.Num(1), E.power(E.add(E.Num(1), Z), E.Num(2))),  # 1 + (1 + z)^2: y^2 + 2 y + 2
    E.add(E.power(E.add(X, E.neg(Y)), E.Num(2)), E.Num(F(1, 2))),
    E.mul(E.add(E.Num(2), E.power(E.add(X, Z), E.Num(4))), E.add(E.Num(1), E.power(Y, E.Num(2)))),
    E.power(E.add(E.Num(1), E.power(E.add(E.Num(1), Z), E.Num(2))), E.Num(3)),
])
def test_a_divisor_positive_by_its_form_gives_a_polynomial_form(divisor):
    """The repressilator's 2 / (1 + (1 + y)^2) (probe55/p01): expanded, the divisor has an
    odd monomial, but its form (a positive number plus an even power) shows it positive."""
    expression = E.div(Y, divisor)
    top, bottom = R.over_positive(expression, STATES)
    for point in [(F(1), F(-2), F(-1)), (F(-3, 2), F(1, 3), F(5, 7)), (F(0), F(0), F(-1))]:
        assert _at(bottom, point) > 0
        folded = traversal.substitute(expression, dict(zip(STATES, map(E.Num, point))))
        assert folded.value == _at(top, point) / _at(bottom, point)


@st.composite
def forms(draw, depth: int = 3):
    """Expressions of numbers of either sign, states, sums, products, quotients,
    negations and integer powers (negative too)."""
    if depth == 0 or draw(st.booleans()):
        return draw(st.sampled_from([X, Y, Z, E.Num(F(draw(st.integers(-3, 3)), 2))]))
    kind = draw(st.sampled_from(["add", "mul", "div", "neg", "pow"]))
    first, second = draw(forms(depth - 1)), draw(forms(depth - 1))
    exponent = E.Num(draw(st.integers(-3, 4)))
    build = {"add": lambda: E.add(first, second), "mul": lambda: E.mul(first, second),
             "div": lambda: E.div(first, second), "neg": lambda: E.neg(first),
             "pow": lambda: E.power(first, exponent)}[kind]
    try:
        return build()
    except (E.ExprError, ZeroDivisionError):  # folded to a division by zero
        return first


@settings(max_examples=300, deadline=None)
@given(forms(), rationals, rationals, rationals)
def test_what_the_form_shows_of_the_sign_holds_at_every_point(expression, x, y, z):
    """Soundness of `sign_by_form`: POSITIVE means > 0 wherever the expression is
    defined, NONNEGATIVE >= 0."""
    sign = R.sign_by_form(expression)
    try:
        folded = traversal.substitute(expression, {"x": E.Num(x), "y": E.Num(y), "z": E.Num(z)})
    except (E.ExprError, ZeroDivisionError):
        return  # undefined at the point
    if not isinstance(folded, E.Num):
        return
    if sign == R.POSITIVE:
        assert folded.value > 0, (expression, folded)
    if sign == R.NONNEGATIVE:
        assert folded.value >= 0, (expression, folded)


@settings(max_examples=300, deadline=None)
@given(forms(), forms(), rationals, rationals, rationals)
def test_the_polynomial_form_has_the_sign_of_the_expression_where_it_is_defined(
        top, bottom, x, y, z):
    """Soundness of `numerator`, which a refutation of a comparison with divisions
    rests on: at every point where the expression is defined, the polynomial has its
    sign (0 included)."""
    expression = E.add(top, E.div(E.Num(1), E.add(bottom, E.Num(F(1, 3)))))
    point = (x, y, z)
    try:
        form = R.numerator(expression, STATES)
        folded = traversal.substitute(expression, dict(zip(STATES, map(E.Num, point))))
    except (P.NotPolynomial, E.ExprError, ZeroDivisionError):
        return  # no form (a division by 0 folded in), or undefined at the point
    if not isinstance(folded, E.Num):
        return
    value = _at(form, point)
    assert (value > 0) == (folded.value > 0) and (value == 0) == (folded.value == 0), \
        (expression, point, value, folded.value)
    quotient = R.quotient(expression, STATES)
    divisor = _at(quotient.divisor(len(STATES)), point)
    assert divisor != 0 and _at(quotient.top, point) / divisor == folded.value
    if quotient.positive():
        assert divisor > 0, (expression, point)
