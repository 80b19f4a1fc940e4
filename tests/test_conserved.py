"""Conserved quantities (engine/first_integral.py) and the kernel's variant rule for
continuous-time safety, "B never increases in D" (kernel/safety_rules.py): an undamped
oscillator's safety, which no B that strictly decreases on its zero level set can show
(the flow preserves area), is certified; a B that does increase is not, by either rule."""
import json
from fractions import Fraction
from pathlib import Path

import fossil_dsl
from fossil_dsl.engine import first_integral
from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.atoms import folded, over_atoms
from fossil_dsl.kernel import Claim, judge
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.plan.compile import compile_spec

ROOT = Path(__file__).resolve().parent.parent

OSCILLATOR = """\
state x, y
dynamics continuous {
    x' = y
    y' = -x
}
domain box([-3, -3], [3, 3])
set init   = ball([0, 0], 0.5)
set unsafe = ~ball([0, 0], 2)
prove from init: always not unsafe
"""

# x'' = -x - x^3 (undamped Duffing): conserved 2y^2 + 2x^2 + x^4, a quartic
DUFFING = OSCILLATOR.replace("y' = -x", "y' = -x - x^3")

# an outward spiral: trajectories from I do leave the ball of radius 2
SPIRAL = OSCILLATOR.replace("x' = y", "x' = y + x / 10").replace("y' = -x", "y' = -x + y / 10")

UNICYCLE = """\
state x1, x2, x3
input u0, u1
dynamics continuous {
    x1' = u0*cos(x3)
    x2' = u0*sin(x3)
    x3' = u1
}
domain box([-10, -10, -6.28], [10, 10, 6.28])
set init   = box([-1, -1, -0.5], [1, 1, 0.5])
set unsafe = ~box([-5, -5, -3.14], [5, 5, 3.14])
prove from init: always not unsafe
"""

ROTATION = """\
state x, y
dynamics discrete {
    next(x) = 3/5*x - 4/5*y
    next(y) = 4/5*x + 3/5*y
}
domain box([-3, -3], [3, 3])
set init   = ball([0, 0], 0.5)
set unsafe = ~ball([0, 0], 2)
prove from init: always not unsafe
"""


def claim(text: str, b: E.Expr) -> Claim:
    return Claim(fossil_dsl.loads(text), {"B": b})


def circle(radius_squared) -> E.Expr:
    x, y = E.Var("x"), E.Var("y")
    return E.add(E.power(x, E.Num(2)), E.power(y, E.Num(2)), E.Num(-Fraction(radius_squared)))


def test_a_conjunction_with_a_false_comparison_of_numbers_is_false():
    x = E.Var("x")
    never = L.Compare(">", E.ZERO, E.ZERO)
    somewhere = L.Compare("<", x, E.Num(1))
    assert L.truth(L.conjunction(somewhere, never)) is False
    assert L.truth(L.disjunction(somewhere, never)) is None
    assert L.truth(L.disjunction(somewhere, L.negation(never))) is True


def test_the_kernel_proves_a_conserved_barrier_by_the_variant_rule():
    verdict = judge(claim(OSCILLATOR, circle(1)))
    assert verdict.certified, verdict.reason
    assert verdict.variant == "non-increasing B"
    names = [p.obligation.name for p in verdict.proofs]
    assert "condition:non-increasing" in names and "condition:flow" not in names
    assert "dB/dt <= 0 throughout D" in verdict.guarantee


def test_a_barrier_that_increases_is_refused_by_both_rules():
    verdict = judge(claim(SPIRAL, circle(1)))
    assert not verdict.certified
    assert "condition:flow" in verdict.reason  # the main rule's failure is reported


def test_the_main_rule_is_used_where_it_holds():
    damped = OSCILLATOR.replace("y' = -x", "y' = -x - y")
    x, y = E.Var("x"), E.Var("y")
    # V = x^2 + xy + y^2 decreases strictly away from 0 for x' = y, y' = -x - y
    b = E.add(E.power(x, E.Num(2)), E.mul(x, y), E.power(y, E.Num(2)), E.Num(-1))
    verdict = judge(claim(damped, b))
    assert verdict.certified and verdict.variant is None, verdict.reason


