"""The sum-of-squares first attempt: a Lyapunov function for polynomial systems from a
semidefinite program (Clarabel), rounded to rationals and proved like any candidate."""
import time
from pathlib import Path

import pytest
import sympy

import fossil_dsl
from fossil_dsl.engine import first_integral, sos, sos_barrier
from fossil_dsl.plan.compile import compile_spec

# Khalil's Example 4.? style: a polynomial system with a cubic coupling, 3 states
THREE_STATES = """\
state x, y, z
dynamics continuous {
    x' = -x + y*z - x^3
    y' = -2*y - x*z
    z' = -z + x*y - z^3
}
domain ball([0, 0, 0], 2)
prove stable
"""

ROA = """\
state x, y
dynamics continuous {
    x' = -x + x*y
    y' = -y + x^2
}
domain box([-0.8, -0.8], [0.8, 0.8])
set I = ball([0.2, 0.1], 0.1)
prove from I: stable
"""


def _plan(text: str, **options):
    return compile_spec(fossil_dsl.loads(text), **options)


def test_a_polynomial_system_is_certified_by_sum_of_squares_without_learning():
    result = fossil_dsl.synthesise(fossil_dsl.loads(THREE_STATES), timeout=120)
    assert result.certified and result.kernel.certified
    assert result.strategy.startswith("sum-of-squares programming")
    assert result.learn_seconds < 0.01 and result.networks == {}
    V = result.sympy["V"]
    x, y, z = sorted(V.free_symbols, key=str)
    assert sympy.Poly(V, x, y, z).total_degree() in (2, 4)
    assert "found by: sum-of-squares" in result.summary()


def test_region_of_attraction_takes_the_sos_function_and_a_sampled_level():
    result = fossil_dsl.synthesise(fossil_dsl.loads(ROA), timeout=120)
    assert result.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares")
    assert "beta" in result.levels


def test_the_program_is_infeasible_for_an_unstable_system():
    unstable = THREE_STATES.replace("x' = -x + y*z - x^3", "x' = x + y*z")
    plan = _plan(unstable)
    assert sos.applies(plan)
    assert sos.lyapunov(plan, time.monotonic() + 30) is None
    result = fossil_dsl.synthesise(fossil_dsl.loads(unstable), max_iters=1, timeout=60)
    assert not result.certified  # refuted at once: the linearisation has eigenvalue 1
    assert "the origin is unstable" in result.reason


@pytest.mark.parametrize("change, why", [
    (("x' = -x + y*z - x^3", "x' = -sin(x) + y*z"), "not polynomial"),
    (("prove stable", "prove stable\nsynthesis {\n    certificate: square(4)\n}"),
     "the user chose a template"),
    (("prove stable", "prove stable\nsynthesis {\n    candidate: x^2 + y^2 + z^2\n}"),
     "the user gave a candidate"),
])
def test_the_attempt_is_skipped_where_it_does_not_apply(change, why):
    assert not sos.applies(_plan(THREE_STATES.replace(*change))), why


def test_the_found_function_is_rounded_to_rationals_and_positive_definite():
    plan = _plan(THREE_STATES)
    finding = sos.lyapunov(plan, time.monotonic() + 30)
    assert finding is not None and finding.margin > 0
    from fossil_dsl.ir.symbolic import to_sympy
    V = to_sympy(finding.formula)
    assert all(isinstance(c, sympy.Rational) for c in sympy.Poly(V).coeffs())
    x, y, z = sorted(V.free_symbols, key=str)
    hessian = sympy.hessian(V, (x, y, z)).subs({x: 0, y: 0, z: 0})
    assert all(value > 0 for value in hessian.eigenvals())


RING_6 = """\
state a, b, c, d, e, f
dynamics continuous {
    a' = -a + 0.4*b - a^3
    b' = -b + 0.4*c - b^3
    c' = -c + 0.4*d - c^3
    d' = -d + 0.4*e - d^3
    e' = -e + 0.4*f - e^3
    f' = -f + 0.4*a - f^3
}
domain ball([0, 0, 0, 0, 0, 0], 1)
prove stable
"""


