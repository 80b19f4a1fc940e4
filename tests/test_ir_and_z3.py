"""The neutral expressions, their exact folding, printing and enclosures, and the Z3
backend's verdicts on formulas with known answers."""
from fractions import Fraction

import mpmath
import pytest
from hypothesis import given, settings, strategies as st

from fossil_dsl import loads
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.enclosure import enclose, sign
from fossil_dsl.ir.expr import to_text
from fossil_dsl.ir.numbers import number_text
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.z3_backend import Z3Backend

x, y = E.Var("x0"), E.Var("x1")


def num(value) -> E.Num:
    return E.Num(Fraction(value))


# ---- exact folding ----------------------------------------------------------------
def test_constants_fold_exactly():
    assert E.add(num("0.1"), num("0.2")) == num("0.3")
    assert E.power(num(2), num(-2)) == num("0.25")
    assert E.mul(num(3), x, num(0)) == E.ZERO
    assert E.apply("cos", E.ZERO) == E.ONE
    assert E.apply("sqrt", num(Fraction(9, 4))) == num(Fraction(3, 2))
    assert isinstance(E.apply("sqrt", num(2)), E.Apply)


@settings(max_examples=200, deadline=None)
@given(func=st.sampled_from(("sin", "cos", "tan")),
       c=st.fractions(-5, 5, max_denominator=12))
def test_rational_multiples_of_pi_fold_only_to_their_exact_values(func, c):
    # sin(pi/6) = 1/2 exactly, so an operating angle pi/6 with power 2 sin(pi/6) = 1
    # gives an equilibrium the checker can decide; sin(pi/4) = sqrt(2)/2 stays a function
    folded = E.apply(func, E.mul(num(c), E.Pi()))
    true = getattr(mpmath, func)(mpmath.mpf(c.numerator) / c.denominator * mpmath.pi)
    if isinstance(folded, E.Num):
        assert abs(mpmath.mpf(folded.value.numerator) / folded.value.denominator - true) \
            < mpmath.mpf(10) ** -12
    else:  # not folded: the value is irrational (or tan is undefined there)
        ratio = c * 6
        assert ratio.denominator != 1 or abs(true) not in (0, 0.5, 1)


def test_the_operating_angle_pi_over_6_is_an_equilibrium():
    assert E.apply("sin", E.mul(num(Fraction(1, 6)), E.Pi())) == num(Fraction(1, 2))
    assert E.apply("cos", E.mul(num(Fraction(2, 3)), E.Pi())) == num(Fraction(-1, 2))
    assert E.apply("tan", E.mul(num(Fraction(-1, 4)), E.Pi())) == num(-1)
    assert isinstance(E.apply("tan", E.mul(num(Fraction(1, 2)), E.Pi())), E.Apply)
    assert E.apply("sin", E.Pi()) == E.ZERO
    text = """state x, w
dynamics continuous {
    x' = w
    w' = 1 - 2*sin(x + pi/6) - 0.5*w
}
domain box([-1, -1], [1, 1])
prove stable
"""
    assert loads(text).states == ("x", "w")  # checked: f(0) = 1 - 2 sin(pi/6) = 0


@pytest.mark.parametrize("build, message", [
    (lambda: E.div(x, E.ZERO), "division by zero"),
    (lambda: E.power(num(10), num(100_000)), "too large"),
    (lambda: E.apply("log", num(-1)), "non-positive"),
    (lambda: E.apply("sqrt", num(-1)), "negative"),
])
def test_impossible_constants_raise_expr_error(build, message):
    with pytest.raises(E.ExprError, match=message):
        build()


def test_substitute_folds():
    f = E.add(E.power(x, num(3)), E.mul(num(-1), y))
    assert traversal.substitute(f, {"x0": num(2), "x1": num(3)}) == num(5)


def test_theory_classification():
    assert traversal.is_polynomial(x * y + x ** 3)
    assert not traversal.is_polynomial(x / y)
    assert traversal.is_arithmetic(x / y) and traversal.is_arithmetic(E.apply("abs", x))
    assert not traversal.is_arithmetic(E.apply("sin", x))
    assert not traversal.is_arithmetic(E.Pi() * x)


