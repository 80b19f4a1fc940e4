"""The reach program where D outside G holds another equilibrium (engine/sos_reach.py):
no V decreases at rate γ there, so dV/dt <= λ V - γ is asked instead, the kernel's
condition wherever V <= 0. probe68/ar15: a FitzHugh-Nagumo neuron kicked past its
threshold fires (reaches G) while its rest state lies in D."""
import time
from pathlib import Path

import numpy as np

import fossil_dsl
from fossil_dsl.engine import sos_reach
from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.engine.polynomial_field import PolynomialField
from fossil_dsl.engine.reach_pieces import Pieces
from fossil_dsl.engine.reach_program import ReachProgram
from fossil_dsl.ir import polynomials as P
from fossil_dsl.plan.compile import compile_spec

SPECS = Path(__file__).resolve().parent.parent / "specs"
SPIKE = SPECS / "probe68/ar15_fitzhugh_nagumo_spike_reach.fsl"


def _feasible(plan, rate: float, half: int) -> bool:
    field = PolynomialField(2, [P.polynomial(f, plan.states) for f in plan.spec.dynamics],
                            P.constant(1, 2), [])
    program = ReachProgram(len(plan.states), field, Pieces(plan), half, False, rate)
    x = program.solve({program.margin: -1.0}, 60)
    return x is not None and x[program.margin] > sos_reach.MIN_MARGIN


def test_the_rest_state_rules_out_a_decrease_everywhere_but_not_where_v_is_negative():
    plan = compile_spec(fossil_dsl.load(SPIKE))
    assert not _feasible(plan, 0.0, 2) and not _feasible(plan, 0.0, 3)
    assert _feasible(plan, 1.0, 3)


def test_the_spike_is_certified_and_its_decrease_holds_only_where_v_is_negative():
    result = fossil_dsl.synthesise(fossil_dsl.load(SPIKE), timeout=60)
    assert result.certified and result.kernel.certified
    assert result.strategy.startswith("sum-of-squares") and "degree 6" in result.strategy
    rest = np.array([[-1.199, -0.624]])  # the rest state, near (-1.2, -0.62)
    assert float(evaluate(result.formulas["V"], state_env(("v", "w"), rest))[0]) > 0


def test_a_kick_below_threshold_is_not_certified_to_fire():
    """From v = -1.05 at rest's w the neuron returns to rest: G is never reached."""
    below = SPIKE.read_text().replace("set init = box([-0.4, -0.65], [-0.3, -0.6])",
                                      "set init = box([-1.1, -0.65], [-1, -0.6])")
    plan = compile_spec(fossil_dsl.loads(below))
    assert sos_reach.search(plan, time.monotonic() + 60) is None
    result = fossil_dsl.synthesise(fossil_dsl.loads(below), timeout=20, max_iters=2)
    assert not result.certified