def test_six_states_are_proved_by_refutations_that_export_recheck_and_load(tmp_path):
    """The kernel proves the conditions from sum-of-squares refutations (checked
    exactly), writes them next to the SMT-LIB files, recheck checks them again, and a
    tampered one is not accepted when the result is loaded."""
    import json
    from fossil_dsl.outputs.recheck import recheck
    result = fossil_dsl.synthesise(fossil_dsl.loads(RING_6), timeout=120)
    assert result.certified, result.summary()
    procedures = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert procedures["condition:decrease"] == "sum of squares (exact)"
    result.save(tmp_path)
    exported = tmp_path / "obligations" / "condition-decrease.sos.json"
    assert exported.exists()
    checks = {c.condition: c for c in recheck(tmp_path, timeout=5)}
    assert checks["condition-decrease"].reproved
    assert checks["condition-decrease"].solver.startswith("sum of squares")
    assert fossil_dsl.load_result(tmp_path).certified
    data = json.loads(exported.read_text())
    data["rest"]["gram"][0][0] = str(-1)  # no longer positive semidefinite
    exported.write_text(json.dumps(data))
    from fossil_dsl.kernel.prove import GIVEN_REFUTATION
    from fossil_dsl.outputs.recheck import read_refutations
    tampered = read_refutations(tmp_path)["condition:decrease"]
    obligation = next(p.obligation for p in result.kernel.proofs
                      if p.obligation.name == "condition:decrease")
    from fossil_dsl.solvers.positivstellensatz import refutation_problem
    assert "not positive semidefinite" in refutation_problem(tampered, obligation.query,
                                                             result.plan.states)
    again = fossil_dsl.load_result(tmp_path, timeout=5)
    decrease = [p for p in again.kernel.proofs if p.obligation.name == "condition:decrease"]
    # the tampered evidence is not what proves it (the kernel may find its own)
    assert not decrease or decrease[0].detail != GIVEN_REFUTATION
    assert procedures and [p.detail for p in result.kernel.proofs
                           if p.obligation.name == "condition:decrease"] == [GIVEN_REFUTATION]


MARGINAL = """\
state x0, x1
dynamics continuous {
    x0' = -x0^3 + x1
    x1' = -x0 - x1^3
}
domain ball([0, 0], 1)
prove stable
"""


def test_a_marginally_stable_linearisation_is_proved_with_a_quartic_decrease():
    """The linearisation is a centre: no t|x|^2 decrease exists, t|x|^4 does, and the
    refutations use the strict comparison |x|^2 > 0 squared."""
    result = fossil_dsl.synthesise(fossil_dsl.loads(MARGINAL), timeout=60)
    assert result.certified, result.summary()
    assert "|x|^4" in result.strategy
    procedures = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert procedures["condition:decrease"] == "sum of squares (exact)"


def test_a_region_of_attraction_gets_a_round_enough_v():
    """The Lorenz system below its bifurcation: the V of largest margin is too flat for
    a sublevel set between init and the domain's boundary; the roundest V with a quarter
    of that margin fits."""
    from pathlib import Path
    spec = fossil_dsl.load(Path(__file__).resolve().parent.parent / "specs" / "literature"
                           / "lit24_lorenz_subcritical_roa.fsl")
    result = fossil_dsl.synthesise(spec, timeout=60)
    assert result.certified and result.strategy.startswith("sum-of-squares")


HENON_LIKE = """\
state x0, x1
dynamics discrete {
    next(x0) = 0.4*x0 - 0.3*x1 + 0.2*x0*x1
    next(x1) = 0.5*x0 + 0.3*x1 - 0.1*x0^2
}
domain ball([0, 0], 1)
prove stable
"""


def test_a_polynomial_map_gets_a_sum_of_squares_v_too():
    """V(f(x)) - V(x) takes dV/dt's place; the kernel's discrete rule judges it."""
    result = fossil_dsl.synthesise(fossil_dsl.loads(HENON_LIKE), timeout=60)
    assert result.certified, result.summary()
    assert "V(f(x)) - V(x) <= -" in result.strategy