# ---- printing ---------------------------------------------------------------------
@pytest.mark.parametrize("value, text", [
    (Fraction(1, 10), "0.1"), (Fraction(-3, 8), "-0.375"), (Fraction(1, 3), "1/3"),
    (Fraction(7), "7"), (Fraction(981, 100), "9.81"),
])
def test_number_text_is_exact(value, text):
    assert number_text(value) == text


def test_expression_text():
    assert to_text(x - y ** 2) == "x0 - x1^2"
    assert to_text(-(x + y) * num(2)) == "-2*(x0 + x1)" or to_text(-(x + y) * num(2)) == "2*-(x0 + x1)"
    assert to_text(E.apply("sin", x) / (x + 1)) == "sin(x0)/(x0 + 1)"


leaves = st.one_of(st.sampled_from([x, y]),
                   st.fractions(min_value=-20, max_value=20, max_denominator=50).map(E.Num))
expressions = st.recursive(leaves, lambda inner: st.one_of(
    st.tuples(inner, inner).map(lambda p: p[0] + p[1]),
    st.tuples(inner, inner).map(lambda p: p[0] - p[1]),
    st.tuples(inner, inner).map(lambda p: p[0] * p[1]),
    st.tuples(inner, st.integers(0, 3)).map(lambda p: p[0] ** p[1]),
    inner.map(lambda e: -e)), max_leaves=12)


@settings(max_examples=150, deadline=None, derandomize=True, database=None)
@given(expressions, st.fractions(-3, 3, max_denominator=7), st.fractions(-3, 3, max_denominator=7))
def test_printed_expressions_parse_back_to_the_same_function(expr, a, b):
    text = f"state x0, x1\ndynamics continuous {{\nx0' = {to_text(expr)}\nx1' = 0\n}}\n" \
           "domain box([-1, -1], [1, 1])\nprove stable\n"
    try:
        spec = loads(text)
    except Exception as exc:  # f(0) != 0 is a legitimate rejection for `stable`
        assert "equilibrium" in str(exc), str(exc)
        return
    point = {"x0": E.Num(a), "x1": E.Num(b)}
    assert traversal.substitute(spec.dynamics[0], point) == traversal.substitute(expr, point)


# ---- enclosures ---------------------------------------------------------------------
@settings(max_examples=100, deadline=None, derandomize=True, database=None)
@given(st.sampled_from(["sin", "cos", "tan", "exp", "tanh", "atan", "abs", "sqrt", "log"]),
       st.fractions(Fraction(1, 100), 5, max_denominator=1000))
def test_enclosure_contains_the_true_value(func, value):
    mpmath.mp.dps = 50
    exact = getattr(mpmath, {"abs": "fabs"}.get(func, func))(mpmath.mpf(value.numerator) /
                                                              value.denominator)
    low, high = enclose(E.Apply(func, E.Num(value)))
    assert low <= exact <= high


def test_enclosures_round_outwards_and_leave_the_rounding_mode_alone():
    import ctypes
    import ctypes.util
    libm = ctypes.CDLL(ctypes.util.find_library("m"))
    before = libm.fegetround()
    third = E.Div(E.ONE, num(3))  # built without folding: codac divides 1 by 3
    low, high = enclose(third)
    assert Fraction(low) < Fraction(1, 3) < Fraction(high)
    tenths = E.Add((num("0.1"), E.Apply("abs", num("0.2"))))
    low, high = enclose(tenths)
    assert Fraction(low) <= Fraction(3, 10) <= Fraction(high) and low < high
    assert libm.fegetround() == before
    assert repr(float("0.011")) == "0.011"


def test_sign_of_irrational_constants():
    assert sign(E.Pi() - num("3.1415926535")) == 1
    assert sign(E.apply("sqrt", num(2)) - num("1.4142135624")) == -1
    assert sign(E.Apply("sin", E.Pi())) is None  # sin(pi) = 0 cannot be decided by intervals


# ---- open inner approximation --------------------------------------------------------
def test_open_inner_makes_comparisons_strict_and_flips_under_not():
    closed = L.Compare("<=", x, E.ONE)
    assert L.open_inner(closed) == L.Compare("<", x, E.ONE)
    assert L.open_inner(L.negation(closed)) == L.Not(closed)
    assert L.closed_outer(L.Compare("<", x, E.ONE)) == closed


# ---- Z3 verdicts ----------------------------------------------------------------------
def ball(r) -> L.Formula:
    return L.Compare("<=", x ** 2 + y ** 2, num(r) ** 2)