def test_the_conserved_functions_are_found_exactly():
    x, y = E.Var("x"), E.Var("y")
    duffing = [y, E.add(E.neg(x), E.neg(E.power(x, E.Num(3))))]
    quadratic = first_integral._candidates(duffing, ["x", "y"], 2)
    assert first_integral.conserved(quadratic, duffing, ["x", "y"], False) == []
    quartic = first_integral._candidates(duffing, ["x", "y"], 4)
    found = first_integral.conserved(quartic, duffing, ["x", "y"], False)
    energy = {(2, 0): Fraction(1), (0, 2): Fraction(1), (4, 0): Fraction(1, 2)}
    polynomials = [P.polynomial(h, ["x", "y"]) for h in found]
    assert any(h in (energy, P.scale(energy, -1)) for h in polynomials), polynomials
    # the pendulum's energy, with cos: its derivative is 0 over the atoms
    pendulum = [y, E.neg(E.apply("sin", x))]
    found = first_integral.conserved(first_integral._candidates(pendulum, ["x", "y"], 2),
                                     pendulum, ["x", "y"], False)
    assert len(found) == 1 and "cos(x)" in E.to_text(found[0]), found
    change = calculus.lie_derivative(found[0], ["x", "y"], pendulum)
    assert L.truth(folded(L.Compare(">", change, E.ZERO), ["x", "y"])) is False


def test_undamped_oscillators_safety_is_certified_and_rechecked(tmp_path):
    for text in (OSCILLATOR, DUFFING):
        result = fossil_dsl.synthesise(fossil_dsl.loads(text), timeout=60)
        assert result.certified, result.summary()
        assert result.strategy.startswith("a conserved quantity"), result.strategy
        assert result.kernel.variant == "non-increasing B"
        assert result.kernel.strengthened == "never leaves D"
    folder = tmp_path / "duffing"
    result.save(folder)
    data = json.loads((folder / "result.json").read_text())
    assert data["kernel"]["variant"] == "non-increasing B"
    checks = recheck(folder, timeout=30)
    assert checks and all(c.reproved for c in checks), checks


def test_an_undamped_pendulums_safety_is_certified_with_its_energy():
    text = OSCILLATOR.replace("y' = -x", "y' = -sin(x)")
    result = fossil_dsl.synthesise(fossil_dsl.loads(text), timeout=60)
    assert result.certified, result.summary()
    assert "cos(x)" in E.to_text(result.formulas["B"])
    assert result.kernel.variant == "non-increasing B"
    non_increasing = next(p for p in result.kernel.proofs
                          if p.obligation.name == "condition:non-increasing")
    assert non_increasing.procedure == "exact arithmetic"


def test_lotka_volterra_is_certified_with_its_logarithmic_integral():
    text = (ROOT / "specs/probe37/s06_lotka_volterra_safety.fsl").read_text()
    result = fossil_dsl.synthesise(fossil_dsl.loads(text), timeout=60)
    assert result.certified, result.summary()
    assert "log(x)" in E.to_text(result.formulas["B"])
    assert result.kernel.strengthened == "never leaves D"


def test_a_division_by_states_cancels_and_by_other_polynomials_does_not():
    x, y = E.Var("x"), E.Var("y")
    quotient, atoms = over_atoms(E.div(E.mul(x, x, y), E.mul(x, E.power(y, E.Num(2)))),
                                 ["x", "y"])
    assert atoms == [] and quotient == {(1, 0, 0, 1): Fraction(1)}  # x * y^-1
    # x / (x + 1) - 1 is not a number: no cancellation through a sum
    difference = E.add(E.div(x, E.add(x, E.ONE)), E.Num(-1))
    assert folded(L.Compare(">", difference, E.ZERO), ["x", "y"]) == \
        L.Compare(">", difference, E.ZERO)


def test_false_properties_of_conservative_systems_are_not_certified():
    for name in ("f18_pendulum_over_the_top", "f19_rigid_body_spin_transfer"):
        text = (ROOT / f"specs/false/{name}.fsl").read_text()
        result = fossil_dsl.synthesise(fossil_dsl.loads(text), timeout=10, max_iters=3)
        assert not result.certified, name


def test_an_outward_spiral_is_not_certified():
    plan = compile_spec(fossil_dsl.loads(SPIRAL))
    assert first_integral.applies(plan)
    assert first_integral.search(plan, float("inf")) is None  # nothing is conserved
    result = fossil_dsl.synthesise(fossil_dsl.loads(SPIRAL), timeout=10, max_iters=3)
    assert not result.certified


def test_a_drift_free_system_is_safe_with_its_inputs_held():
    result = fossil_dsl.synthesise(fossil_dsl.loads(UNICYCLE), timeout=60)
    assert result.certified, result.summary()
    assert result.sympy["u0"] == 0 and result.sympy["u1"] == 0
    assert result.kernel.variant == "non-increasing B"


