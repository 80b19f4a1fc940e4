"""A field with functions in polynomial form on cells of the domain
(engine/polynomial_field.celled_field): on each cell the applications' facts are those
of the narrow ranges their arguments take there (Taylor polynomials within ε for tanh,
solvers/taylor_facts.py), so a reach program can ask V's decrease for every value the
facts allow and still find one where D's facts, a sector through the origin, leave none.
probe77/ba11: a two-neuron tanh network x+ = tanh(1.1 x + 0.5 y), y+ = tanh(-0.4 x +
0.9 y) + 0.5 u, unstable at the origin, driven to G without x falling to -0.7."""
import math
from pathlib import Path

import numpy as np

import fossil_dsl
from fossil_dsl.engine import sos_reach
from fossil_dsl.engine.polynomial_field import MAX_CELLS, celled_field, exact_field
from fossil_dsl.engine.quadratic_shapes import lqr_controllers
from fossil_dsl.engine.reach_pieces import Pieces
from fossil_dsl.engine.reach_program import ReachProgram
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.plan.compile import compile_spec

NETWORK = Path(__file__).resolve().parent.parent / \
    "specs/probe77/ba11_dissipative_tanh_rnn_rwa_ctrl.fsl"


def _closed_loop():
    plan = compile_spec(fossil_dsl.load(NETWORK))
    controller, gain = next(iter(lqr_controllers(plan, np.zeros(1),
                                                 np.random.default_rng(0))))
    closed = [traversal.substitute(f, controller) for f in plan.spec.dynamics]
    return plan, closed, gain


def _value(p, point) -> float:
    return sum(float(c) * math.prod(v ** k for v, k in zip(point, m)) for m, c in p.items())


def test_every_cell_s_facts_hold_at_the_true_values_of_tanh():
    plan, closed, gain = _closed_loop()
    field = celled_field(plan, closed)
    assert field is not None and len(field.cells) == MAX_CELLS  # 8 x 8 in 2 states
    rng = np.random.default_rng(1)
    (k1, k2), = gain
    for bounds, constraints in field.cells:
        for _ in range(20):
            x, y = (rng.uniform(float(lo), float(hi)) for lo, hi in bounds)
            point = (x, y, math.tanh(1.1 * x + 0.5 * y), math.tanh(-0.4 * x + 0.9 * y))
            assert all(_value(g, point) >= -1e-9 for g in constraints), (bounds, point)
        # and the numerators are the map's, with t1, t2 for the two tanh
        assert abs(_value(field.numerators[1], point) - (point[3] + 0.5 * (k1 * x + k2 * y))) \
            < 1e-9


def _margin(plan, field) -> float | None:
    program = ReachProgram(len(plan.states), field, Pieces(plan), 2, True)
    x = program.solve({program.margin: -1.0}, 120)
    return None if x is None else x[program.margin]


def test_the_cells_facts_admit_a_v_where_the_domain_s_do_not():
    plan, closed, _ = _closed_loop()
    whole, celled = exact_field(plan, closed), celled_field(plan, closed)
    assert not whole.cells and not P.degree(whole.denominator)
    assert _margin(plan, whole) < sos_reach.MIN_MARGIN  # the sector: no quartic V
    assert _margin(plan, celled) > 0.1


def test_the_tanh_network_is_certified_by_the_celled_program():
    result = fossil_dsl.synthesise(fossil_dsl.load(NETWORK), seed=0, timeout=120)
    assert result.certified and result.kernel.certified, result.summary()
    assert "cells of D" in result.strategy, result.strategy


def test_a_v_found_with_the_facts_gets_the_stand_in_s_longer_queries():
    # probe76/az24: its quartic V's decrease was 9 boxes short of a proof after 5 s
    import time
    from dataclasses import replace
    from fossil_dsl.engine.proving import STAND_IN_QUERY_SECONDS, budgets
    finding = sos_reach.ReachFinding({}, {}, None, np.zeros(0), 4, 0.08, 2.0, {},
                                     abstracted=True)
    deadline = time.monotonic() + 100
    assert budgets(finding, 5.0, deadline)[1] >= STAND_IN_QUERY_SECONDS
    assert budgets(replace(finding, abstracted=False), 5.0, deadline)[1] \
        < STAND_IN_QUERY_SECONDS
