"""Split verification (issue 26): a query is proved from its pieces only if the pieces
cover the whole space (checked exactly) and every piece is refuted; the first piece with
a point gives the counterexample."""
from __future__ import annotations

import json
import math
from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.cluster.pieces import LocalPieces
from fossil_dsl.engine.split import SplitBackend
from fossil_dsl.frontends.cli import main
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel import cover
from fossil_dsl.kernel.obligations import Obligation
from fossil_dsl.kernel.prove import discharge
from fossil_dsl.solvers.api import Answer, Status
from fossil_dsl.solvers.interval_backend import IntervalBackend

X, Y = E.Var("x"), E.Var("y")
STATES = ["x", "y"]


def _fact(bound: Fraction) -> L.Formula:
    """x^2 - x y + y^2 + sin(x)/10 <= bound on the annulus 1/2 <= |x|^2 <= 1."""
    radius = E.add(E.mul(X, X), E.mul(Y, Y))
    value = E.add(E.mul(X, X), E.neg(E.mul(X, Y)), E.mul(Y, Y),
                  E.mul(E.Num(Fraction(1, 10)), E.Apply("sin", X)))
    return L.conjunction(L.Compare(">=", radius, E.Num(Fraction(1, 2))),
                         L.Compare("<=", radius, E.Num(1)),
                         L.Compare("<=", value, E.Num(bound)))


# the quadratic form is at least |x|^2 / 2 >= 1/4, sin(x)/10 >= -0.085: no point ...
TRUE_FACT = _fact(Fraction(1, 20))
# ... but it is 1/4 - 0.065 at x = y = 1/2 (the form's smallest direction): points
FALSE_FACT = _fact(Fraction(3, 10))


@pytest.fixture(scope="module")
def checker():
    pieces = LocalPieces(2)
    yield pieces
    pieces.close()


sides = st.tuples(st.fractions(-10, 10), st.fractions(Fraction(1, 100), 10))


@settings(max_examples=50, deadline=None)
@given(st.lists(sides, min_size=1, max_size=4), st.integers(1, 20))
def test_a_bisection_covers_its_hull_and_any_gap_or_overlap_is_found(hull_sides, count):
    hull = tuple((low, low + width) for low, width in hull_sides)
    boxes = cover.bisected(hull, count)
    assert len(boxes) >= count and cover.covers(hull, boxes) == ""
    if len(boxes) > 1:
        assert cover.covers(hull, boxes[1:]) != ""  # a gap
        assert cover.covers(hull, boxes + [boxes[0]]) != ""  # an overlap
    shrunk = ((hull[0][0], (hull[0][0] + hull[0][1]) / 2),) + hull[1:]
    assert cover.covers(hull, [shrunk]) != ""  # half of it


def test_the_pieces_are_the_boxes_and_the_outside_of_the_hull():
    hull = ((Fraction(-1), Fraction(1)), (Fraction(-1), Fraction(1)))
    boxes = cover.bisected(hull, 4)
    regions = cover.regions(STATES, hull, boxes)
    assert len(regions) == 5
    point = {"x": E.Num(Fraction(1, 2)), "y": E.Num(Fraction(1, 2))}
    assert [L.truth(L.substitute(r, point)) for r in regions].count(True) == 1
    assert L.truth(L.substitute(regions[-1], point)) is False  # not outside H


def test_the_kernel_proves_a_true_fact_from_its_pieces(checker):
    proof = discharge(Obligation("fact", "a fact", TRUE_FACT), STATES, 30.0, pieces=checker)
    assert proof.proved
    assert proof.procedure == f"interval, split into {checker.pieces + 1} pieces"


def test_the_kernel_does_not_prove_a_false_fact_and_names_a_point(checker):
    proof = discharge(Obligation("fact", "a fact", FALSE_FACT), STATES, 30.0, pieces=checker)
    assert not proof.proved and proof.witness is not None
    x, y = map(float, proof.witness)
    assert 0.5 - 1e-3 <= x * x + y * y <= 1 + 1e-3  # a point of the query (up to delta)
    assert x * x - x * y + y * y + math.sin(x) / 10 <= 0.3 + 1e-3


class Silent:
    """A checker that answers no piece (or too few): never a proof."""
    pieces = 4

    def check_all(self, query, regions, names, timeout, delta=None):
        return [Answer(Status.UNSAT)] * (len(regions) - 1)


def test_a_checker_that_leaves_a_piece_unanswered_proves_nothing():
    proof = discharge(Obligation("fact", "a fact", FALSE_FACT), STATES, 30.0, pieces=Silent())
    assert not proof.proved and "answers for" in proof.detail
    answer = SplitBackend(IntervalBackend(), Silent()).check(FALSE_FACT, STATES, 30.0)
    assert answer.status is Status.UNKNOWN


def test_the_loop_backend_returns_a_point_of_a_piece(checker):
    answer = SplitBackend(IntervalBackend(), checker).check(FALSE_FACT, STATES, 30.0)
    assert answer.status is Status.SAT and set(answer.model) == set(STATES)
    assert SplitBackend(IntervalBackend(), checker).check(TRUE_FACT, STATES, 30.0).status \
        is Status.UNSAT


def test_split_run_end_to_end(tmp_path, capsys):
    """`fossilc SPEC --split 2` on a spec with sin: certified, the kernel's proofs name
    the split, and `fossilc recheck` re-proves the exported obligations."""
    spec = "specs/literature/lit01_damped_pendulum.fsl"
    assert main([spec, "--split", "2", "-o", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    procedures = [o["procedure"] for o in data["kernel"]["obligations"]]
    assert any(p.startswith("interval, split into") for p in procedures), procedures
    assert main(["recheck", str(tmp_path)]) == 0


def test_a_dead_piece_worker_is_replaced_and_never_proves_anything():
    pieces = LocalPieces(1)
    try:
        hull = cover.hull_of(TRUE_FACT, STATES)
        regions = cover.regions(STATES, hull, cover.bisected(hull, 2))
        assert all(a.status is Status.UNSAT
                   for a in pieces.check_all(TRUE_FACT, regions, STATES, 30.0))
        worker = pieces._started[0]
        worker.process.kill()
        worker.process.wait()
        # a dead worker answers UNKNOWN for what it was asked ...
        assert worker.ask({"id": 0}).status is Status.UNKNOWN
        # ... and the next query starts a fresh one
        assert all(a.status is Status.UNSAT
                   for a in pieces.check_all(TRUE_FACT, regions, STATES, 30.0))
        assert pieces._started[0] is not worker
    finally:
        pieces.close()
