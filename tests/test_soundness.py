"""False properties are never certified.

Each kind of false CERTIFIED found on main (0503d1c) is reproduced here with specs of our
own, end to end through `fossilc`'s Python API, and again against the kernel alone with
the checker's facts bypassed, so that neither layer relies on the other. The enclosures
the interval procedure trusts are compared with mpmath at 100 digits.
"""
from __future__ import annotations

import dataclasses
import random
from fractions import Fraction

import mpmath
import pytest
import sympy
import torch

import fossil_dsl
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.expr import Num
from fossil_dsl.kernel import Claim, judge
from fossil_dsl.plan.compile import compile_spec


def check_errors(text: str) -> str:
    result = fossil_dsl.check_text(text, "false.fsl")
    assert not result.ok, "the spec was accepted"
    return " ".join(d.message for d in result.errors)


def run(text: str, **options):
    return fossil_dsl.synthesise(fossil_dsl.loads(text, "false.fsl"), **options)


def claim_for(spec, levels=None, radius=None):
    """The claim of a spec's candidates, with the plan's excluded ball."""
    plan = compile_spec(spec)
    functions = {f.name: f.candidate for f in plan.functions}
    radius = plan.origin_radius if radius is None else radius
    return Claim(spec, functions, {}, levels or {}, radius)


# ---- undecided set relations are errors ------------------------------------------
ROA_EXP_INIT = """
state x0
dynamics continuous { x0' = -x0 + x0^3 }
domain box([-0.9], [0.9])
set init = { exp(x0) >= 12, x0 <= 3 }
prove from init: stable
synthesis {
    candidate: x0^2 * (x0 - 2.7)^2
}
"""


def test_initial_set_reaching_outside_the_domain_is_refused():
    assert "cannot prove that `init` is inside the domain" in check_errors(ROA_EXP_INIT)


def test_initial_set_outside_the_domain_fails_in_the_kernel():
    """The same claim with the checker bypassed: the kernel proves I inside D itself."""
    spec = fossil_dsl.loads(ROA_EXP_INIT.replace("{ exp(x0) >= 12, x0 <= 3 }",
                                                 "box([0.2], [0.3])"), "roa.fsl")
    outside = S.Box((Num(Fraction(249, 100)),), (Num(3),))
    roles = dict(spec.property.roles, initial=outside)
    spec = dataclasses.replace(spec, property=dataclasses.replace(spec.property, roles=roles))
    verdict = judge(claim_for(spec, {"beta": Fraction(1)}))
    assert not verdict.certified
    assert [p.obligation.name for p in verdict.failed] == ["relation:initial in domain"]


def test_initial_set_partly_outside_the_safe_set_is_refused():
    text = """
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-2, -2], [2, 2])
set safe = box([-1, -1], [1, 1])
set init = { exp(x0) <= 3, x0 >= 0.5, x1 >= -0.1, x1 <= 0.1 }
set goal = ball([0, 0], 0.1)
prove from init: safe until goal
"""
    assert "`init` is inside the interior of the safe set `safe`" in check_errors(text)


# ---- a neighbourhood of the origin --------------------------------------------------
ANNULUS = """
state x0, x1
dynamics continuous {
    x0' = x0
    x1' = x1
}
domain ball([0,0],1) - ball([0,0],0.6)
prove stable
synthesis {
    candidate: (x0^2 + x1^2) * (x0^2 + x1^2 - 1.05)^2
}
"""
NO_ORIGIN = """
state x0
dynamics continuous { x0' = x0 }
domain box([1], [2])
prove stable
synthesis {
    candidate: x0 * (x0 - 2.1)^2
}
"""


@pytest.mark.parametrize("text", [ANNULUS, NO_ORIGIN], ids=["hole", "no origin"])
def test_domain_without_a_neighbourhood_of_the_origin_is_refused(text):
    assert "no neighbourhood of the origin" in check_errors(text)


HOLE = S.Difference(S.Ball((Num(0), Num(0)), Num(1)),
                    S.Ball((Num(0), Num(0)), Num(Fraction(3, 5))))


@pytest.mark.parametrize("text, domain, box", [
    (ANNULUS, HOLE, "ball([0,0],1) - ball([0,0],0.6)"),
    (NO_ORIGIN, S.Box((Num(1),), (Num(2),)), "box([1], [2])")], ids=["hole", "no origin"])
def test_kernel_refuses_stability_without_a_neighbourhood(text, domain, box):
    """The checker refuses these; put past it, the kernel refuses them too."""
    around_origin = "box([-1, -1], [1, 1])" if "x1" in text else "box([-3], [3])"
    spec = fossil_dsl.loads(text.replace(box, around_origin), "a.fsl")
    spec = dataclasses.replace(spec, domain=domain, property=dataclasses.replace(
        spec.property, roles={"domain": domain}))
    verdict = judge(claim_for(spec))
    assert not verdict.certified and verdict.failed[0].obligation.name == "neighbourhood"


