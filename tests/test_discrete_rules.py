"""Discrete time for every property: the pitfalls that the continuous-time rules, read
with V(f(x)) - V(x) in place of dV/dt, fall into.

Each case is a false property of a map with a candidate for which every obligation of
the continuous-time rule is proved (a step jumps over a boundary that a trajectory
would have to cross), the iterates that show the property false, and the discrete
rule's verdict: not certified, at the obligation about where a step lands. Synthesis
must never certify these properties either.
"""
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import pytest

import fossil_dsl
from fossil_dsl.engine.evaluate import evaluate, holds
from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.kernel import judge
from fossil_dsl.kernel.obligations import Claim, Facts, common
from fossil_dsl.kernel.registry import RULES
from fossil_dsl.kernel.prove import Outcome
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.certificates.base import CERTIFICATES
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.z3_backend import Z3Backend


@dataclass(frozen=True)
class Pitfall:
    spec: str
    functions: dict  # name -> formula text
    levels: dict  # name -> rational text
    start: float  # an initial state whose iterates break the property
    broken: str  # how they break it, as a test on the iterates (see `_iterates_break`)
    failing: str  # the discrete rule's obligation that fails


PITFALLS = {
    # V's sublevel set has a second piece outside D; a step from I jumps there over ∂D,
    # where V > β, and the iterates then grow without bound
    "roa: a step jumps out of D": Pitfall("""\
state x0
dynamics discrete { next(x0) = 0.5*x0 + 5*x0^2 }
domain box([-1], [1])
set init = box([0.705], [0.715])
prove from init: stable
""", {"V": "1000*x0^2*(x0 - 0.71)^2*(x0 - 2.8755)^4 + x0^2*(x0 - 2.8755)^2"},
        {"beta": "2.69"}, 0.71, "diverges", "condition:image"),
    # B decreases wherever B = 0, but a step from inside {B <= 0} lands in U
    "swa: a step jumps into U": Pitfall("""\
state x0
dynamics discrete { next(x0) = -0.9*x0 }
domain box([-2], [2])
set init = box([0.95], [1.05])
set unsafe = box([-0.93], [-0.87])
prove from init: stable and always not unsafe
""", {"V": "x0^2", "B": "(x0 + 0.95)*(x0 + 0.85)*(x0 - 0.9)^2*(x0 - 1.1)"},
        {"beta": "1.2"}, 1.0, "enters unsafe", "condition:barrier_invariance"),
    # V > 0 on ∂S, but a step from {V <= 0} jumps over ∂S into U
    "rwa: a step jumps over the boundary of S": Pitfall("""\
state x0
dynamics discrete { next(x0) = x0 + 1 }
domain box([-5], [5])
set unsafe = box([0.5], [1.5])
set init = box([0], [0.2])
set goal = box([-4], [-3])
prove from init: not unsafe until goal
""", {"V": "(x0 + 0.1)*(x0 - 0.3)*(x0 - 0.8)*(x0 - 1.4)"}, {}, 0.1, "enters unsafe",
        "condition:image"),
    # the orbit bounces between F and the outside: V > β on ∂F, and V decreases on the
    # band F ∩ {V >= β}, but a step from F ∩ {V < β} jumps out of F
    "rswa: the orbit bounces out of F": Pitfall("""\
state x0
dynamics discrete { next(x0) = -x0 }
domain box([-2], [2])
set unsafe = box([1.8], [2])
set init = box([-1.02], [-0.98])
set final = box([0.5], [1.5])
prove from init: not unsafe until always final
""", {"V": "10*(x0^2 - 1)^2 - 0.1 + 0.2*x0*(x0^2 - 0.64)*(x0^2 - 1.44)"}, {"beta": "3"},
        -1.0, "leaves final after entering it", "condition:stay_image"),
    # from G, a step leaves F although B decreases wherever B = 0
    "rar: a step from G leaves F": Pitfall("""\
state x0
dynamics discrete { next(x0) = -1 + 20*(x0 - 1)^2 }
domain box([-2], [2])
set unsafe = box([1.8], [2])
set init = box([1.312], [1.32])
set goal = box([0.9], [1.1])
set final = box([0.5], [1.5])
prove from init: not unsafe until (goal and always final)
""", {"V": "100*(x0 - 1.31)*(x0 - 1.322)*(x0 - 0.9)*(x0 - 1.1)", "B": "(x0 - 1)^2 - 0.1"},
        {}, 1.315, "leaves final after goal", "condition:barrier_invariance"),
}


def _formula(spec_text: str, text: str) -> E.Expr:
    """A formula of the spec's states, read by the language's own parser."""
    return fossil_dsl.loads(spec_text + f"synthesis {{ candidate: {text} }}\n",
                            "pitfall.fsl").synthesis.candidate


def _claim(case: Pitfall) -> Claim:
    spec = fossil_dsl.loads(case.spec, "pitfall.fsl")
    functions = {name: _formula(case.spec, text) for name, text in case.functions.items()}
    levels = {name: Fraction(text) for name, text in case.levels.items()}
    return Claim(spec, functions, levels=levels)