def sin(e):
    return E.apply("sin", e)


def cos(e):
    return E.apply("cos", e)


def exp(e):
    return E.apply("exp", e)


def sigmoid_form(e):  # tanh(e) written through exp
    return num(2) / (E.ONE + exp(num(-2) * e)) - E.ONE


THOUSANDTH = num("0.001")
# (id, formula, verdict over the reals, is its closure (strict -> non-strict) satisfiable)
# A delta-decision verifier decides the closure: where only strictness makes a formula
# UNSAT, it may answer (delta-)SAT; it may never answer UNSAT to a satisfiable formula.
CONFORMANCE = [
    ("empty", L.Compare("<", x ** 2 + y ** 2, E.ZERO), Status.UNSAT, True),
    ("circle-meets-line", L.conjunction(ball(1), L.Compare(">=", x + y, num("1.4"))),
     Status.SAT, True),
    ("circle-misses-line", L.conjunction(ball(1), L.Compare(">=", x + y, num("1.5"))),
     Status.UNSAT, False),
    ("am-gm", L.Compare("<", x ** 2 + y ** 2, num(2) * x * y), Status.UNSAT, True),
    ("cubic-root", L.conjunction(L.Compare("<=", x ** 3 - num(2), E.ZERO),
                                 L.Compare(">=", x ** 3 - num(2), E.ZERO)), Status.SAT, True),
    ("cubic-no-root", L.conjunction(L.Compare(">=", x ** 3 - num(2), E.ZERO),
                                    L.Compare("<=", x, num("1.25"))), Status.UNSAT, False),
    ("division", L.conjunction(L.Compare(">", x, E.ONE), L.Compare(">", E.ONE / x, E.ONE)),
     Status.UNSAT, True),
    ("abs", L.Compare("<", E.apply("abs", x), E.ZERO), Status.UNSAT, True),
    ("pi-bounds", L.conjunction(L.Compare(">", x, E.Pi()), L.Compare("<", x, num("3.1415"))),
     Status.UNSAT, False),
    # transcendental identities, and the same identities perturbed (then false)
    ("pythagoras", L.Compare(">", sin(x) ** 2 + cos(x) ** 2, E.ONE + THOUSANDTH),
     Status.UNSAT, False),
    ("pythagoras-perturbed", L.Compare(">", sin(x) ** 2 + num("1.01") * cos(x) ** 2,
                                       E.ONE + THOUSANDTH), Status.SAT, True),
    ("exp-inverse", L.Compare("<", exp(x) * exp(-x), E.ONE - THOUSANDTH), Status.UNSAT, False),
    ("exp-inverse-perturbed", L.Compare("<", exp(x) * exp(num("-1.01") * x),
                                        E.ONE - THOUSANDTH), Status.SAT, True),
    ("tanh-through-exp", L.Compare(">", E.apply("abs", E.apply("tanh", x) - sigmoid_form(x)),
                                   THOUSANDTH), Status.UNSAT, False),
    ("tanh-through-exp-perturbed",
     L.Compare(">", E.apply("abs", E.apply("tanh", x) - sigmoid_form(num("1.1") * x)),
               THOUSANDTH), Status.SAT, True),
    ("sin-above-one", L.Compare(">", sin(x), E.ONE + THOUSANDTH), Status.UNSAT, False),
    ("sin-near-one", L.Compare(">=", sin(x), E.ONE - THOUSANDTH), Status.SAT, True),
]
BOUNDS = L.conjunction(*(L.Compare(op, v, num(s * 10)) for v in (x, y)
                         for op, s in ((">=", -1), ("<=", 1))))


def installed_backends():
    from fossil_dsl.solvers import registry
    for name in registry.names():
        if name in ("z3", "cvc5") or registry.is_installed(name):
            yield pytest.param(name, id=name)
        else:
            yield pytest.param(name, id=name, marks=pytest.mark.skip(
                reason=f"verifier {name} is not installed here"))


@pytest.mark.parametrize("backend", list(installed_backends()))
@pytest.mark.parametrize("formula, expected, closure_sat", [c[1:] for c in CONFORMANCE],
                         ids=[c[0] for c in CONFORMANCE])