LINEAR_6 = """\
state x1, x2, x3, x4, x5, x6
dynamics continuous {
    x1' = -x1 + 0.5*x2
    x2' = -x2 + 0.5*x3 + 0.1*x1*x4
    x3' = -x3 + 0.5*x4
    x4' = -x4 + 0.5*x5 - 0.1*x1*x2
    x5' = -x5 + 0.5*x6
    x6' = -x6 + 0.5*x1
}
domain ball([0, 0, 0, 0, 0, 0], 4)
set init = ball([0, 0, 0, 0, 0, 0], 0.5)
set unsafe = ~ball([0, 0, 0, 0, 0, 0], 3)
prove from init: always not unsafe
"""


def test_a_six_state_safety_property_gets_a_quadratic_barrier_by_sum_of_squares():
    """A quadratic B from the program; the flow condition proved exactly."""
    result = fossil_dsl.synthesise(fossil_dsl.loads(LINEAR_6), timeout=120)
    assert result.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares programming (Clarabel): B of degree 2")
    procedures = {p.obligation.name: p.procedure for p in result.kernel.proofs}
    assert procedures["condition:flow"] == "sum of squares (exact)"


def _ring(n: int) -> str:
    xs = [f"x{i}" for i in range(1, n + 1)]
    zero = ", ".join(["0"] * n)
    lines = [f"state {', '.join(xs)}", "dynamics continuous {"]
    lines += [f"    {xs[i]}' = -{xs[i]} + 0.5*{xs[(i + 1) % n]}" for i in range(n)]
    lines += ["}", f"domain ball([{zero}], 4)", f"set init = ball([{zero}], 0.5)",
              f"set unsafe = ~ball([{zero}], 3)", "prove from init: always not unsafe"]
    return "\n".join(lines) + "\n"


def test_eight_states_check_and_certify_with_refutations_for_relations_too():
    """Z3 does not decide within the checker's 5 s that two balls in 8 dimensions are
    disjoint; a sum-of-squares refutation does (and the kernel's relations, and the
    barrier's conditions, and B > 0 on the boundary of D for the stronger guarantee)."""
    checked = fossil_dsl.check_text(_ring(8), "ring8.fsl")
    assert checked.ok, checked.render()
    result = fossil_dsl.synthesise(checked.spec, timeout=120)
    assert result.certified, result.summary()
    by_text = {p.obligation.text: p.procedure for p in result.kernel.proofs}
    assert by_text["I and U are disjoint"] == "sum of squares (exact)"
    assert result.kernel.strengthened is not None  # never leaves D: B > 0 on its boundary


def test_linear_relations_of_many_states_go_to_z3_first(monkeypatch):
    """probe48/c11 (7 states, a box domain) was refused as a bad spec on a loaded machine:
    its linear relations went to the refutation first (1-3 s each, most of it on a
    satisfiable query) and spent the checker's 5 s. Z3 decides them at once; the
    refutation still comes first for the nonlinear ones (two balls, above)."""
    from fossil_dsl.solvers import sos_refutation
    asked = []
    original = sos_refutation.SosBackend.check

    def check(self, formula, variables, timeout, stop=None):
        asked.append(formula)
        return original(self, formula, variables, timeout, stop)
    monkeypatch.setattr(sos_refutation.SosBackend, "check", check)
    path = Path(__file__).resolve().parent.parent / "specs/probe48/c11_hopfield_ring_7d_stable.fsl"
    checked = fossil_dsl.check_text(path.read_text(), path.name)
    assert checked.ok, checked.render()
    assert asked == []
    assert fossil_dsl.check_text(_ring(8), "ring8.fsl").ok and asked  # balls: refuted first


def test_refutations_the_kernel_found_itself_are_exported_and_rechecked(tmp_path):
    from fossil_dsl.outputs.recheck import recheck
    result = fossil_dsl.synthesise(fossil_dsl.check_text(_ring(8), "ring8.fsl").spec,
                                   timeout=120)
    assert result.certified
    result.save(tmp_path)
    assert (tmp_path / "obligations" / "relation-initial_and_unsafe.sos.json").exists()
    checks = recheck(tmp_path, timeout=10)
    assert all(c.reproved for c in checks), [(c.condition, c.reason) for c in checks]