# ---- the excluded ball ------------------------------------------------------------
def test_domain_smaller_than_the_excluded_ball_proves_nothing():
    text = """
state x0, x1
dynamics continuous {
    x0' = x0
    x1' = x1
}
domain ball([0,0], 0.005)
prove stable
synthesis {
    candidate: x0^2 + x1^2
    verifier: interval
}
"""
    assert not run(text).certified
    spec = fossil_dsl.loads(text, "small.fsl")
    verdict = judge(claim_for(spec, radius=Fraction(1, 100)))
    assert not verdict.certified
    assert verdict.failed[0].obligation.name == "ball:room"


BALL_ESCAPE_ROA = """
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-1, -1], [1, 1])
set init = box([0.5, 0.5], [0.6, 0.6])
prove from init: stable
synthesis {
    candidate: x0^2 + x1^2
}
"""


def test_roa_needs_the_excluded_ball_inside_the_sublevel_set():
    """With β below V on part of the ball, a trajectory could leave Ω through it."""
    spec = fossil_dsl.loads(BALL_ESCAPE_ROA, "roa.fsl")
    small_beta = {"beta": Fraction(1, 10 ** 6)}
    verdict = judge(claim_for(spec, small_beta, radius=Fraction(1, 100)))
    assert not verdict.certified
    names = [p.obligation.name for p in verdict.failed]
    assert names and names[0] in ("condition:initial", "ball:sublevel")
    # and the rule itself: V < β on the ball is an obligation
    from fossil_dsl.kernel import list_obligations as obligations
    assert "ball:sublevel" in [o.name for o in obligations(
        claim_for(spec, small_beta, radius=Fraction(1, 100)))]


BOUNCING_MAP = """
state x0
dynamics discrete { next(x0) = 0.5*x0 + 0.2*(x0/0.001)*exp(-(x0/0.001)^2) }
domain box([-1], [1])
prove stable
synthesis {
    candidate: x0^2
    verifier: interval
}
"""


def test_discrete_map_that_throws_points_out_of_the_ball_is_not_certified():
    result = run(BOUNCING_MAP)
    assert not result.certified
    verdict = judge(claim_for(fossil_dsl.loads(BOUNCING_MAP, "map.fsl")))
    assert "ball:image" in [p.obligation.name for p in verdict.failed]


# ---- undefined points ---------------------------------------------------------------
SQRT_HOLE = """
state x0, x1
dynamics continuous {
    x0' = -1
    x1' = 0
}
domain box([-2,-2],[2,2])
set safe = box([-1.5,-1],[1.5,1])
set init = box([-1.2,-0.5],[-1,0.5])
set goal = box([0.5,-0.2],[1,0.2])
prove from init: safe until goal
synthesis {
    candidate: CANDIDATE
    verifier: interval
}
"""


@pytest.mark.parametrize("candidate", ["sqrt(x0) + 0.1", "log(x0 + 1.1) - 5",
                                       "1/(x0 + 0.3) - 10", "tan(x0) - 4"])
def test_candidate_undefined_in_the_safe_set_is_not_certified(candidate):
    result = run(SQRT_HOLE.replace("CANDIDATE", candidate))
    assert not result.certified
    assert result.exit_code == 1


def test_definedness_is_an_obligation_named_in_the_reason():
    result = run(SQRT_HOLE.replace("CANDIDATE", "sqrt(x0) + 0.1"))
    assert "defined" in result.reason


# ---- unbounded regions ------------------------------------------------------------
def test_reach_on_an_unbounded_domain_is_refused_before_running():
    text = """
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain { x0 + x1 <= 10 }
set init = box([0.5,0.5],[1,1])
set goal = ball([0,0],0.1)
prove from init: eventually goal
"""
    assert "must be bounded" in check_errors(text)


class HalfPlane(fossil_dsl.BespokeSet):
    """Unbounded constraints with a bounded sampling box."""
    box = ([-1, -1], [1, 1])

    def constraints(self, x):
        return [x[0] + x[1] <= 1]

    def sample(self, count, generator):
        return torch.rand(count, 2, generator=generator, dtype=torch.float64) * 2 - 1


def test_python_api_refuses_a_bespoke_domain_with_unbounded_constraints():
    x0, x1 = sympy.symbols("x0 x1", real=True)
    with pytest.raises(fossil_dsl.BuildError, match="box"):
        fossil_dsl.build_spec("half", [x0, x1], [x0, x1], HalfPlane(),
                              "from init: eventually goal",
                              {"init": "box([0.5, 0.1], [0.6, 0.2])",
                               "goal": "ball([0, 0], 0.1)"})


class Disc(HalfPlane):
    def constraints(self, x):
        return [x[0] ** 2 + x[1] ** 2 <= 1]


def test_python_api_accepts_a_bespoke_domain_inside_its_box():
    x0, x1 = sympy.symbols("x0 x1", real=True)
    spec = fossil_dsl.build_spec("disc", [x0, x1], [-x0, -x1], Disc(), "stable")
    assert spec.domain.bounding_box() == ((-1.0, -1.0), (1.0, 1.0))