def test_backend_conformance(backend, formula, expected, closure_sat):
    from fossil_dsl.solvers import registry
    info = registry.BACKENDS[backend]
    bounded = L.conjunction(formula, BOUNDS)
    polynomial = all(traversal.is_arithmetic(side) for c in L.comparisons(formula)
                     for side in (c.left, c.right))
    # CVC5 often answers transcendental queries only by running into its time limit
    timeout = 10 if polynomial or info.delta_decision else 3
    answer = registry.load(backend).check(bounded, ["x0", "x1"], timeout=timeout)
    if answer.status is Status.UNKNOWN:  # allowed, but never a wrong verdict
        # ... except where a backend is complete: Z3 on polynomials, intervals on
        # bounded queries (they give UNSAT or delta-SAT)
        assert not (backend == "z3" and polynomial), answer.reason
        assert not info.delta_decision, answer.reason
        return
    if info.delta_decision and expected is Status.UNSAT and closure_sat:
        return  # either answer is right: UNSAT, or delta-SAT on the closure
    assert answer.status is expected, answer
    if expected is Status.SAT:
        assert set(answer.model) == {"x0", "x1"}
        point = {n: E.Num(v) for n, v in answer.model.items()}
        assert L.truth(L.substitute(bounded, point)) or answer.approximate


def test_z3_models_satisfy_the_formula_exactly():
    formula = L.conjunction(ball(1), L.Compare(">=", x + y, num("1.4")))
    answer = Z3Backend().check(formula, ["x0", "x1"], timeout=10)
    point = {name: E.Num(value) for name, value in answer.model.items()}
    assert traversal.substitute(x ** 2 + y ** 2, point).value <= 1
    assert traversal.substitute(x + y, point).value >= Fraction("1.4")


def test_z3_reports_transcendental_as_unknown_not_unsat():
    answer = Z3Backend().check(L.Compare(">", E.apply("sin", x), num(2)), ["x0"], timeout=5)
    assert answer.status is Status.UNKNOWN and "sin" in answer.reason


def test_like_terms_cancel_so_f0_is_exact():
    two = num(2)
    assert E.apply("sin", x + two) - E.apply("sin", two) != E.ZERO
    assert traversal.substitute(E.apply("sin", x + two) - E.apply("sin", two), {"x0": E.ZERO}) == E.ZERO
    assert x * num(3) - num(3) * x == E.ZERO
    result = loads("state x0\ndynamics continuous { x0' = sin(x0 + 2) - sin(2) - x0 }\n"
                   "domain ball([0], 1)\nprove stable\n")
    assert result.dynamics[0] != E.ZERO


def test_newlines_anywhere_inside_set_braces():
    spec = loads("state x0, x1\ndynamics continuous {\n x0' = -x0\n x1' = -x1\n}\n"
                 "domain {\n  x0 <= 1\n  , x1 <=\n    1, x0 >= -1, x1 >= -1\n}\nprove stable\n")
    assert len(spec.domain.constraints) == 4


def test_cvc5_is_stopped_at_its_deadline_even_when_it_ignores_its_limit(monkeypatch):
    # CVC5's nonlinear module was seen running 30 minutes past `tlimit-per`
    import time
    from fossil_dsl.solvers import cvc5_backend
    monkeypatch.setattr(cvc5_backend, "_solve", lambda *args: time.sleep(600))
    monkeypatch.setattr(cvc5_backend, "GRACE_SECONDS", 0.5)
    started = time.monotonic()
    answer = cvc5_backend.Cvc5Backend().check_text(
        "(set-logic QF_NRA)\n(declare-const x Real)\n(assert (> x 0))\n(check-sat)\n", 1.0)
    assert answer.status.value == "unknown" and "stopped" in answer.reason
    assert time.monotonic() - started < 3


def test_cvc5_is_stopped_when_another_solver_of_a_race_has_answered(monkeypatch):
    import threading
    import time
    from fossil_dsl.solvers import cvc5_backend
    monkeypatch.setattr(cvc5_backend, "_solve", lambda *args: time.sleep(600))
    stop = threading.Event()
    threading.Timer(0.3, stop.set).start()
    started = time.monotonic()
    answer = cvc5_backend.Cvc5Backend().check_text(
        "(set-logic QF_NRA)\n(declare-const x Real)\n(assert (> x 0))\n(check-sat)\n", 60.0,
        stop=stop)
    assert answer.status.value == "unknown" and answer.reason == "stopped"
    assert time.monotonic() - started < 2


