"""Generated false properties, with adversarial candidates: none is ever certified.

Each case is a property that is false for its system by construction (an unstable
eigenvalue, trajectories that provably enter the unsafe set, a goal that is never
reached), paired with a candidate certificate that hypothesis draws: quadratic forms,
huge coefficients, poles, functions that dip under zero by 1e-15, sqrt and tanh of a
polynomial. No certificate of a false property exists, so the kernel must refuse every
one. 100 cases in the default run, 1000 in the slow suite.
"""
from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import fossil_dsl
from fossil_dsl.ir.expr import to_text
from fossil_dsl.kernel import Claim, judge

TIMEOUT = 1.0  # seconds per obligation: running out is "not proved", never a proof
FAST = settings(max_examples=25, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
SLOW = settings(max_examples=250, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])

small = st.integers(-4, 4).map(lambda n: Fraction(n, 2))


@st.composite
def unstable_matrix(draw, n: int):
    """An n x n matrix with an eigenvalue of real part at least 0.1."""
    entries = draw(st.lists(small, min_size=n * n, max_size=n * n))
    matrix = np.array([float(e) for e in entries]).reshape(n, n)
    assume(max(np.linalg.eigvals(matrix).real) >= 0.1)
    return [entries[i * n:(i + 1) * n] for i in range(n)]


def linear_text(matrix, states) -> list[str]:
    return [" + ".join(f"({to_text_number(a)})*{s}" for a, s in zip(row, states))
            for row in matrix]


def to_text_number(value: Fraction) -> str:
    from fossil_dsl.ir.expr import Num
    return to_text(Num(value))


@st.composite
def candidate(draw, states, zero_at_origin: bool = True):
    """A candidate certificate's text: benign or adversarial."""
    n = len(states)
    weights = draw(st.lists(st.integers(-5, 5), min_size=n * n, max_size=n * n))
    quadratic = " + ".join(f"({w})*{a}*{b}" for w, (a, b) in
                           zip(weights, [(a, b) for a in states for b in states]))
    square = " + ".join(f"{s}^2" for s in states)
    offset = "" if zero_at_origin else f" - {draw(st.sampled_from(['0.5', '1', '1e-15']))}"
    kind = draw(st.sampled_from(["quadratic", "definite", "huge", "pole", "dip", "sqrt",
                                 "tanh"]))
    return {
        "quadratic": f"{quadratic}{offset}",
        "definite": f"{square}{offset}",
        "huge": f"1e12*({square}) + 1e-12*({quadratic}){offset}",
        "pole": f"{square} + {states[0]}^2/({states[-1]} - 0.25){offset}",
        "dip": f"{square} - 1e-15*{states[0]}^2{offset}",
        "sqrt": f"sqrt({square} + {states[0]}){offset}",
        "tanh": f"tanh({square}){offset}",
    }[kind]


def spec_of(states, dynamics, rest: str, time: str = "continuous"):
    left = (lambda s: f"{s}'") if time == "continuous" else (lambda s: f"next({s})")
    equations = "\n".join(f"    {left(s)} = {f}" for s, f in zip(states, dynamics))
    text = f"state {', '.join(states)}\ndynamics {time} {{\n{equations}\n}}\n{rest}"
    return fossil_dsl.loads(text, "generated.fsl")


def assert_never_certified(spec, functions: dict[str, str], levels=None):
    parsed = {name: fossil_dsl.loads(_with_candidate(spec, text), "c.fsl").synthesis.candidate
              for name, text in functions.items()}
    verdict = judge(Claim(spec, parsed, {}, levels or {}, Fraction(0)), timeout=TIMEOUT)
    assert not verdict.certified, (spec.dynamics, functions, verdict.reason)


def _with_candidate(spec, candidate_text: str) -> str:
    """A tiny spec that only parses the candidate (so it is read by the language's own
    grammar, never evaluated)."""
    states = ", ".join(spec.states)
    zero = "\n".join(f"    {s}' = -{s}" for s in spec.states)
    box = "box([" + ", ".join("-1" for _ in spec.states) + "], [" + \
        ", ".join("1" for _ in spec.states) + "])"
    return (f"state {states}\ndynamics continuous {{\n{zero}\n}}\ndomain {box}\n"
            "prove stable\n"
            f"synthesis {{\n    candidate: {candidate_text}\n}}\n")


STATES = {2: ["x0", "x1"], 3: ["x0", "x1", "x2"]}
BOX = {2: "box([-1, -1], [1, 1])", 3: "box([-1, -1, -1], [1, 1, 1])"}