# ---- rounding ---------------------------------------------------------------------
FUNCTIONS = {"sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan, "exp": mpmath.exp,
             "log": mpmath.log, "sqrt": mpmath.sqrt, "tanh": mpmath.tanh,
             "atan": mpmath.atan}


def _points(name: str) -> list[float]:
    rng = random.Random(name)
    positive = name in ("log", "sqrt")
    points = [rng.uniform(1e-9 if positive else -40, 40) for _ in range(2000)]
    points += [10.0 ** k for k in range(-300, 300, 7)]  # tiny and huge
    points += [float(k * mpmath.pi / 2) for k in range(-40, 41)]  # near poles and zeros
    points += [float(k * mpmath.pi / 2) * (1 + 1e-16) for k in range(-40, 41)]
    points += [0.5, 1.0, 2.0, 1e-17, 709.0, -745.0, 0.0]
    return [p for p in points if p > 0] if positive else points


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_every_enclosure_contains_the_true_value(name):
    """The interval procedure's functions against mpmath at 100 digits."""
    from fossil_dsl.ir.enclosure import function, upward_rounding
    mpmath.mp.dps = 100
    with upward_rounding() as codac:
        for x in _points(name):
            interval = function(name, codac.Interval(x, x))
            if interval.is_empty():
                continue  # outside the function's domain (tan at a pole)
            true = FUNCTIONS[name](mpmath.mpf(x))
            assert mpmath.mpf(interval.lb()) <= true <= mpmath.mpf(interval.ub()), (x, interval)


def _double_enclosure(value) -> tuple[float, float]:
    """The narrowest pair of doubles around an mpmath number (exactly a binary fraction)."""
    from fossil_dsl.ir.enclosure import rational_bounds
    sign = int(mpmath.sign(value))  # (mpmath's mantissa is unsigned)
    return rational_bounds(sign * Fraction(int(value.man)) * Fraction(2) ** int(value.exp))


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_contraction_keeps_every_true_preimage(name):
    """Backward: contracting x by f(x) in [the doubles around f(x0)] keeps x0 (codac's
    inverse operators: asin, log, atanh through the composite, ...)."""
    from fossil_dsl.ir.enclosure import function, upward_rounding
    mpmath.mp.dps = 100
    rng = random.Random(f"backward {name}")
    positive = name in ("log", "sqrt")
    with upward_rounding() as codac:
        variable = codac.VectorVar(1)
        image = codac.AnalyticFunction([variable], function(name, variable[0]))
        for _ in range(600):
            x0 = rng.uniform(1e-6 if positive else -20, 20)
            low, high = _double_enclosure(FUNCTIONS[name](mpmath.mpf(x0)))
            width = rng.choice([1e-12, 1e-6, 0.01, 1.0])
            box = codac.IntervalVector([[max(x0 - width, 1e-300) if positive else x0 - width,
                                         x0 + width]])
            codac.CtcInverse_Interval(image, codac.Interval(low, high)).contract(box)
            assert not box.is_empty() and box[0].lb() <= x0 <= box[0].ub(), (x0, box)


def _tanh_query_native_tanh_misses():
    """`x = x0 and y = t and tanh(x) - y >= gap`, true since tanh(x0) = t + 2 gap, where t is the
    upper end of codac's own tanh of x0 (it misses the true value by under an ulp, so
    the difference with t is needed to expose it)."""
    from fossil_dsl.ir import expr as E
    from fossil_dsl.ir import logic as L
    from fossil_dsl.ir.enclosure import upward_rounding
    mpmath.mp.dps = 60
    rng = random.Random("tanh misses")
    with upward_rounding() as codac:
        while True:
            x0 = rng.uniform(-3, 3)
            native = codac.tanh(codac.Interval(x0, x0)).ub()
            true = mpmath.tanh(mpmath.mpf(x0))
            if true > native:
                break
    gap = Fraction(str(mpmath.nstr((true - mpmath.mpf(native)) / 2, 30)))
    x, y = E.Var("x"), E.Var("y")  # y = t: a variable, so that t and gap stay apart
    fixed = [L.Compare(relation, variable, E.Num(Fraction(value)))
             for variable, value in ((x, x0), (y, native)) for relation in ("<=", ">=")]
    return L.conjunction(*fixed, L.Compare(">=", E.add(E.Apply("tanh", x), E.neg(y)),
                                           E.Num(gap)))


def test_the_kernels_interval_procedure_encloses_tanh_outwards():
    """The search mode of the loop keeps codac's own tanh (three times faster to search
    with; its answers are leads); the procedure the kernel and recheck build does not
    refute a true query at a point where that tanh misses the true value."""
    from fossil_dsl.solvers import registry
    from fossil_dsl.solvers.api import Status
    from fossil_dsl.solvers.interval_backend import IntervalBackend
    query = _tanh_query_native_tanh_misses()
    for backend in (IntervalBackend(), registry.load("interval")):
        assert backend.check(query, ["x", "y"], timeout=10).status is Status.SAT
    search = registry.load("interval", search=True)
    assert search.check(query, ["x", "y"], timeout=10).status is Status.UNSAT  # a lead only