def test_cvc5_answers_from_its_child_process():
    from fossil_dsl.solvers import cvc5_backend
    text = "(set-logic QF_NRA)\n(declare-const x Real)\n(assert (> (* x x) 2))\n(check-sat)\n"
    sat = cvc5_backend.Cvc5Backend().check_text(text, 5.0, ["x"])
    assert sat.status.value == "sat" and sat.model["x"] ** 2 > 2
    unsat = cvc5_backend.Cvc5Backend().check_text(text.replace("> (* x x) 2", "< (* x x) -1"), 5.0)
    assert unsat.status.value == "unsat"


def test_cvc5_races_for_polynomial_counterexamples_that_z3_misses():
    # specs/probe/g04's decrease condition for a learned V (4 states, quadratic): Z3 and
    # the interval search each ran 30 s without an answer; CVC5 has a model at once
    import time
    from pathlib import Path
    from fossil_dsl import load
    from fossil_dsl.frontends.api import _backend
    from fossil_dsl.plan.compile import compile_spec
    from fossil_dsl.solvers.smtlib_reader import read_script
    root = Path(__file__).resolve().parent
    query = read_script((root / "data" / "g04_decrease.smt2").read_text())
    plan = compile_spec(load(root.parent / "specs" / "probe" / "g04_planar_rwa.fsl"))
    started = time.monotonic()
    answer = _backend(plan).check(query.formula, query.variables, 20.0)
    assert answer.status.value == "sat" and answer.solver == "cvc5"
    assert time.monotonic() - started < 10
    point = {v: E.Num(answer.model[v]) for v in query.variables}
    assert L.truth(L.substitute(query.formula, point)) is True


def test_a_z3_check_that_ignores_its_interrupt_is_left_behind(monkeypatch):
    """The kernel asks Z3 in its own thread: a check that does not stop when interrupted
    must not hold the run (discrete d10 overran its run's timeout, sessions 32 and 40)."""
    import threading
    import time
    import z3
    from fossil_dsl.solvers import z3_backend
    monkeypatch.setattr(z3_backend, "ABANDON_AFTER", 0.2)
    release = threading.Event()

    class Deaf:  # a check that returns only when released, whatever it is told
        def check(self):
            release.wait(30)
            return z3.unsat

    class Context:
        interrupts = 0

        def interrupt(self):
            Context.interrupts += 1

    started = time.monotonic()
    try:
        answer = z3_backend._check_with_deadline(Deaf(), Context(), 0.1)
        assert answer.status is Status.UNKNOWN and answer.reason == z3_backend.LEFT_BEHIND
    finally:
        release.set()
    assert time.monotonic() - started < 5 and Context.interrupts == 1
    stop = threading.Event()
    stop.set()  # stopped from outside: interrupted at once, then left behind
    release.clear()
    started = time.monotonic()
    try:
        answer = z3_backend._check_with_deadline(Deaf(), Context(), 60, stop)
        assert answer.status is Status.UNKNOWN and answer.reason == z3_backend.LEFT_BEHIND
    finally:
        release.set()
    assert time.monotonic() - started < 5 and Context.interrupts == 2


def test_an_error_in_a_z3_check_reaches_the_caller_at_once():
    """The check runs in a worker thread; its error is raised in the caller's, not turned
    into an unknown answer after the timeout."""
    import time
    import z3
    from fossil_dsl.solvers import z3_backend

    class Failing:
        def check(self):
            raise z3.Z3Exception("broken")

    class Context:
        def interrupt(self):
            pass

    started = time.monotonic()
    with pytest.raises(z3.Z3Exception, match="broken"):
        z3_backend._check_with_deadline(Failing(), Context(), 60)
    assert time.monotonic() - started < 2


def test_a_z3_check_canceled_by_its_timeout_is_unknown_not_an_internal_error():
    """Z3 may end an interrupted or timed-out check by raising "canceled" (bytes) instead
    of answering unknown: the false probe f62 ended as "fossilc: internal error:
    Z3Exception: b'canceled'" after 51 s of a 120 s run."""
    import z3
    from fossil_dsl.solvers import z3_backend

    class Canceled:
        def check(self):
            raise z3.Z3Exception(b"canceled")

    class Context:
        def interrupt(self):
            pass

    answer = z3_backend._check_with_deadline(Canceled(), Context(), 60)
    assert answer.status is Status.UNKNOWN and answer.reason == z3_backend.CANCELED
