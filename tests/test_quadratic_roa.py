"""A region of attraction from the linearisation (engine/quadratic_roa.py): V = x^T P x
from the Lyapunov equation (or the ellipsoid between I and D), β just over V's largest
value on I, checked on samples and proved like any candidate."""
from fractions import Fraction
from pathlib import Path

import numpy as np
import sympy

import fossil_dsl
from fossil_dsl.engine import quadratic_roa
from fossil_dsl.ir.symbolic import to_sympy
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.plan.compile import compile_spec

ROOT = Path(__file__).resolve().parent.parent
NEURON = ROOT / "specs" / "probe53" / "n01_fitzhugh_nagumo_roa.fsl"


def _candidates(path: Path) -> list:
    plan = compile_spec(fossil_dsl.load(path))
    assert quadratic_roa.applies(plan)
    return list(quadratic_roa.candidates(plan, float("inf")))


def test_an_excitable_neurons_rest_is_certified_with_the_lyapunov_equations_v(tmp_path):
    """probe53/n01: FitzHugh-Nagumo at rest. Learning timed out (120 s): its level,
    halfway between I and ∂D, took in states that fire. The Lyapunov equation's V on
    its smallest sublevel set holding I is proved at once, with no ball left out."""
    result = fossil_dsl.synthesise(fossil_dsl.load(NEURON), seed=0, timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("the linearisation's quadratic V")
    assert "ε-stability" not in result.kernel.guarantee
    beta = result.levels["beta"]
    V = result.sympy["V"]
    x, y = sorted(V.free_symbols, key=str)
    on_init = max(float(V.subs({x: 0.12 * np.cos(a), y: 0.12 * np.sin(a)}))
                  for a in np.linspace(0, 2 * np.pi, 200))
    assert on_init <= beta <= 1.05 * on_init  # the smallest Ω, not halfway to ∂D
    result.save(tmp_path / "neuron")
    checks = recheck(tmp_path / "neuron", timeout=30)
    assert checks and all(c.reproved for c in checks), checks


def test_the_level_is_just_over_the_largest_value_on_i():
    found = _candidates(NEURON)[0]
    assert isinstance(found.levels["beta"], Fraction) and found.controller == {}
    assert found.describe().startswith("the linearisation's quadratic V on its smallest")


def test_a_pendulum_on_a_cart_gets_the_ellipsoid_between_i_and_d_and_its_gain():
    """probe53/n06: every LQR Lyapunov ellipsoid is flat, so each sublevel set that
    holds the ball I leaves D; the ellipsoid program's P and gain fit."""
    path = ROOT / "specs" / "probe53" / "n06_pendulum_on_cart_stab_ctrl_4d.fsl"
    found = _candidates(path)
    assert found and all(set(f.controller) == {"u"} for f in found)
    result = fossil_dsl.synthesise(fossil_dsl.load(path), seed=0, timeout=90)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("the linearisation's quadratic V and a linear controller")


def test_false_regions_of_attraction_get_no_candidate():
    """Initial sets past a separatrix or an equilibrium, a Van der Pol initial set past
    its cycle, and an unstable focus (f38): decrease fails on samples of every Ω. Since
    systems without inputs have the ellipsoid between I and D too, also a chemostat's I
    reaching its washout line (f79) and a map with an unstable fixed point (f81)."""
    for name in ("f04_vdp_big_init", "f16_init_past_separatrix", "f22_roa_past_equilibrium",
                 "f34_kuramoto_splay_in_init", "f38_fitzhugh_nagumo_antidamped",
                 "f79_chemostat_washout_line_roa", "f81_ricker_delay_map_unstable_roa"):
        assert _candidates(ROOT / "specs" / "false" / f"{name}.fsl") == [], name


def test_an_unstable_focus_is_not_certified():
    spec = fossil_dsl.load(ROOT / "specs" / "false" / "f38_fitzhugh_nagumo_antidamped.fsl")
    assert not fossil_dsl.synthesise(spec, seed=0, timeout=15, max_iters=2).certified


def test_largest_region_runs_keep_their_basin_attempt():
    plan = compile_spec(fossil_dsl.load(ROOT / "specs" / "roa_largest.fsl"))
    assert not quadratic_roa.applies(plan)


def test_stable_while_avoid_takes_b_as_v_minus_its_level():
    """lit13: a pendulum's SWA. Ω = {V <= β} cannot be left and misses U, so B = V - β
    is a barrier; every condition is proved by exact refutations."""
    path = ROOT / "specs" / "literature" / "lit13_pendulum_swa.fsl"
    found = _candidates(path)[0]
    assert set(found.formulas) == {"V", "B"}
    result = fossil_dsl.synthesise(fossil_dsl.load(path), seed=0, timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("the linearisation's quadratic V")
    V, B = result.sympy["V"], result.sympy["B"]
    assert sympy.nsimplify(V - B) == sympy.Rational(str(result.levels["beta"]))


def test_an_swa_whose_omega_meets_u_gets_no_candidate():
    """f26 (false): orbits round a centre from I pass through U; the linearisation is
    not asymptotically stable, and no Ω of a quadratic misses U while holding I."""
    assert _candidates(ROOT / "specs" / "false" / "f26_swa_center.fsl") == []


SATURATED = ROOT / "specs" / "probe58" / "ab04_saturated_double_integrators_rwa_ctrl_4d.fsl"


def _reach_candidates(path: Path) -> list:
    plan = compile_spec(fossil_dsl.load(path))
    assert quadratic_roa.reaches(plan) and not quadratic_roa.applies(plan)
    return list(quadratic_roa.candidates(plan, float("inf")))


def test_saturated_actuators_get_a_reach_v_from_the_ellipsoid_with_a_small_gain(tmp_path):
    """probe58/ab04: two sampled double integrators behind tanh(u), RWA (timeout in
    120 s before). The ellipsoid of the default gain weight has |u| up to 1.6, where
    tanh bends and V grows; the one with gain weight 0.1 keeps |u| <= 0.8, and V = k
    (x^T P x - β) falls by 10 γ at its samples. Its decrease is refuted with tanh's
    sector over the range of -K x on {V <= 0} (atom_facts.py)."""
    found = _reach_candidates(SATURATED)
    assert found and set(found[0].formulas) == {"V"} and set(found[0].controller) == {"u1", "u2"}
    assert found[0].levels == {}
    result = fossil_dsl.synthesise(fossil_dsl.load(SATURATED), seed=0, timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    # since session 77 the reach program with tanh's facts finds a quadratic V first
    assert result.strategy.startswith(("the linearisation's quadratic V and a linear controller",
                                       "sum-of-squares programming")), result.strategy
    result.save(tmp_path / "saturated")
    checks = recheck(tmp_path / "saturated", timeout=30)
    assert checks and all(c.reproved for c in checks), checks


def test_the_ellipsoid_keeps_out_of_an_unsafe_half_space():
    """ab04's U = {p1 + p2 >= 2.5}: a'Q a <= s b^2 puts the ellipsoid {x^T P x <= 1}
    (which holds I's corners with p1 = p2 = 1.1) strictly on the safe side."""
    from fossil_dsl.engine.ellipsoid_seed import ellipsoids
    from fossil_dsl.engine.linear import jacobians, operating_point
    spec = fossil_dsl.load(SATURATED)
    A, B = jacobians(spec, operating_point(spec))
    shapes = list(ellipsoids(A, B, spec, discrete=True))
    assert len(shapes) >= 2  # one per gain weight that has an ellipsoid inside D
    a = np.array([1.0, 0.0, 1.0, 0.0])
    for P, _ in shapes:
        assert np.sqrt(a @ np.linalg.inv(P) @ a) < 2.5  # max of p1 + p2 on the ellipsoid


def test_false_reach_properties_get_no_reach_candidate():
    """A goal beside the equilibrium, a wall across the way, an uncontrollable mode:
    no Ω of a quadratic both holds I and lies in S with V falling outside G."""
    for name in ("f05_rwa_wrong_goal", "f24_rwa_wall", "f52_uncontrollable_mode_rwa",
                 "f70_offset_equilibrium_rwa"):
        assert _reach_candidates(ROOT / "specs" / "false" / f"{name}.fsl") == [], name


def test_a_saturated_force_gets_the_ellipsoid_whose_inputs_stay_in_tanhs_linear_range():
    """probe63/ak04 (two carts on a hardening spring, the first pushed through tanh(u),
    RWA): on the ellipsoid of gain weight 0.1, |u| reaches 1.1, where tanh's sector
    [0.73, 1] lets dV/dt reach +0.009 at samples and the refutation fails; with weight 1,
    |u| <= 0.25 and the sector [0.98, 1] holds the decrease, refuted by sum of squares
    or, since session 68, by the interval verifier's Taylor forms (not certified in
    120 s before)."""
    path = ROOT / "specs" / "probe63" / "ak04_saturated_cart_rwa_ctrl_4d.fsl"
    result = fossil_dsl.synthesise(fossil_dsl.load(path), seed=0, timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("the linearisation's quadratic V and a linear controller")
    by_name = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert by_name["condition:decrease"] in ("sum of squares (exact)", "taylor"), by_name


CARTS = ROOT / "specs" / "probe64" / "am04_coupled_sampled_carts_rar_ctrl_4d.fsl"


def test_reach_avoid_remain_gets_v_and_b_from_one_quadratic(tmp_path):
    """probe64/am04, two sampled carts on a spring (4 states, two inputs, one behind
    tanh): RAR timed out in 120 s before session 64 (maps have no RAR program). The
    quadratic's Ω gives V = k (x^T P x - β), and its sublevel set just holding G, inside
    F, gives B. (Its decrease, with tanh, is proved by the interval procedure;
    `fossilc recheck` re-proves it with Arb in about 50 s: too long for a test.)"""
    found = _reach_candidates(CARTS)
    assert found and set(found[0].formulas) == {"V", "B"}, found
    result = fossil_dsl.synthesise(fossil_dsl.load(CARTS), seed=0, timeout=90)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("the linearisation's quadratic V and a linear controller")
    by_name = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert by_name["condition:barrier_invariance"] == "sum of squares (exact)", by_name


def test_b_is_left_out_where_its_sublevel_set_cannot_hold_g_inside_f():
    """F a ball barely larger than G: no ellipse of the quadratic (not a circle) holds
    G and lies in F, so there is no candidate, though V alone would pass."""
    text = CARTS.read_text().replace("set stay = ball([0, 0, 0, 0], 0.4)",
                                     "set stay = ball([0, 0, 0, 0], 0.16)")
    plan = compile_spec(fossil_dsl.loads(text))
    assert quadratic_roa.reaches(plan)
    assert list(quadratic_roa.candidates(plan, float("inf"))) == []


def test_false_reach_avoid_remain_properties_get_no_candidate():
    for name in ("f10_rar_no_remain", "f77_exp_feedback_map_leaves_stay_rar"):
        assert _reach_candidates(ROOT / "specs" / "false" / f"{name}.fsl") == [], name


SAMPLED_CHAIN = ROOT / "specs" / "probe74" / "ax33_sine_map_rar_ctrl_3d.fsl"


def test_reach_avoid_remain_takes_b_from_the_ellipsoid_between_g_and_f():
    """probe74/ax33, a sampled 3-state chain with sin: no LQR shape has a sublevel set
    holding G's ball of 0.2 inside F's of 0.4 (timeout in 120 s before session 74). The
    ellipsoid program between G and F gives B and a gain; V is that gain's Lyapunov
    quadratic. B's sublevel set holds G and lies in F: checked at points of both."""
    found = _reach_candidates(SAMPLED_CHAIN)
    assert found and set(found[0].formulas) == {"V", "B"}, found
    x, y, z = symbols = sympy.symbols("x y z")
    B = to_sympy(found[0].formulas["B"], dict(zip("xyz", symbols)))
    rng = np.random.default_rng(0)
    for direction in rng.normal(size=(200, 3)):
        unit = direction / np.linalg.norm(direction)
        on_goal = dict(zip((x, y, z), 0.2 * unit))
        past_final = dict(zip((x, y, z), 0.4 * unit))
        assert B.subs(on_goal) <= 0 < B.subs(past_final)


def test_the_ellipsoid_between_g_and_f_is_refused_where_no_gain_keeps_one():
    """F barely larger than G: the program has no invariant ellipsoid between them."""
    text = SAMPLED_CHAIN.read_text().replace("set F = ball([0, 0, 0], 0.4)",
                                             "set F = ball([0, 0, 0], 0.21)")
    plan = compile_spec(fossil_dsl.loads(text))
    assert list(quadratic_roa.candidates(plan, float("inf"))) == []


def test_continuous_reach_avoid_remain_with_functions_tries_the_quadratic_first():
    """probe74/ax29 (exp in the field): the program for a polynomial stand-in took 19 s
    where the linearisation's quadratic V and B are proved in under a second; polynomial
    fields keep the program first."""
    from fossil_dsl.engine import sos_reach
    gain = compile_spec(fossil_dsl.load(ROOT / "specs/probe74/ax29_exp_gain_rar_3d.fsl"))
    assert sos_reach.applies_late(gain) and not sos_reach.applies(gain)
    polynomial = compile_spec(fossil_dsl.load(ROOT / "specs/rar_continuous.fsl"))
    assert sos_reach.applies(polynomial) and not sos_reach.applies_late(polynomial)
    result = fossil_dsl.synthesise(gain.spec, seed=0, timeout=60)
    assert result.certified and result.strategy.startswith("the linearisation's quadratic V")


def test_reach_and_stay_gets_v_and_its_level_from_the_linearisations_quadratic():
    """probe74/ax35, a double integrator under -tanh(x + 2y): the reach program has no
    polynomial stand-in for tanh over D (it saturates); before session 74 RSWA had no
    quadratic attempt and was left to learning. V = k (x^T P x - level) with β just
    inside F's boundary, so that {V <= β} lies in F."""
    path = ROOT / "specs/probe74/ax35_tanh_policy_settle_far_limit.fsl"
    found = _reach_candidates(path)
    assert found and set(found[0].formulas) == {"V"} and "beta" in found[0].levels
    x, y = symbols = sympy.symbols("x y")
    V = to_sympy(found[0].formulas["V"], dict(zip("xy", symbols)))
    beta = found[0].levels["beta"]
    circle = np.linspace(0, 2 * np.pi, 100)
    assert max(V.subs({x: 0.8 + 0.2 * np.cos(a), y: 0.2 * np.sin(a)}) for a in circle) <= 0
    assert min(V.subs({x: 0.3 * np.cos(a), y: 0.3 * np.sin(a)}) for a in circle) > beta
    result = fossil_dsl.synthesise(fossil_dsl.load(path), seed=0, timeout=60)
    assert result.certified and result.strategy.startswith("the linearisation's quadratic V")


def test_false_reach_and_stay_properties_get_no_candidate():
    for name in ("f06_rswa_leaves", "f49_tanh_map_rswa_overshoot",
                 "f112_final_set_beside_the_equilibrium_rswa", "f119_center_never_settles"):
        assert _reach_candidates(ROOT / "specs" / "false" / f"{name}.fsl") == [], name