# four double integrators in a ring, one force each: LQR and its quadratic V are the
# textbook answer, but Z3 gave no answer on "V > 0" in 8 variables within 50 s
RING_OF_CARTS = """\
state x0, x1, x2, x3, x4, x5, x6, x7
input u0, u1, u2, u3
dynamics continuous {
    x0' = x1
    x1' = u0 + 0.1*x2
    x2' = x3
    x3' = u1 + 0.1*x4
    x4' = x5
    x5' = u2 + 0.1*x6
    x6' = x7
    x7' = u3 + 0.1*x0
}
domain ball([0, 0, 0, 0, 0, 0, 0, 0], 1)
prove stable
"""


def test_the_learning_loop_tries_refutations_first_from_six_states():
    result = fossil_dsl.synthesise(fossil_dsl.loads(RING_OF_CARTS), seed=0, timeout=120)
    assert result.certified and result.iterations == 1, result.reason
    solvers = {c.name: c.solver for c in result.conditions}
    assert solvers["positive"] == solvers["decrease"] == "sum of squares (exact)", solvers


CUBIC_MAP = """\
state x0, x1, x2, x3
dynamics discrete {
    next(x0) = 0.5*x0 + 0.2*x1 - 0.1*x0^3
    next(x1) = -0.2*x0 + 0.5*x1 - 0.1*x1^3
    next(x2) = 0.6*x2 + 0.1*x3
    next(x3) = 0.1*x0 + 0.6*x3 - 0.1*x3^3
}
domain box([-1, -1, -1, -1], [1, 1, 1, 1])
prove stable
"""


def test_a_box_domain_gets_its_bound_products_where_the_bounds_alone_give_nothing():
    """V(f(x)) - V(x) of a cubic map has terms -c x_i^6 that sum-of-squares multiples of
    the linear bounds (degree 5 at most) cannot match; (1 - x_i^2) times a quartic can."""
    plan = _plan(CUBIC_MAP)
    field = sos.field_of(plan)
    plain = sos.set_constraints(plan.spec.domain, plan.states)
    program = sos._LyapunovProgram(4, field, plain, 1, 1, True)
    assert program.solve({program.margin: -1.0}, 60) is None  # infeasible
    found = sos.lyapunov(plan, time.monotonic() + 60)
    assert found is not None and found.margin > 0.01


QUADRATIC_MAP = """\
state x0, x1, x2, x3
dynamics discrete {
    next(x0) = 0.6*x0 + 0.2*x1
    next(x1) = -0.2*x0 + 0.6*x1 + 0.2*x2^2
    next(x2) = 0.5*x2 + 0.1*x3
    next(x3) = 0.5*x3 - 0.2*x0*x2
}
domain box([-1, -1, -1, -1], [1, 1, 1, 1])
set init = ball([0, 0, 0, 0], 0.5)
prove from init: stable
"""


def test_a_quadratic_v_with_the_box_products_comes_before_a_quartic_without_them():
    """specs/discrete/d18: the quadratic program without the products is infeasible; the
    quartic one without them took 30 s and its V's decrease 100 s to refute, the
    quadratic one with them 0.06 s (its V is proved at once)."""
    plan = _plan(QUADRATIC_MAP)
    plain = sos.set_constraints(plan.spec.domain, plan.states)
    program = sos._LyapunovProgram(4, sos.field_of(plan), plain, 1, 1, True)
    assert program.solve({program.margin: -1.0}, 60) is None  # infeasible
    found = sos.lyapunov(plan, time.monotonic() + 60)
    assert found is not None and found.degree == 2 and found.margin > 0.01
    result = fossil_dsl.synthesise(fossil_dsl.loads(QUADRATIC_MAP), timeout=60)
    assert result.certified and "V of degree 2" in result.strategy, result.summary()


