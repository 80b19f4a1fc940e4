"""The numeric search for counterexamples (engine/falsify.py): the points it returns
satisfy the query exactly, it finds slivers that uniform samples miss, it returns
nothing for an unsatisfiable query, and the loop's trigger (first for many states or
after a slow query; after an UNKNOWN) behaves as documented."""
import time
from fractions import Fraction

from fossil_dsl.engine import falsify
from fossil_dsl.engine.falsify import (FIRST_FROM_STATES, FIRST_SLICE, SLOW_QUERY, SOLVER,
                                       Falsifier, witness)
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Answer, Status

SIX = [f"x{i}" for i in range(1, 7)]


def _var(name):
    return E.Var(name)


def _squared_norm(states):
    return E.add(*(E.power(_var(s), E.Num(2)) for s in states))


def _in_box(states, low, high):
    return L.conjunction(*(L.conjunction(L.Compare(">=", _var(s), E.Num(low)),
                                         L.Compare("<=", _var(s), E.Num(high)))
                           for s in states))


def _exactly_true(query, states, point) -> bool:
    exact = {s: E.Num(Fraction(v)) for s, v in zip(states, point)}
    return L.truth(L.substitute(query, exact)) is True


def _shell_sliver():
    """A shell of width 0.0005 round radius 0.3 in six states, one orthant's part: about
    1e-8 of the box, so uniform samples never land in it."""
    return L.conjunction(
        _in_box(SIX, -2, 2),
        L.Compare(">=", _squared_norm(SIX), E.Num(Fraction(9, 100))),
        L.Compare("<=", _squared_norm(SIX), E.Num(Fraction(903, 10000))),
        L.Compare(">=", _var("x1"), E.Num(Fraction(1, 10))),
        L.Compare("<", _var("x2"), E.Num(Fraction(-1, 10))))


def test_a_witness_satisfies_the_query_exactly_even_in_a_sliver():
    query = _shell_sliver()
    point = witness(query, SIX, ([-2] * 6, [2] * 6), seed=0)
    assert point is not None
    assert _exactly_true(query, SIX, point)


def test_no_witness_for_an_unsatisfiable_query():
    query = L.conjunction(_in_box(SIX, -2, 2),
                          L.Compare("<=", E.add(_squared_norm(SIX), E.Num(1)), E.Num(Fraction(1, 2))))
    assert witness(query, SIX, ([-2] * 6, [2] * 6), seed=0) is None


def test_undefined_values_are_far_not_witnesses():
    """log(x) is undefined for x <= 0, where the points start half the time: NaN must
    count as far from holding, and the point found lies where log is defined."""
    x = _var("x")
    query = L.conjunction(_in_box(["x"], -1, 1),
                          L.Compare("<=", E.apply("log", x), E.Num(-1)))
    point = witness(query, ["x"], ([-1], [1]), seed=1)
    assert point is not None and 0 < point[0] <= 0.3679


class _Verifier:
    """A stand-in verifier: records the budgets it is given; answers `answer`, after
    using up the budget where `slow`."""

    def __init__(self, answer, slow=False):
        self.answer, self.slow, self.budgets = answer, slow, []

    def __call__(self, seconds):
        self.budgets.append(seconds)
        if self.slow:
            time.sleep(seconds)
        return self.answer


def test_the_falsifier_searches_first_only_where_bisection_is_slow():
    two = ["x", "y"]
    query = L.conjunction(_in_box(two, -1, 1), L.Compare(">=", _var("x"), E.Num(Fraction(1, 2))))
    falsifier = Falsifier(two, ([-1, -1], [1, 1]), seed=0)
    proved = Answer(Status.UNSAT)
    verifier = _Verifier(proved)
    assert falsifier.checked("decrease", query, 60, verifier) is proved  # two states, never slow
    assert verifier.budgets == [min(60, FIRST_SLICE)]
    assert falsifier.after("decrease", query, proved, SLOW_QUERY + 1) is proved
    found = falsifier.checked("decrease", query, 60, verifier)  # slow once: searched first
    assert found.status is Status.SAT and found.solver == SOLVER and len(verifier.budgets) == 1
    assert _exactly_true(query, two, [found.model[s] for s in two])
    assert FIRST_FROM_STATES <= 6
    six = _Verifier(proved)
    assert Falsifier(SIX, ([-2] * 6, [2] * 6), 0).checked(
        "boundary", _shell_sliver(), 60, six).status is Status.SAT and six.budgets == []
    # with Z3 (complete on polynomials, quick to find points) only after a slow query
    assert Falsifier(SIX, ([-2] * 6, [2] * 6), 0, bisecting=False).checked(
        "boundary", _shell_sliver(), 60, six) is proved


def test_a_verifier_without_an_answer_in_its_first_slice_is_searched_then_asked_again(
        monkeypatch):
    monkeypatch.setattr(falsify, "FIRST_SLICE", 0.2)
    two = ["x", "y"]
    unknown = Answer(Status.UNKNOWN, reason="timeout")
    failing = L.conjunction(_in_box(two, -1, 1), L.Compare(">=", _var("y"), E.Num(Fraction(9, 10))))
    verifier = _Verifier(unknown, slow=True)
    found = Falsifier(two, ([-1, -1], [1, 1]), seed=0).checked("decrease", failing, 3, verifier)
    assert found.status is Status.SAT and verifier.budgets == [0.2]  # not asked again
    impossible = L.conjunction(_in_box(two, -1, 1), L.Compare(">=", _var("y"), E.Num(2)))
    verifier = _Verifier(unknown, slow=True)
    assert Falsifier(two, ([-1, -1], [1, 1]), seed=0).checked(
        "decrease", impossible, 3, verifier) is unknown
    assert verifier.budgets[0] == 0.2 and 1 < verifier.budgets[1] < 2.8  # the rest
    quick = _Verifier(unknown)  # an UNKNOWN before the slice ends: not asked again
    Falsifier(two, ([-1, -1], [1, 1]), seed=0).checked("decrease", impossible, 3, quick)
    assert quick.budgets == [0.2]


def test_an_unknown_answer_becomes_a_counterexample_where_one_is_found():
    two = ["x", "y"]
    query = L.conjunction(_in_box(two, -1, 1), L.Compare(">=", _var("y"), E.Num(Fraction(9, 10))))
    falsifier = Falsifier(two, ([-1, -1], [1, 1]), seed=0)
    unknown = Answer(Status.UNKNOWN, reason="timeout")
    assert falsifier.after("initial", query, unknown, 1.0).status is Status.SAT
    impossible = L.conjunction(_in_box(two, -1, 1), L.Compare(">=", _var("y"), E.Num(2)))
    assert falsifier.after("initial", impossible, unknown, 1.0) is unknown
    assert "initial" not in falsifier.slow