class ContinuousReading(Facts):
    """The continuous-time rules' facts, with C(f(x)) - C(x) in place of dC/dt (so a
    barrier's flow condition reads B(f(x)) - B(x) < 0 wherever B = 0)."""

    def __init__(self, claim: Claim):
        super().__init__(claim)
        self.discrete = False

    def change(self, name: str) -> E.Expr:
        value = self.value(name)
        return E.add(calculus.compose(value, self.states, self.field), E.neg(value))


def _continuous_reading(claim: Claim) -> list:
    facts = ContinuousReading(claim)
    common(facts)
    RULES[(claim.spec.property.form, TimeDomain.CONTINUOUS)](facts)
    return facts.obligations


def _iterates_break(case: Pitfall, claim: Claim) -> bool:
    """Whether the iterates from `start` break the property as `broken` says."""
    spec = claim.spec
    step = spec.dynamics[0]
    member = {name: region.contains_formula(spec.states)
              for name, region in spec.property.roles.items()}

    def inside(name, x):
        return bool(holds(member[name], {spec.states[0]: np.array([x])}, 1)[0])

    x, path = case.start, [case.start]
    for _ in range(40):
        x = float(evaluate(step, {spec.states[0]: x}))
        path.append(x)
        if abs(x) > 1e6:
            break
    if case.broken == "diverges":
        return abs(path[-1]) > 1e6
    if case.broken == "enters unsafe":
        return any(inside("unsafe", p) for p in path)
    target = "goal" if case.broken == "leaves final after goal" else "final"
    first = next(i for i, p in enumerate(path) if inside(target, p))
    return any(not inside("final", p) for p in path[first:])


@pytest.mark.parametrize("name", sorted(PITFALLS))
def test_the_continuous_reading_is_fooled_and_the_discrete_rule_is_not(name):
    case = PITFALLS[name]
    claim = _claim(case)
    assert _iterates_break(case, claim), "the property is meant to be false"
    for obligation in _continuous_reading(claim):
        answer = Z3Backend().check(obligation.query, claim.spec.states, 60)
        assert answer.status is Status.UNSAT, (obligation.name, answer)
    verdict = judge(claim, timeout=60)
    assert not verdict.certified
    failed = verdict.failed[0]
    assert failed.obligation.name == case.failing, verdict.reason
    assert failed.outcome is Outcome.FAILS  # with a point where a step lands outside


@pytest.mark.parametrize("name", sorted(PITFALLS))
def test_synthesis_never_certifies_the_false_discrete_properties(name):
    spec = fossil_dsl.loads(PITFALLS[name].spec, "pitfall.fsl")
    result = fossil_dsl.synthesise(spec, seed=0, max_iters=4, timeout=15)
    assert not result.certified


def test_every_property_form_has_a_discrete_rule_and_certificate():
    for form, certificate in CERTIFICATES.items():
        assert certificate.discrete_time, form
        assert (form, TimeDomain.DISCRETE) in RULES, form


# ---- the step's change, expanded over its atoms ------------------------------------
def _random_points(rng, count=50):
    return [{"x0": rng.uniform(-2, 2), "x1": rng.uniform(-2, 2)} for _ in range(count)]


def test_a_steps_change_is_expanded_and_equal_to_the_difference():
    """V(f(x)) - V(x) for V = (100 x0 + x1)^2 + x1^2 and a step of 1/20 with sin: V's
    large terms cancel exactly (no power of a sum is left, no x0^2), and the expansion equals
    the plain difference wherever it is evaluated."""
    import random
    x0, x1, h = E.Var("x0"), E.Var("x1"), E.Num(Fraction(1, 20))
    V = E.add(E.power(E.add(E.mul(E.Num(100), x0), x1), E.Num(2)), E.power(x1, E.Num(2)))
    step = [E.add(x0, E.mul(h, x1)), E.add(x1, E.mul(h, E.apply("sin", x0)))]
    change = calculus.change(V, ["x0", "x1"], step, discrete=True)
    plain = E.add(calculus.compose(V, ["x0", "x1"], step), E.neg(V))
    powers = [n for n in E.walk(change) if isinstance(n, E.Pow)]
    assert powers and all(isinstance(p.base, (E.Var, E.Apply)) for p in powers)
    assert "x0^2" not in str(change)  # 10000 x0^2 cancelled
    for point in _random_points(random.Random(0)):
        assert float(evaluate(change, point)) == pytest.approx(float(evaluate(plain, point)),
                                                               abs=1e-9)


_X0, _X1 = E.Var("x0"), E.Var("x1")
PARTIAL = {"log": E.apply("log", E.add(_X0, E.Num(2))), "division": E.div(_X1, _X0),
           "sqrt": E.apply("sqrt", E.add(E.power(_X0, E.Num(2)), E.ONE))}


@pytest.mark.parametrize("partial", sorted(PARTIAL))
def test_a_change_with_a_partial_function_is_not_expanded(partial):
    """An expansion could cancel x / x, and with it the obligation that x is not 0."""
    names, V = ["x0", "x1"], PARTIAL[partial]
    step = [E.add(_X0, E.Num(Fraction(1, 10))), _X1]
    change = calculus.change(V, names, step, discrete=True)
    assert change == E.add(calculus.compose(V, names, step), E.neg(V))