def test_a_map_whose_decrease_z3_cannot_decide_is_proved_outside_a_lemma_ball():
    """Z3 times out on the sextic decrease and the interval procedure cannot refute boxes
    at the origin: the V is proved with a ball the Taylor lemma covers, and the guarantee
    is still asymptotic stability (no ε)."""
    result = fossil_dsl.synthesise(fossil_dsl.loads(CUBIC_MAP), timeout=120)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares programming")
    assert "asymptotically stable" in result.guarantee()
    assert "ε" not in result.guarantee() and "epsilon" not in result.guarantee()


COUPLED_REVERSED_VAN_DER_POL = (Path(__file__).parent.parent / "specs" / "probe44"
                                / "y02_coupled_reversed_vdp_roa_4d.fsl")


def test_a_quartic_v_found_with_box_products_is_refuted_with_them_too():
    """The program finds a degree-4 V with the products of the box's opposite bounds;
    its decrease has a refutation only with those products too (without them: 60 s of
    solvers timing out, then learning)."""
    result = fossil_dsl.synthesise(fossil_dsl.load(COUPLED_REVERSED_VAN_DER_POL), timeout=120)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares programming")
    decrease = next(p for p in result.kernel.proofs
                    if p.obligation.name == "condition:decrease")
    assert decrease.proved and getattr(decrease.evidence, "products", ())


# probe45/z03: the SIR model, where every point with i = 0 is an equilibrium; no quadratic
# B meets the program's conditions, learning failed in 25 iterations
EPIDEMIC = """\
state s, i
dynamics continuous {
    s' = -s*i
    i' = s*i - 0.5*i
}
domain box([0, 0], [1, 1])
set init = box([0.3, 0.01], [0.45, 0.05])
set unsafe = { i >= 0.2 }
prove from init: always not unsafe
"""


def test_a_box_initial_set_needs_its_products_for_a_quadratic_barrier(monkeypatch):
    """-B - e >= 0 on the box I with constant multipliers of its linear bounds needs
    -B's Hessian PSD, which no B convex enough to stay positive on U has; the products
    (s - l)(u - s) >= 0 bring the -s^2 terms. Without them no quadratic B was found and
    the program went on to a quartic (sessions up to 60)."""
    with monkeypatch.context() as patch:
        patch.setattr(sos_barrier, "DEGREES", (1,))
        patch.setattr(sos_barrier, "interval_products", lambda constraints: constraints)
        assert sos_barrier.barrier(_plan(EPIDEMIC), time.monotonic() + 30) is None
    found = sos_barrier.barrier(_plan(EPIDEMIC), time.monotonic() + 30)
    assert found is not None and found.degree == 2
    # (since session 53 a run takes s exp(-2 (s + i)), conserved, before the programs)
    monkeypatch.setattr(first_integral, "applies", lambda plan: False)
    result = fossil_dsl.synthesise(fossil_dsl.loads(EPIDEMIC), timeout=60)
    assert result.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares programming (Clarabel): B of degree 2")


def test_six_state_barriers_are_quadratic_with_the_initial_sets_products():
    """bb25 and probe48/c09 (a non-normal linear system) had quartic barriers (programs
    of 1 877 and 2 465 variables) while I's box entered without its products; with
    them each has a quadratic one, proved at once."""
    root = Path(__file__).resolve().parent.parent
    for path in (root / "specs/barrierbench/bb25.fsl",
                 root / "specs/probe48/c09_nonnormal_linear_6d_safety.fsl"):
        result = fossil_dsl.synthesise(fossil_dsl.load(path), timeout=60)
        assert result.certified and result.kernel.certified, result.summary()
        assert result.strategy.startswith("sum-of-squares programming (Clarabel): B of degree 2")


