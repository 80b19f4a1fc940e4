"""Refutations slab by slab across one state (solvers/slab_split.py): found where the whole
query has none (a planar quadrotor's decrease), checked exactly against pieces the
checker makes itself, exported and read back; a split whose edges or slabs do not match
is rejected; a satisfiable query gets none; and the quadrotor is certified end to end."""
import json
import time
from fractions import Fraction as F
from pathlib import Path

import pytest

import fossil_dsl
from fossil_dsl.engine import quadratic_roa, region_attempts
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel import Claim, list_obligations
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.plan.compile import compile_spec
from fossil_dsl.solvers.evidence_json import refutation_from_json, refutation_json
from fossil_dsl.solvers.positivstellensatz import SlabSplit, refutation_problem, slabs
from fossil_dsl.solvers.slab_split import refuted_in_slabs, slab_variable
from fossil_dsl.solvers.sos_refutation import refute

ROOT = Path(__file__).resolve().parents[1]
QUADROTOR = ROOT / "specs" / "probe65" / "ao10_planar_quadrotor_stable_ctrl_6d.fsl"
STATES = ("a", "b", "c", "d")
A, B, C, D = (E.Var(s) for s in STATES)


def _n(value) -> E.Num:
    return E.Num(F(value))


def _taylor5(a: E.Expr) -> E.Expr:
    """a - a^3/6 + a^5/120, within a^7/5040 (7.1e-4 at 1.2) above sin a on [0, 1.2]."""
    return E.add(a, E.mul(_n(F(-1, 6)), E.power(a, _n(3))),
                 E.mul(_n(F(1, 120)), E.power(a, _n(5))))


def _query(margin: F) -> L.Formula:
    """sin(a) + b c <= a - a^3/6 + a^5/120 - margin with a in [0.3, 1.2] and b, c, d in
    [-1/20, 1/20] (b c >= -1/400): unsatisfiable for margin 1/100, satisfiable for
    margin -1/1000 (a = 0.3, b = c = 0)."""
    bounds = [L.Compare(">=", A, _n(F(3, 10))), L.Compare("<=", A, _n(F(6, 5)))]
    for v in (B, C, D):
        bounds += [L.Compare(">=", v, _n(F(-1, 20))), L.Compare("<=", v, _n(F(1, 20)))]
    left = E.add(E.apply("sin", A), E.mul(B, C))
    return L.conjunction(*bounds, L.Compare("<=", left, E.add(_taylor5(A), _n(-margin))))


@pytest.fixture(scope="module")
def quadrotor():
    """probe65/ao10's decrease obligation for the linearisation's quadratic V (6 states,
    sin and cos of the pitch th) and its refutation in slabs."""
    spec = fossil_dsl.load(QUADROTOR)
    plan = compile_spec(spec)
    finding = next(quadratic_roa.candidates(plan, time.monotonic() + 30))
    lemma = region_attempts.lemma_plan(plan, finding.formulas, finding.controller, finding.levels)
    claim = Claim(spec, dict(finding.formulas), dict(finding.controller),
                  dict(finding.levels), lemma.origin_radius)
    decrease = next(o for o in list_obligations(claim) if o.name == "condition:decrease")
    split = refuted_in_slabs(decrease.query, spec.states, time.monotonic() + 120)
    return decrease.query, spec.states, split


def test_a_query_refuted_only_in_slabs_and_checked_exactly(quadrotor):
    query, states, split = quadrotor
    assert slab_variable(query, states) == "th"
    # the facts over th's whole range are too loose: no refutation of the whole query
    assert refute(query, states, time.monotonic() + 30) is None
    assert isinstance(split, SlabSplit) and split.variable == "th"
    assert len(split.slabs) == len(split.edges) + 1 >= 5
    assert refutation_problem(split, query, states) is None
    again = refutation_from_json(json.loads(json.dumps(refutation_json(split, states))))
    assert again == split and refutation_problem(again, query, states) is None


def test_a_split_that_does_not_match_its_pieces_is_rejected(quadrotor):
    query, states, split = quadrotor
    first, second = split.edges[0], split.edges[1]
    moved = SlabSplit("th", (first + F(1, 10),) + split.edges[1:], split.slabs)
    assert refutation_problem(moved, query, states) is not None
    dropped = SlabSplit("th", split.edges[1:], split.slabs[1:])  # the first slab's piece
    assert refutation_problem(dropped, query, states) is not None  # now th <= e_2
    unordered = SlabSplit("th", (second, first) + split.edges[2:], split.slabs)
    assert "do not increase" in refutation_problem(unordered, query, states)
    other = SlabSplit("z9", split.edges, split.slabs)
    assert "not a state" in refutation_problem(other, query, states)


def test_the_pieces_cover_every_value_of_the_variable():
    pieces = slabs(L.TRUE, "a", [F(0), F(1, 2)])
    texts = [L.formula_text(p) for p in pieces]
    assert texts == ["a <= 0", "a >= 0 and a <= 0.5", "a >= 0.5"]


def test_a_satisfiable_query_has_no_slab_refutation():
    query = _query(F(-1, 1000))
    started = time.monotonic()
    assert refuted_in_slabs(query, STATES, started + 60) is None
    # it gives up at the first slab that stays unrefuted at the narrowest width
    assert time.monotonic() - started < 30


def test_no_slab_variable_where_functions_act_on_two_states_or_few_states():
    two = L.Compare("<=", E.add(E.apply("sin", A), E.apply("cos", B)), _n(0))
    assert slab_variable(two, STATES) is None
    one = L.Compare("<=", E.apply("sin", E.mul(_n(2), A)), _n(0))
    assert slab_variable(one, STATES) == "a"
    assert slab_variable(one, ("a", "b")) is None  # bisection handles 2 states


def test_the_planar_quadrotor_is_certified_through_slabs_and_rechecked(tmp_path):
    # probe65/ao10: 6 states, sin and cos of the pitch; not certified before slabs
    result = fossil_dsl.synthesise(fossil_dsl.load(QUADROTOR), timeout=200)
    assert result.certified
    evidence = result.refutations["condition:decrease"]
    assert isinstance(evidence, SlabSplit) and evidence.variable == "th"
    assert f"refuted in {len(evidence.slabs)} slabs across th" in result.summary()
    result.save(tmp_path)
    checks = recheck(tmp_path)
    assert all(check.reproved for check in checks)