def test_a_rotation_map_keeps_its_circles_by_the_main_rule():
    result = fossil_dsl.synthesise(fossil_dsl.loads(ROTATION), timeout=60)
    assert result.certified, result.summary()
    assert result.strategy.startswith("a conserved quantity")
    assert result.kernel.variant is None  # a map's rule is met by B(f(x)) = B(x)


def test_a_given_conserved_barrier_is_certified():
    text = OSCILLATOR + "synthesis {\n    candidate: x^2 + y^2 - 1\n}\n"
    result = fossil_dsl.synthesise(fossil_dsl.loads(text), timeout=30)
    assert result.certified, result.summary()
    assert result.kernel.variant == "non-increasing B"


def test_a_log_conserved_quantity_is_made_defined_where_the_domain_reaches_zero(tmp_path):
    # probe52/m05: the SIR system conserves s + i - 0.5 log(s), and D holds s = 0, where
    # log is undefined; s exp(-2 (s + i)) = exp(-2 H) is conserved and defined there
    spec = fossil_dsl.loads((ROOT / "specs/probe52/m05_sir_peak_safety.fsl").read_text())
    finding = first_integral.search(compile_spec(spec), float("inf"))
    assert finding is not None and "log" not in E.to_text(finding.formula)
    change = calculus.lie_derivative(finding.formula, ["s", "i"], spec.dynamics)
    assert L.truth(folded(L.Compare(">", change, E.ZERO), ["s", "i"])) is False
    assert L.truth(folded(L.Compare("<", change, E.ZERO), ["s", "i"])) is False
    result = fossil_dsl.synthesise(spec, timeout=60)
    assert result.certified, result.summary()
    assert result.strategy.startswith("a conserved quantity"), result.strategy
    result.save(tmp_path / "sir")
    checks = recheck(tmp_path / "sir", timeout=30)
    assert checks and all(c.reproved for c in checks), checks


def test_no_power_makes_logs_of_opposite_signs_defined_at_zero():
    assert first_integral._power_scale([Fraction(-1, 2)]) == -2
    assert first_integral._power_scale([Fraction(2, 3), Fraction(1, 2)]) == 6
    assert first_integral._power_scale([Fraction(1), Fraction(-1)]) is None
    assert first_integral._power_scale([Fraction(5)]) == Fraction(1, 5)
    assert first_integral._power_scale([Fraction(1), Fraction(7)]) is None  # x y^7


def test_shifted_lotka_volterra_is_certified_with_the_logs_of_its_invariant_lines(tmp_path):
    # probe75/ay34: u' = -(1 + u) v, v' = (1 + v) u conserves u - log(1 + u) + v - log(1 + v);
    # 1 + u divides u's own equation, so u = -1 is invariant and log(1 + u) a candidate
    spec = fossil_dsl.load(ROOT / "specs/probe75/ay34_lotka_volterra_cycle_safety.fsl")
    result = fossil_dsl.synthesise(spec, timeout=60)
    assert result.certified, result.summary()
    assert result.strategy.startswith("a conserved quantity")
    assert "log(u + 1)" in E.to_text(result.formulas["B"])
    result.save(tmp_path)
    checks = recheck(tmp_path, timeout=30)
    assert checks and all(c.reproved for c in checks), checks


def test_a_log_of_a_factor_is_a_candidate_only_where_it_keeps_one_sign_on_d():
    u, v = E.Var("u"), E.Var("v")
    one_plus = lambda s: E.add(s, E.ONE)  # noqa: E731
    field = [E.mul(E.Num(-1), one_plus(u), v), E.mul(one_plus(v), u)]
    found = first_integral._invariant_logs(field, ["u", "v"], ([-0.9, -0.9], [3, 3]))
    assert set(found) == {E.apply("log", one_plus(u)), E.apply("log", one_plus(v))}
    assert found[E.apply("log", one_plus(u))] == E.mul(E.Num(-1), v)
    # D reaches u = -1: log(1 + u) is undefined there, and no longer a candidate
    assert list(first_integral._invariant_logs(field, ["u", "v"], ([-1.2, -0.9], [3, 3]))) \
        == [E.apply("log", one_plus(v))]
    # u's equation without the factor: nothing
    assert first_integral._invariant_logs([v, u], ["u", "v"], ([-0.9, -0.9], [3, 3])) == {}


def test_a_false_property_of_the_shifted_lotka_volterra_cycle_is_not_certified():
    spec = fossil_dsl.load(ROOT / "specs/false/f133_lotka_volterra_cycle_reaches_low_prey.fsl")
    assert first_integral.search(compile_spec(spec), float("inf")) is None
    result = fossil_dsl.synthesise(spec, timeout=10, max_iters=3)
    assert not result.certified