def test_a_decrease_on_a_tight_sublevel_set_needs_multipliers_of_one_degree_more(monkeypatch):
    """probe48/c02 (the reversed Van der Pol basin holding the ball of radius 1.3): the
    degree-6 V shaped to the basin decreases on {V <= 0.93} with a margin of 0.001|x|^2.
    With s0 of the query's degree (8) no program is feasible; with every multiplier one
    degree more, the decrease is refuted, and the kernel's check accepts it."""
    from fractions import Fraction
    from fossil_dsl.kernel import Claim, list_obligations
    from fossil_dsl.plan.compile import origin_radius
    from fossil_dsl.solvers import sos_refutation
    from fossil_dsl.solvers.positivstellensatz import refutation_problem
    root = Path(__file__).resolve().parent
    text = (root.parent / "specs/probe48/c02_reversed_vdp_roa_tight.fsl").read_text()
    V = (root / "data/c02_shaped_v.txt").read_text().strip()
    spec = fossil_dsl.loads(text + f"synthesis {{\n    candidate: {V}\n}}\n")
    plan = _plan(text + f"synthesis {{\n    candidate: {V}\n}}\n")
    claim = Claim(spec, {"V": plan.functions[0].candidate}, {}, {"beta": Fraction(93, 100)},
                  origin_radius(spec))
    [decrease] = [o for o in list_obligations(claim) if o.name == "condition:decrease"]
    found = sos_refutation.refute(decrease.query, plan.states, time.monotonic() + 60)
    assert found is not None
    assert refutation_problem(found, decrease.query, plan.states) is None
    monkeypatch.setattr(sos_refutation, "RAISED_MAX_ENTRIES", 0)  # no raised programs
    assert sos_refutation.refute(decrease.query, plan.states, time.monotonic() + 60) is None


def test_a_rational_field_gets_a_barrier_multiplied_through_its_denominator():
    """probe53/n03, a chemostat with Monod uptake s/(0.5 + s): learning timed out
    (120 s). Over the denominator 10 + 20 s (positive on D) the flow condition is
    linear in B again; no B of degree 2 exists, one of degree 4 does (of degree 6 before
    I's products entered the programs)."""
    path = Path(__file__).resolve().parent.parent / "specs/probe53/n03_chemostat_washout_safety.fsl"
    plan = compile_spec(fossil_dsl.load(path))
    assert sos.applies(plan) and sos.field_of(plan) is None
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(sos_barrier, "DEGREES", (1,))
        assert sos_barrier.barrier(plan, time.monotonic() + 30) is None
    found = sos_barrier.barrier(plan, time.monotonic() + 30)
    assert found is not None and found.degree == 4
    result = fossil_dsl.synthesise(fossil_dsl.load(path), timeout=90)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("sum-of-squares programming (Clarabel): B of degree 4")


def test_a_rational_field_whose_denominator_changes_sign_on_d_gets_no_barrier():
    text = (Path(__file__).resolve().parent.parent
            / "specs/probe53/n03_chemostat_washout_safety.fsl").read_text()
    text = text.replace("(0.5 + s)", "(s - 0.5)")
    plan = compile_spec(fossil_dsl.loads(text))
    assert sos.applies(plan)
    assert sos_barrier.barrier(plan, time.monotonic() + 30) is None


SPRING_CHAIN = Path(__file__).resolve().parent.parent / \
    "specs/probe72/av32_cubic_spring_chain_safety_6d.fsl"


def test_a_quartic_barrier_too_large_in_full_is_sought_quartic_in_the_nonlinear_states():
    """probe72/av32, three masses on cubic springs (6 states): the full quartic barrier
    program (10 333 variables) exceeds its cap, and nothing was found in 120 s before
    session 74. B quartic in the positions and quadratic in the speeds, an energy's
    shape: the program is a quarter of the size and finds B; the kernel proves it."""
    plan = compile_spec(fossil_dsl.load(SPRING_CHAIN))
    basis = sos_barrier._nonlinear_part_basis(
        sos_barrier.exact_field(plan, plan.spec.dynamics).numerators, 6, 2)
    speeds = {m for m in basis if sum(m[3:]) > 0}
    assert max(sum(m) for m in speeds) == 2  # v1..v3 enter linearly in the field
    assert max(sum(m) for m in basis) == 4 and len(basis) < 210
    found = sos_barrier.barrier(plan, time.monotonic() + 60)
    assert found is not None and found.degree == 4
    result = fossil_dsl.synthesise(fossil_dsl.load(SPRING_CHAIN), seed=0, timeout=90)
    assert result.certified and result.strategy.startswith("sum-of-squares"), result.reason