def unstable_stability(data, time: str):
    n = data.draw(st.sampled_from([2, 3]))
    states = STATES[n]
    matrix = data.draw(unstable_matrix(n))
    dynamics = linear_text(matrix, states)
    if time == "discrete":  # x + A x has an eigenvalue of modulus > 1
        dynamics = [f"{s} + {f}" for s, f in zip(states, dynamics)]
    if data.draw(st.booleans()):  # a cubic term does not change the linearisation
        dynamics[0] += f" - {states[0]}^3"
    spec = spec_of(states, dynamics, f"domain {BOX[n]}\nprove stable\n", time)
    assert_never_certified(spec, {"V": data.draw(candidate(states))})


def unstable_roa(data):
    n = 2
    states = STATES[n]
    dynamics = linear_text(data.draw(unstable_matrix(n)), states)
    rest = (f"domain {BOX[n]}\nset init = box([0.2, 0.2], [0.3, 0.3])\n"
            "prove from init: stable\n")
    spec = spec_of(states, dynamics, rest)
    beta = Fraction(data.draw(st.integers(1, 50)), 10)
    assert_never_certified(spec, {"V": data.draw(candidate(states))}, {"beta": beta})


def roa_through_a_face(data):
    """x' = a x (x - 1): the points of I on D's face x = 1 are equilibria, not the origin
    (the kernel's variant for regions that reach the boundary must refuse it)."""
    states = STATES[2]
    a = to_text_number(Fraction(data.draw(st.integers(1, 8)), 4))
    rest = ("domain box([-0.5, -1], [1, 1])\nset init = box([0.8, -0.2], [1, 0.2])\n"
            "prove from init: stable\n")
    spec = spec_of(states, [f"{a}*x0*(x0 - 1)", "-x1"], rest)
    beta = Fraction(data.draw(st.integers(1, 50)), 10)
    assert_never_certified(spec, {"V": data.draw(candidate(states))}, {"beta": beta})


def unsafe_drift(data):
    """x' = v: the initial box drifts into the unsafe box, which lies on its path."""
    states = STATES[2]
    v = [Fraction(data.draw(st.integers(1, 4)), 4), Fraction(data.draw(st.integers(-4, 4)), 4)]
    t = Fraction(data.draw(st.integers(2, 6)), 4)
    centre = [Fraction(-3, 4), Fraction(0)]
    hit = [c + t * vi for c, vi in zip(centre, v)]
    assume(t * v[0] >= Fraction(3, 10) and all(abs(h) <= Fraction(17, 10) for h in hit))
    unsafe = "box([" + ", ".join(to_text_number(h - Fraction(1, 10)) for h in hit) + "], [" + \
        ", ".join(to_text_number(h + Fraction(1, 10)) for h in hit) + "])"
    rest = (f"domain box([-2, -2], [2, 2])\nset init = box([-0.8, -0.05], [-0.7, 0.05])\n"
            f"set unsafe = {unsafe}\nprove from init: always not unsafe\n")
    spec = spec_of(states, [to_text_number(x) for x in v], rest)
    assert_never_certified(spec, {"B": data.draw(candidate(states, zero_at_origin=False))})


def goal_never_reached(data):
    """x' = a x with a > 0 carries the initial box away from the goal round the origin."""
    states = STATES[2]
    a = to_text_number(Fraction(data.draw(st.integers(1, 8)), 4))
    rest = ("domain box([-2, -2], [2, 2])\nset init = box([0.5, 0.5], [0.6, 0.6])\n"
            "set goal = ball([0, 0], 0.1)\nprove from init: eventually goal\n")
    spec = spec_of(states, [f"{a}*x0", f"{a}*x1"], rest)
    assert_never_certified(spec, {"V": data.draw(candidate(states, zero_at_origin=False))})


CASES = {"stability": lambda d: unstable_stability(d, "continuous"),
         "discrete stability": lambda d: unstable_stability(d, "discrete"),
         "roa": unstable_roa, "roa through a face": roa_through_a_face,
         "safety": unsafe_drift, "reach": goal_never_reached}


@pytest.mark.parametrize("kind", sorted(CASES))
@FAST
@given(data=st.data())
def test_false_property_never_certified(kind, data):
    CASES[kind](data)


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(CASES))
@SLOW
@given(data=st.data())
def test_false_property_never_certified_many(kind, data):
    CASES[kind](data)
