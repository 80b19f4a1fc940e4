"""The interval procedure resumes a search that its deadline stopped when the same query
is asked again (the loop's falsifier asks a slow query twice: a first slice, then the
rest), and only then: another query in between starts afresh; the answers are the ones a
single uninterrupted search gives, UNSAT and SAT alike."""
from fractions import Fraction as F

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.interval_backend import IntervalBackend

X, Y, Z = (E.Var(s) for s in "xyz")
STATES = ["x", "y", "z"]


def _n(value) -> E.Num:
    return E.Num(F(value))


def _query(weight: F) -> L.Formula:
    """-|x|^2 + weight (x + y + z)^2 + sin(x y z)/10 >= 0 on the box [-1, 1]^3 outside the
    ball of 1/100: unsatisfiable for weight 3/10 (takes a few thousand boxes),
    satisfiable for 7/20 (along (1, 1, 1): 0.05 |x|^2 > 0)."""
    square = E.add(*(E.power(v, _n(2)) for v in (X, Y, Z)))
    g = E.add(E.neg(square), E.mul(E.Num(weight), E.power(E.add(X, Y, Z), _n(2))),
              E.mul(_n(F(1, 10)), E.apply("sin", E.mul(X, Y, Z))))
    box = [c for v in (X, Y, Z) for c in (L.Compare(">=", v, _n(-1)), L.Compare("<=", v, _n(1)))]
    return L.conjunction(*box, L.Compare(">", square, _n(F(1, 10000))),
                         L.Compare(">=", g, _n(0)))


def test_a_stopped_search_resumes_where_it_stopped_and_proves_the_query():
    backend, query = IntervalBackend(), _query(F(3, 10))
    first = backend.check(query, STATES, 0.001)
    assert first.status is Status.UNKNOWN and "timeout" in first.reason
    assert backend._paused is not None and backend._paused[0][0] == query
    assert backend.check(query, STATES, 60).status is Status.UNSAT
    assert backend._paused is None


def test_another_query_in_between_is_not_resumed_into_and_starts_afresh():
    backend, query, other = IntervalBackend(), _query(F(3, 10)), _query(F(2, 10))
    assert backend.check(query, STATES, 0.001).status is Status.UNKNOWN
    assert backend.check(other, STATES, 60).status is Status.UNSAT
    assert backend._paused is None
    assert backend.check(query, STATES, 60).status is Status.UNSAT


def test_a_satisfiable_query_is_still_found_satisfiable_after_a_pause():
    backend, query = IntervalBackend(), _query(F(7, 20))
    first = backend.check(query, STATES, 0.001)
    answer = first if first.status is Status.SAT else backend.check(query, STATES, 60)
    assert answer.status is Status.SAT
    point = [float(answer.model[s]) for s in STATES]
    assert sum(v * v for v in point) > 1e-4