def test_a_linear_field_gets_no_second_program_of_the_quadratic_basis():
    plan = _plan(THREE_STATES.replace("x' = -x + y*z - x^3", "x' = -x")
                 .replace("y' = -2*y - x*z", "y' = -2*y").replace("z' = -z + x*y - z^3",
                                                                  "z' = -z"))
    numerators = sos_barrier.exact_field(plan, plan.spec.dynamics).numerators
    assert max(map(sum, sos_barrier._nonlinear_part_basis(numerators, 3, 2))) == 2


SPECS74 = Path(__file__).resolve().parent.parent / "specs/probe74"
FOUR_MASSES = Path(__file__).resolve().parent.parent / \
    "specs/probe48/c05_four_mass_chain_8d_stable.fsl"


def test_an_eight_state_spring_chain_gets_an_energy_shaped_quartic_v(monkeypatch):
    """probe48/c05, four masses on hardening springs (8 states), `prove stable` on the
    box: no quadratic V decreases on D, the full quartic program (30 361 variables) is
    over the bound, and learning timed out (open since session 48). V's terms above
    degree 2 in the positions only (an energy plus cross terms): 2 557 variables."""
    plan = compile_spec(fossil_dsl.load(FOUR_MASSES))
    field = sos.field_of(plan)
    assert sos.nonlinear_states(field, 8) == {0, 2, 4, 6}  # q1..q4, not the speeds
    plain = sos.set_constraints(plan.spec.domain, plan.states)
    full = sos._LyapunovProgram(8, field, plain, 2, 1, False)
    shaped = sos._LyapunovProgram(8, field, plain, 2, 1, False, sos.nonlinear_states(field, 8))
    assert full.count > sos.MAX_VARIABLES >= shaped.count
    # (the quadratic programs, which fail, take 20 s of the attempt's 30 under load)
    monkeypatch.setattr(sos, "DEGREES", (2,))
    result = fossil_dsl.synthesise(fossil_dsl.load(FOUR_MASSES), seed=0, timeout=110)
    assert result.certified and result.strategy.startswith("sum-of-squares"), result.reason
    V = result.sympy["V"]
    speeds = [s for s in V.free_symbols if str(s).startswith("v")]
    assert all(sympy.degree(V, s) <= 2 for s in speeds)


def test_the_energy_shaped_program_comes_where_the_full_one_is_large():
    """probe74/ax37, four masses on cubic springs to ground (8 states): its energy-shaped
    quartic B needs 5 771 variables, over the full programs' bound of 4 000 (certified
    in 48 s since session 74, a timeout before); ax36, three masses' region of
    attraction: the energy-shaped V's program (1 009 variables) before the full one
    (8 401, too costly to start in the attempt's time); a small full program alone."""
    plan = compile_spec(fossil_dsl.load(SPECS74 / "ax37_four_mass_chain_safety_8d.fsl"))
    field = sos_barrier.exact_field(plan, plan.spec.dynamics)
    (full, full_cap), (shaped, cap) = sos_barrier._bases(field, 8, 2)
    assert full is None and cap > full_cap and max(map(sum, shaped)) == 4
    spec = fossil_dsl.load(SPECS74 / "ax36_three_mass_cubic_chain_roa_6d.fsl")
    plan = compile_spec(spec)
    programs = list(sos._programs(plan, sos.field_of(plan),
                                  sos.set_constraints(plan.spec.domain, plan.states), 2, 1))
    assert programs[0].nonlinear == {0, 1, 2} and programs[1].nonlinear is None
    assert programs[0].count < programs[1].count / 4
    small = list(sos._programs(_plan(THREE_STATES), sos.field_of(_plan(THREE_STATES)), [], 2, 1))
    assert len(small) == 1 and small[0].nonlinear is None
    result = fossil_dsl.synthesise(spec, seed=0, timeout=60)
    assert result.certified and result.strategy.startswith("sum-of-squares"), result.reason
