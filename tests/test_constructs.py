"""Every construct of the language reference (/work/shared/fsl-language.md) parses and
checks, and gives the CheckedSpec that the reference describes.

Sections follow the reference: declarations, lexical rules, expressions, set
expressions, properties, the synthesis block, and the whole example. Set membership is
checked with a small exact evaluator of the neutral formulas (Fraction arithmetic only,
no solver), so "(1, 0) is in the closed unit ball but not in the open one" is decided
here, independently of the package's SMT backend.
"""
from __future__ import annotations

import operator
import re
from fractions import Fraction
from pathlib import Path

import pytest

from fossil_dsl import check_text, loads, parse
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.spec import Layer, SampleCounts, TimeDomain

STATES = ("x0", "x1")


# =====================================================================================
# Helpers
# =====================================================================================
def checked(text: str, path: str = "spec.fsl", *, quiet: bool = True):
    """The CheckedSpec of `text`; fails the test on any error (and, if `quiet`, on any
    warning too)."""
    result = check_text(text, path)
    assert result.ok, result.render()
    assert result.spec is not None
    if quiet:
        assert result.diagnostics == (), result.render()
    return result.spec


def edit(text: str, *pairs: str) -> str:
    """`text` with each (old, new) pair replaced; every `old` must occur."""
    for old, new in zip(pairs[::2], pairs[1::2]):
        assert old in text, old
        text = text.replace(old, new)
    return text


def warnings_only_about(result, *names: str) -> bool:
    """True if every warning of `result` names one of the given sets."""
    return all(any(f"`{name}`" in w.message for name in names) for w in result.warnings)


# ---- an exact evaluator for the neutral expressions and formulas ----------------------
_RELATIONS = {"<=": operator.le, "<": operator.lt, ">=": operator.ge, ">": operator.gt}


def evaluate(expr: E.Expr, env: dict[str, Fraction]) -> Fraction:
    """The exact value of a rational expression (abs is the only function allowed)."""
    if isinstance(expr, E.Num):
        return expr.value
    if isinstance(expr, E.Var):
        return env[expr.name]
    if isinstance(expr, E.Add):
        return sum((evaluate(t, env) for t in expr.terms), Fraction(0))
    if isinstance(expr, E.Mul):
        value = Fraction(1)
        for factor in expr.factors:
            value *= evaluate(factor, env)
        return value
    if isinstance(expr, E.Div):
        return evaluate(expr.numerator, env) / evaluate(expr.denominator, env)
    if isinstance(expr, E.Neg):
        return -evaluate(expr.operand, env)
    if isinstance(expr, E.Pow):
        exponent = evaluate(expr.exponent, env)
        assert exponent.denominator == 1, f"no exact value for {expr}"
        return evaluate(expr.base, env) ** int(exponent)
    if isinstance(expr, E.Apply) and expr.func == "abs":
        return abs(evaluate(expr.arg, env))
    raise AssertionError(f"no exact rational value for {expr!r}")


def holds(formula: L.Formula, env: dict[str, Fraction]) -> bool:
    if isinstance(formula, L.Compare):
        return _RELATIONS[formula.relation](evaluate(formula.left, env),
                                            evaluate(formula.right, env))
    if isinstance(formula, L.And):
        return all(holds(a, env) for a in formula.args)
    if isinstance(formula, L.Or):
        return any(holds(a, env) for a in formula.args)
    if isinstance(formula, L.Not):
        return not holds(formula.arg, env)
    if isinstance(formula, L.BoolConst):
        return formula.value
    raise AssertionError(f"not a formula: {formula!r}")


def env_of(coords, states=STATES) -> dict[str, Fraction]:
    """Coordinates as exact rationals; give them as ints or decimal strings, never floats."""
    assert not any(isinstance(c, float) for c in coords), "use strings for exact decimals"
    return {name: Fraction(c) for name, c in zip(states, coords)}


def contains(region: S.SetExpr, coords, states=STATES) -> bool:
    return holds(region.contains_formula(states), env_of(coords, states))


def test_evaluator_self_check():
    """The evaluator the set tests rely on: exact, and every connective means what it says."""
    x, y = E.Var("x0"), E.Var("x1")
    env = env_of(["0.1", "-3"])
    assert evaluate(x * 3, env) == Fraction(3, 10)  # exact, not 0.30000000000000004
    assert evaluate(E.Div(y, E.Add((x, E.Num(1)))), env) == Fraction(-30, 11)
    assert evaluate(E.Pow(y, E.Num(3)), env) == -27
    assert evaluate(E.Apply("abs", y), env) == 3
    one, two = E.Num(1), E.Num(2)
    assert holds(L.Compare("<=", one, one), env) and not holds(L.Compare("<", one, one), env)
    assert holds(L.Compare(">", two, one), env) and not holds(L.Compare(">=", one, two), env)
    assert holds(L.Or((L.FALSE, L.TRUE)), env) and not holds(L.And((L.TRUE, L.FALSE)), env)
    assert holds(L.Not(L.FALSE), env) and not holds(L.Not(L.TRUE), env)


# ---- base specs --------------------------------------------------------------------
# An autonomous system with the origin as equilibrium, on a box that the sets below fit.
AUTONOMOUS = """\
state x0, x1
dynamics continuous {
    x0' = -x0 + x1
    x1' = -x1
}
domain box([-2, -2], [2, 2])
"""

WITH_INPUT = """\
state x0, x1
input u0
dynamics continuous {
    x0' = -x0 + x1 + u0
    x1' = -x1
}
domain box([-2, -2], [2, 2])
"""

# Chosen so that every relation the checker proves holds: init inside the domain, inside
# the interior of the safe set and disjoint from unsafe; goal inside final; final
# disjoint from unsafe; the origin in goal and final.
PROPERTY_SETS = {
    "init": "ball([0, 0], 1)",
    "unsafe": "box([1.5, 1.5], [2, 2])",
    "safe": "box([-1.5, -1.5], [1.5, 1.5])",
    "goal": "ball([0, 0], 0.1)",
    "final": "ball([0, 0], 0.2)",
}


def property_spec(prove: str, inputs: bool = False, extra: str = "") -> str:
    """A spec proving `prove`, declaring exactly the sets it names (so no warnings)."""
    used = set(re.findall(r"[A-Za-z_]\w*", prove))
    sets = "".join(f"set {name} = {value}\n" for name, value in PROPERTY_SETS.items()
                   if name in used)
    return (WITH_INPUT if inputs else AUTONOMOUS) + sets + f"prove {prove}\n" + extra


SAFETY = property_spec("from init: always not unsafe")

PENDULUM = """\
# Inverted pendulum with friction, two inputs: reach-avoid-remain.
spec pendulum_rar

state x0, x1
input u0, u1                      # declaring inputs means: synthesise a feedback controller
const m = 0.15, L = 0.5, g = 9.81, b = 0.1

dynamics continuous {
    x0' = x1 + u0
    x1' = u1 + (m*g*L*sin(x0) - b*x1) / (m*L^2)
}

domain box([-3.5, -3.5], [3.5, 3.5])
set safe  = box([-3, -3], [3, 3])
set init  = box([-2, -2], [2, 2])
set goal  = box([-0.1, -0.1], [0.1, 0.1])
set final = box([-0.2, -0.2], [0.2, 0.2])

prove from init: safe until (goal and always final)

synthesis {
    certificate:  sigmoid(6), square(6)
    certificate2: sigmoid(6), square(6)
    controller:   linear(8)
}
"""


def num(value) -> E.Num:
    return E.Num(Fraction(value))


def box(lower, upper, is_open=False) -> S.Box:
    return S.Box(tuple(map(num, lower)), tuple(map(num, upper)), is_open)


def essentials(spec):
    """What a spec means, without its source positions."""
    return (spec.name, spec.states, spec.inputs, dict(spec.constants), spec.time,
            spec.dynamics, spec.domain, dict(spec.sets), spec.property.form,
            dict(spec.property.roles), spec.synthesis)


# =====================================================================================
# Declarations
# =====================================================================================
def test_spec_declares_the_name():
    spec = checked("spec my_name\n" + SAFETY, path="elsewhere/other_file.fsl")
    assert spec.name == "my_name"
    assert spec.path == "elsewhere/other_file.fsl"


@pytest.mark.parametrize("path, name", [
    ("dir/my_model.fsl", "my_model"),
    ("my_model.fsl", "my_model"),
    ("a/b/pendulum_v2.fsl", "pendulum_v2"),
])
def test_spec_name_defaults_to_the_file_stem(path, name):
    assert checked(SAFETY, path=path).name == name


def test_state_declares_the_states_in_order():
    spec = checked("""\
state b, a, c
dynamics continuous {
    c' = -3*c
    a' = -2*a
    b' = -b
}
domain box([-1, -1, -1], [1, 1, 1])
prove stable
""")
    assert spec.states == ("b", "a", "c")
    # one equation per state, in the order of `state`, not of the block
    assert spec.dynamics == (E.Neg(E.Var("b")), E.Mul((num(-2), E.Var("a"))),
                             E.Mul((num(-3), E.Var("c"))))
    assert spec.summary() == "stability (Lyapunov), 3 states, 0 inputs, continuous time"


def test_input_declares_control_inputs():
    spec = checked(property_spec("from init: stable", inputs=True))
    assert spec.inputs == ("u0",)
    assert spec.has_controller
    assert E.Var("u0") in E.walk(spec.dynamics[0])
    assert spec.summary().endswith("2 states, 1 input, continuous time")
    autonomous = checked(property_spec("from init: stable"))
    assert autonomous.inputs == () and not autonomous.has_controller


def test_const_several_in_one_statement_using_earlier_ones_folded_exactly():
    spec = checked("""\
const a = 0.1, b = a*3
const c = b/a + 2^2, d = -c
state x0, x1
dynamics continuous {
    x0' = -b*x0
    x1' = d*x1 + a*x0
}
domain box([-1, -1], [1, 1])
prove stable
""")
    assert spec.constants["a"] == E.Num(Fraction(1, 10))
    assert spec.constants["b"] == E.Num(Fraction(3, 10))  # not 0.30000000000000004
    assert spec.constants["c"] == E.Num(Fraction(7))
    assert spec.constants["d"] == E.Num(Fraction(-7))
    # the constants are substituted into the dynamics
    assert spec.dynamics[0] == E.Mul((num(Fraction(-3, 10)), E.Var("x0")))
    assert spec.dynamics[1] == E.Add((E.Mul((num(-7), E.Var("x1"))),
                                      E.Mul((num(Fraction(1, 10)), E.Var("x0")))))


def test_dynamics_continuous():
    spec = checked(AUTONOMOUS + "prove stable\n")
    assert spec.time is TimeDomain.CONTINUOUS
    assert spec.dynamics == (E.Add((E.Neg(E.Var("x0")), E.Var("x1"))), E.Neg(E.Var("x1")))
    assert spec.summary() == "stability (Lyapunov), 2 states, 0 inputs, continuous time"


def test_dynamics_discrete():
    spec = checked("""\
state x0, x1
dynamics discrete {
    next(x0) = x0/2 + x1/4
    next(x1) = 0.9*x1
}
domain box([-1, -1], [1, 1])
set init = ball([0, 0], 0.5)
prove from init: stable
""")
    assert spec.time is TimeDomain.DISCRETE
    env = env_of(["0.4", "-0.8"])
    assert evaluate(spec.dynamics[0], env) == Fraction(4, 10) / 2 - Fraction(8, 10) / 4
    assert evaluate(spec.dynamics[1], env) == Fraction(9, 10) * Fraction(-8, 10)
    assert spec.summary() == ("region of attraction (ROA), 2 states, 0 inputs, "
                              "discrete time")


def test_domain():
    spec = checked(edit(AUTONOMOUS, "box([-2, -2], [2, 2])", "box([-2.5, -1], [2.5, 1])")
                   + "prove stable\n")
    assert spec.domain == box(["-2.5", -1], ["2.5", 1])
    assert spec.property.role("domain") == spec.domain
    assert contains(spec.domain, ["2.5", "-1"]) and not contains(spec.domain, ["0", "1.01"])


def test_set_declarations_are_named_sets():
    spec = checked(SAFETY)
    assert set(spec.sets) == {"init", "unsafe"}
    assert spec.sets["init"] == S.Named("init", S.Ball((num(0), num(0)), num(1)))
    assert spec.sets["unsafe"] == S.Named("unsafe", box(["1.5", "1.5"], [2, 2]))
    assert spec.property.role("initial") == spec.sets["init"]


def test_prove_and_synthesis_declarations():
    spec = checked(SAFETY + "synthesis {\n    seed: 7\n}\n")
    assert spec.property.form == "safety"
    assert spec.property.certificate == "barrier"
    assert spec.synthesis.seed == 7
    assert spec.summary() == "safety (barrier), 2 states, 0 inputs, continuous time"


def test_declarations_in_any_order():
    spec = checked("""\
prove from init: always not unsafe
synthesis { seed: 3 }
set init = inner & ball([0, 0], 1)
set inner = box([-0.5, -0.5], [0.5, 0.5])
domain box([-k, -k], [k, k])
set unsafe = box([1.5, 1.5], [2, 2])
dynamics discrete {
    next(x1) = x1 / k
    next(x0) = k*x0/4 + u0
}
input u0
const k = 2
state x0, x1
spec late_name
""")
    assert spec.name == "late_name"
    assert spec.states == ("x0", "x1") and spec.inputs == ("u0",)
    assert spec.constants["k"] == num(2)
    assert spec.domain == box([-2, -2], [2, 2])  # the constant declared later is used
    assert spec.dynamics == (E.Add((E.Mul((num(Fraction(1, 2)), E.Var("x0"))), E.Var("u0"))),
                             E.Mul((num(Fraction(1, 2)), E.Var("x1"))))
    assert spec.property.form == "safety"
    assert spec.synthesis.seed == 3
    init = spec.property.role("initial")
    # `inner`, declared after `init`, is used by it: the intersection of box and ball
    assert init.value == S.Intersection(spec.sets["inner"], S.Ball((num(0), num(0)), num(1)))
    assert contains(init, ["0.5", "0.5"]) and not contains(init, ["0.6", "0"])


# =====================================================================================
# Lexical rules
# =====================================================================================
PLAIN = """\
state x0, x1
const k = 3
dynamics continuous {
    x0' = -k*x0 + x1
    x1' = -(x0 + x1)
}
domain box([-1, -1], [1, 1])
set init = ball([0, 0], 0.5)
prove from init: stable
synthesis {
    seed: 1
}
"""

COMMENTED = """\
# a comment on the first line
state x0, x1   # after a statement
const k = (1 +   # inside parentheses spanning lines
           2)    # after the closing one
# a comment between statements

dynamics continuous {   # after the opening brace
    # a whole-line comment in the block
    x0' = -k*x0 + x1    # after an equation
    x1' = -(x0 # inside parentheses
            + x1)
}   # after the closing brace
domain box([-1,   # inside a bracket spanning lines
            -1],
           [1, 1])
set init = ball([0, 0], 0.5)#no space needed
prove from init: stable  # after the property
synthesis {   # in the options block
    # a comment line
    seed: 1   # after an option
}
# the last line is a comment
"""


def test_comments_anywhere():
    assert essentials(checked(COMMENTED)) == essentials(checked(PLAIN))


@pytest.mark.parametrize("text, value", [
    ("3", Fraction(3)),
    ("-0.5", Fraction(-1, 2)),
    ("1e-3", Fraction(1, 1000)),
    ("2.5E+2", Fraction(250)),
    ("0.1", Fraction(1, 10)),
    ("1E3", Fraction(1000)),
    ("0.15", Fraction(3, 20)),
    ("9.81", Fraction(981, 100)),
])
def test_numbers_are_exact_decimals(text, value):
    spec = checked(f"const c = {text}\n"
                   + edit(AUTONOMOUS, "x1' = -x1", "x1' = -x1 + c*x0") + "prove stable\n")
    assert spec.constants["c"] == E.Num(value)
    assert spec.dynamics[1] == E.Add((E.Neg(E.Var("x1")), E.Mul((E.Num(value), E.Var("x0")))))


def test_decimal_is_not_the_nearest_binary_float():
    spec = checked("const c = 0.1\n" + edit(AUTONOMOUS, "-x1\n", "-c*x1\n") + "prove stable\n")
    assert spec.constants["c"].value == Fraction(1, 10) != Fraction(0.1)
    goal = checked(property_spec("from init: eventually goal")).sets["goal"]
    assert goal.value.radius == E.Num(Fraction(1, 10))


def test_line_continuation_outside_brackets():
    text = edit(PLAIN, "state x0, x1", "state x0, \\\n      x1",
                "x0' = -k*x0 + x1", "x0' = -k*x0 \\\n          + x1",
                "prove from init: stable", "prove from init: \\\n    stable")
    assert essentials(checked(text)) == essentials(checked(PLAIN))
    crlf = text.replace("\n", "\r\n")  # a backslash before CRLF continues the line too
    assert essentials(checked(crlf)) == essentials(checked(PLAIN))
    # without the backslash, the newline ends the statement
    assert not check_text(edit(PLAIN, "x0' = -k*x0 + x1", "x0' = -k*x0\n          + x1")).ok
    # except after a comma, where no statement can end (an extension: docs/language.md)
    after_comma = edit(PLAIN, "state x0, x1", "state x0,\n      x1")
    assert essentials(checked(after_comma)) == essentials(checked(PLAIN))


def test_newlines_inside_parentheses_and_brackets():
    text = edit(PLAIN, "x1' = -(x0 + x1)", "x1' = -(x0\n        +\n        x1)",
                "domain box([-1, -1], [1, 1])",
                "domain box(\n    [-1,\n     -1],\n    [1, 1]\n)",
                "prove from init: stable", "prove from (\n    init\n): (\n    stable\n)")
    assert essentials(checked(text)) == essentials(checked(PLAIN))
    # the same newline outside a bracket ends the statement
    assert not check_text(edit(PLAIN, "x1' = -(x0 + x1)", "x1' = -x0\n + x1")).ok


def test_crlf_line_endings():
    crlf = PENDULUM.replace("\n", "\r\n")
    assert "\r\n" in crlf
    assert parse(crlf) == parse(PENDULUM)  # same tree, same positions
    assert essentials(checked(crlf)) == essentials(checked(PENDULUM))
    assert essentials(checked(COMMENTED.replace("\n", "\r\n"))) == essentials(checked(PLAIN))


@pytest.mark.parametrize("text", [
    PLAIN.rstrip("\n"),  # ends with the `}` of the synthesis block
    SAFETY.rstrip("\n"),  # ends with the property
    SAFETY + "# a comment and no newline",
    PENDULUM.replace("\n", "\r\n").rstrip("\r\n"),
])
def test_file_without_final_newline(text):
    assert not text.endswith(("\n", "\r"))
    spec = checked(text)
    assert essentials(spec) == essentials(checked(text + "\n"))


# =====================================================================================
# Expressions
# =====================================================================================
ARITHMETIC = [
    # (expression over x0 and x1, its value as a Python function of Fractions)
    ("x0 + x1", lambda x, y: x + y),
    ("x0 - x1", lambda x, y: x - y),
    ("x0 * x1", lambda x, y: x * y),
    ("x0 / (1 + x1^2)", lambda x, y: x / (1 + y**2)),
    ("-x0", lambda x, y: -x),
    ("x0 - x1 - 1", lambda x, y: (x - y) - 1),  # left-associative
    ("x0 / 2 / x1", lambda x, y: (x / 2) / y),
    ("x0 + 2 * x1", lambda x, y: x + 2 * y),  # * before +
    ("(x0 + 2) * x1", lambda x, y: (x + 2) * y),  # parentheses
    ("x0 * x1^2", lambda x, y: x * y**2),  # ^ before *
    ("-x0^2", lambda x, y: -(x**2)),  # -x^2 is -(x^2)
    ("(-x0)^2", lambda x, y: x**2),
    ("x0**3 - x1^3", lambda x, y: x**3 - y**3),  # ** and ^ alike
    ("2*-x1", lambda x, y: -2 * y),
    ("abs(x0 - x1)", lambda x, y: abs(x - y)),
]


@pytest.mark.parametrize("text, meaning", ARITHMETIC, ids=[a[0] for a in ARITHMETIC])
def test_arithmetic(text, meaning):
    # a safety property, so the dynamics need not vanish at the origin
    spec = checked(edit(SAFETY, "x0' = -x0 + x1", f"x0' = {text}"))
    for coords in (["1.5", "-0.75"], ["-3", "0.2"], ["0.1", "7"]):
        x, y = env_of(coords).values()
        assert evaluate(spec.dynamics[0], env_of(coords)) == meaning(x, y), coords


def test_unary_minus_binds_looser_than_power():
    spec = checked(edit(SAFETY, "x0' = -x0 + x1", "x0' = -x0^2",
                        "x1' = -x1", "x1' = (-x1)^2"))
    assert spec.dynamics[0] == E.Neg(E.Pow(E.Var("x0"), num(2)))
    assert spec.dynamics[1] == E.Pow(E.Neg(E.Var("x1")), num(2))


def test_caret_and_double_star_mean_the_same():
    caret = checked(edit(SAFETY, "x0' = -x0 + x1", "x0' = -x0^3 + x1^2"))
    stars = checked(edit(SAFETY, "x0' = -x0 + x1", "x0' = -x0**3 + x1**2"))
    assert caret.dynamics == stars.dynamics
    assert caret.dynamics[0] == E.Add((E.Neg(E.Pow(E.Var("x0"), num(3))),
                                       E.Pow(E.Var("x1"), num(2))))


@pytest.mark.parametrize("text, value", [
    ("2*3^2", 18),  # ^ before *
    ("2*3**2", 18),
    ("-2^2", -4),  # -(2^2)
    ("(-2)^2", 4),
    ("(1 + 2) * 3", 9),
    ("1 + 2 * 3", 7),
    ("2^-1", Fraction(1, 2)),
    ("7 - 2 - 1", 4),
    ("1/3", Fraction(1, 3)),
])
def test_constant_expressions_are_folded_exactly(text, value):
    spec = checked(f"const c = {text}\n"
                   + edit(AUTONOMOUS, "x1' = -x1", "x1' = -x1 + c*x0") + "prove stable\n")
    assert spec.constants["c"] == E.Num(Fraction(value))


def test_pi():
    spec = checked("const tau = 2*pi\n"
                   + edit(SAFETY, "x0' = -x0 + x1", "x0' = -x0 + pi*x1 + tau"))
    assert spec.constants["tau"] == E.Mul((num(2), E.Pi()))
    assert sum(isinstance(node, E.Pi) for node in E.walk(spec.dynamics[0])) == 2
    assert not traversal.is_arithmetic(spec.dynamics[0])  # pi is not a rational number


FUNCTIONS = [
    # (function, its use in x0' (vanishing at the origin), the argument it is applied to)
    ("sin", "sin(x0)", E.Var("x0")),
    ("cos", "cos(x0) - 1", E.Var("x0")),
    ("tan", "tan(x0)", E.Var("x0")),
    ("exp", "exp(x0) - 1", E.Var("x0")),
    ("log", "log(1 + x0)", E.Add((E.Var("x0"), num(1)))),
    ("sqrt", "sqrt(1 + x0) - 1", E.Add((E.Var("x0"), num(1)))),
    ("tanh", "tanh(x0)", E.Var("x0")),
    ("atan", "atan(x0)", E.Var("x0")),
    ("abs", "abs(x0)", E.Var("x0")),
]


@pytest.mark.parametrize("func, use, arg", FUNCTIONS, ids=[f[0] for f in FUNCTIONS])
def test_functions(func, use, arg):
    spec = checked(f"""\
state x0, x1
dynamics continuous {{
    x0' = -x1 + {use}
    x1' = -x1
}}
domain box([-0.5, -0.5], [0.5, 0.5])
prove stable
""")  # quiet: f(0) = 0 is proved exactly by folding func at 0
    applied = [node for node in E.walk(spec.dynamics[0]) if isinstance(node, E.Apply)]
    assert applied == [E.Apply(func, arg)]
    assert E.Var("x1") in E.walk(spec.dynamics[0])


def test_constants_are_substituted_into_the_dynamics():
    spec = checked(PENDULUM)
    used = set().union(*(E.free_vars(f) for f in spec.dynamics))
    assert used == {"x0", "x1", "u0", "u1"}  # no m, L, g, b
    # x1' = u1 + (m*g*L*sin(x0) - b*x1) / (m*L^2), with the constants' exact values
    m, L_, g, b = Fraction("0.15"), Fraction("0.5"), Fraction("9.81"), Fraction("0.1")
    numerator = E.Add((E.Mul((num(m * g * L_), E.Apply("sin", E.Var("x0")))),
                       E.Mul((num(-b), E.Var("x1")))))
    assert spec.dynamics[1] == E.Add((E.Var("u1"),
                                      E.Mul((num(1 / (m * L_**2)), numerator))))


# =====================================================================================
# Set expressions (membership decided exactly by the evaluator above)
# =====================================================================================
SET_CASES = [
    # (id, set expression, points inside, points outside); the domain is box([-2,-2],[2,2])
    ("box", "box([-1, -1], [1, 1])",
     [("1", "1"), ("0", "0"), ("-1", "0.5")], [("1.01", "0"), ("0", "-1.5")]),
    ("ball", "ball([0, 0], 1)",
     [("1", "0"), ("0.6", "0.8"), ("0", "0")], [("0.8", "0.8"), ("1.01", "0")]),
    ("ball-off-centre", "ball([1, -1], 0.5)",
     [("1.5", "-1"), ("1", "-1.5")], [("0", "0"), ("1.5", "-1.5")]),
    ("ellipsoid", "ellipsoid([0, 0], [1, 2])",
     [("0", "2"), ("1", "0"), ("0.6", "1.6")], [("0", "2.01"), ("1", "1")]),
    ("open-box", "open box([-1, -1], [1, 1])",
     [("0.99", "-0.99"), ("0", "0")], [("1", "0"), ("0", "-1")]),
    ("open-ball", "open ball([0, 0], 1)",
     [("0.99", "0"), ("0.59", "0.8")], [("1", "0"), ("0.6", "0.8")]),
    ("open-ellipsoid", "open ellipsoid([0, 0], [1, 2])",
     [("0", "1.99"), ("0.5", "1")], [("0", "2"), ("0.6", "1.6")]),
    ("semialgebraic", "{ x0 <= 1, x1 < 1, x0 + x1 >= -1, x0*x1 > -1 }",
     [("1", "0"), ("-0.5", "-0.5"), ("1", "-0.9")],
     [("1.1", "0"), ("0", "1"), ("-0.6", "-0.5"), ("1", "-1")]),
    ("semialgebraic-const", "{ x0^2 + x1^2 <= r^2 }",
     [("0.3", "0.4"), ("0", "0")], [("0.3", "0.41")]),
    ("union", "box([-1, -1], [0, 0]) | ball([1, 1], 0.5)",
     [("-1", "-1"), ("0", "0"), ("1", "1.5")], [("0.5", "-0.5"), ("1", "1.6")]),
    ("intersection", "box([-1, -1], [1, 1]) & ball([1, 1], 1)",
     [("1", "1"), ("0.5", "0.5")], [("1.5", "1.5"), ("-0.5", "-0.5")]),
    ("difference", "box([-1, -1], [1, 1]) - ball([0, 0], 0.5)",
     [("1", "1"), ("0.6", "0")], [("0.5", "0"), ("0", "0"), ("1.5", "0")]),
    ("complement", "~box([-1, -1], [1, 1])",  # relative to the domain
     [("1.5", "0"), ("2", "2"), ("1.01", "0")], [("0", "0"), ("1", "1"), ("3", "0")]),
    ("named", "init",
     [("0.5", "0"), ("0", "-0.5")], [("0.6", "0")]),
    ("annulus", "ball([0, 0], 1) - ball([0, 0], 0.01)",
     [("0.5", "0"), ("1", "0"), ("0.02", "0"), ("0", "-0.011")],
     [("0", "0"), ("0.01", "0"), ("0.005", "0.005"), ("1.01", "0")]),
    ("parenthesised", "(box([-1, -1], [1, 1]) - (ball([0, 0], 0.5) | ball([1, 1], 0.5)))",
     [("-1", "-1"), ("0.6", "0")], [("0", "0"), ("1", "1"), ("0.5", "1")]),
]


def set_spec(expression: str) -> str:
    return ("const r = 0.5\n" + AUTONOMOUS + "set init = ball([0, 0], 0.5)\n"
            + "set unsafe = box([1.5, 1.5], [2, 2])\n"
            + f"set s = {expression}\nprove from init: always not unsafe\n")


@pytest.mark.parametrize("expression, inside, outside", [c[1:] for c in SET_CASES],
                         ids=[c[0] for c in SET_CASES])
def test_set_forms(expression, inside, outside):
    result = check_text(set_spec(expression))
    assert result.ok, result.render()
    assert warnings_only_about(result, "s", "r"), result.render()  # s is not in the property
    region = result.spec.sets["s"]
    assert isinstance(region, S.Named) and region.name == "s"
    for point in inside:
        assert contains(region, point), f"{point} should be in {expression}"
    for point in outside:
        assert not contains(region, point), f"{point} should not be in {expression}"


def test_set_form_nodes():
    """The neutral set each form builds."""
    def value(expression):
        return checked(set_spec(expression), quiet=False).sets["s"].value

    spec = checked(set_spec("init"), quiet=False)
    unit_box = box([-1, -1], [1, 1])
    unit_ball = S.Ball((num(0), num(0)), num(1))
    assert value("box([-1, -1], [1, 1])") == unit_box
    assert value("open box([-1, -1], [1, 1])") == box([-1, -1], [1, 1], is_open=True)
    assert value("ball([0, 0], 1)") == unit_ball
    assert value("open ball([0, 0], 1)") == S.Ball((num(0), num(0)), num(1), is_open=True)
    assert value("ellipsoid([0, 0], [1, 2])") == S.Ellipsoid((num(0), num(0)), (num(1), num(2)))
    assert value("open ellipsoid([0, 0], [1, 2])") == S.Ellipsoid(
        (num(0), num(0)), (num(1), num(2)), is_open=True)
    assert value("box([-1, -1], [1, 1]) | ball([0, 0], 1)") == S.Union(unit_box, unit_ball)
    assert value("box([-1, -1], [1, 1]) & ball([0, 0], 1)") == S.Intersection(unit_box, unit_ball)
    assert value("box([-1, -1], [1, 1]) - ball([0, 0], 1)") == S.Difference(unit_box, unit_ball)
    assert value("~box([-1, -1], [1, 1])") == S.Complement(unit_box, spec.domain)
    assert spec.sets["s"].value == spec.sets["init"]
    semi = value("{ x0 <= 1, x1 < 1, x0 >= -1, x1 > -1 }")
    assert isinstance(semi, S.Semialgebraic)
    assert [c.relation for c in semi.constraints] == ["<=", "<", ">=", ">"]


def test_semialgebraic_set_across_several_lines():
    one_line = checked(set_spec("{ x0 <= 1, x1 < 1, x0 + x1 >= -1, x0*x1 > -1 }"),
                       quiet=False).sets["s"]
    several = checked(set_spec("""{
    x0 <= 1,            # right edge
    x1 < 1,

    x0 + x1 >= -1,      # a half-plane
    x0*x1 > -1
}"""), quiet=False).sets["s"]
    assert several == one_line
    assert len(several.value.constraints) == 4


def test_set_used_before_its_declaration():
    spec = checked(AUTONOMOUS + """\
set init = core | rim
set core = ball([0, 0], 0.25)
set rim = ball([0, 0], 1) - ball([0, 0], 0.5)
set unsafe = box([1.5, 1.5], [2, 2])
prove from init: always not unsafe
""")
    init = spec.sets["init"]
    assert init.value == S.Union(spec.sets["core"], spec.sets["rim"])
    assert contains(init, ["0.25", "0"]) and contains(init, ["0.75", "0"])
    assert not contains(init, ["0.4", "0"]) and not contains(init, ["1.1", "0"])


def test_annulus_domain():
    spec = checked("""\
state x0, x1
input u0
dynamics continuous {
    x0' = x1 - x0^3
    x1' = u0
}
domain ball([0, 0], 1) - ball([0, 0], 0.01)
set init = ball([0.5, 0.5], 0.1)
set unsafe = ball([-0.5, -0.5], 0.1)
prove from init: always not unsafe
synthesis {
    certificate: sigmoid(5), square(5)
    controller: linear(5)
}
""")
    assert spec.domain == S.Difference(S.Ball((num(0), num(0)), num(1)),
                                       S.Ball((num(0), num(0)), num(Fraction(1, 100))))
    assert spec.property.role("domain") == spec.domain
    assert contains(spec.domain, ["0.5", "0.5"]) and not contains(spec.domain, ["0", "0"])
    assert not contains(spec.domain, ["0.01", "0"]) and contains(spec.domain, ["0", "1"])


# =====================================================================================
# Properties: every row of the reference's table, in several equivalent arrangements
# =====================================================================================
SWA, RWA, RSWA, RAR = ("stable while avoid", "reach while avoid",
                       "reach and stay while avoid", "reach-avoid-remain")
U_ROLES = {"unsafe": "unsafe", "safe": "~unsafe"}  # `not U`: safe = domain minus U
S_ROLES = {"safe": "&safe", "unsafe": "~safe"}  # `S`: safe = S within D, unsafe = D minus S

PROPERTIES = [
    # (id, formula, form, certificate, roles other than domain and initial, max_iters)
    ("stability", "stable", "stability", "Lyapunov", {}, 25),
    ("roa", "from init: stable", "region of attraction", "ROA", {}, 25),
    ("roa-parens", "from init: (stable)", "region of attraction", "ROA", {}, 25),
    ("safety", "from init: always not unsafe", "safety", "barrier", U_ROLES, 25),
    ("safety-tilde", "from init: always ~unsafe", "safety", "barrier", U_ROLES, 25),
    ("safety-safe-set", "from init: always safe", "safety", "barrier", S_ROLES, 25),
    ("safety-double-not", "from init: always not not safe", "safety", "barrier", S_ROLES, 25),
    ("safety-triple-not", "from init: always not not not unsafe", "safety", "barrier",
     U_ROLES, 25),
    ("safety-parens", "from init: (always (not (unsafe)))", "safety", "barrier", U_ROLES, 25),
    ("swa", "from init: stable and always not unsafe", SWA, "ROA + barrier", U_ROLES, 100),
    ("swa-swapped", "from init: always not unsafe and stable", SWA, "ROA + barrier",
     U_ROLES, 100),
    ("swa-safe-set", "from init: always safe and stable", SWA, "ROA + barrier", S_ROLES, 100),
    ("swa-tilde", "from init: (stable) and (always ~unsafe)", SWA, "ROA + barrier",
     U_ROLES, 100),
    ("rwa", "from init: not unsafe until goal", RWA, "reach-while-avoid",
     {**U_ROLES, "goal": "goal"}, 25),
    ("rwa-tilde", "from init: ~unsafe until goal", RWA, "reach-while-avoid",
     {**U_ROLES, "goal": "goal"}, 25),
    ("rwa-safe-set", "from init: safe until goal", RWA, "reach-while-avoid",
     {**S_ROLES, "goal": "goal"}, 25),
    ("rwa-double-not", "from init: not not (safe until goal)", RWA, "reach-while-avoid",
     {**S_ROLES, "goal": "goal"}, 25),
    ("rwa-parens", "from init: ((not unsafe) until (goal))", RWA, "reach-while-avoid",
     {**U_ROLES, "goal": "goal"}, 25),
    ("rswa", "from init: not unsafe until always final", RSWA, "RWA + stay level set",
     {**U_ROLES, "final": "final"}, 25),
    ("rswa-safe-set", "from init: safe until always final", RSWA, "RWA + stay level set",
     {**S_ROLES, "final": "final"}, 25),
    ("rswa-tilde-parens", "from init: ~unsafe until (always (final))", RSWA,
     "RWA + stay level set", {**U_ROLES, "final": "final"}, 25),
    ("rar", "from init: not unsafe until (goal and always final)", RAR, "RWA + barrier",
     {**U_ROLES, "goal": "goal", "final": "final"}, 100),
    ("rar-swapped", "from init: not unsafe until (always final and goal)", RAR,
     "RWA + barrier", {**U_ROLES, "goal": "goal", "final": "final"}, 100),
    ("rar-safe-set", "from init: safe until (goal and always final)", RAR, "RWA + barrier",
     {**S_ROLES, "goal": "goal", "final": "final"}, 100),
    ("rar-tilde-double-not", "from init: ~unsafe until (always final and not not goal)", RAR,
     "RWA + barrier", {**U_ROLES, "goal": "goal", "final": "final"}, 100),
    ("reach", "from init: eventually goal", "reach", "RWA with the safe set = the domain",
     {"goal": "goal", "safe": "domain"}, 25),
    ("reach-parens", "from init: (eventually (goal))", "reach",
     "RWA with the safe set = the domain", {"goal": "goal", "safe": "domain"}, 25),
]


def expected_role(spec, description: str) -> S.SetExpr:
    if description == "domain":
        return spec.domain
    if description.startswith("~"):
        return S.Complement(spec.sets[description[1:]], spec.domain)
    if description.startswith("&"):  # a given safe set, taken within the domain
        return S.Intersection(spec.sets[description[1:]], spec.domain)
    return spec.sets[description]


@pytest.mark.parametrize("inputs", [False, True], ids=["autonomous", "with-input"])
@pytest.mark.parametrize("formula, form, certificate, roles, max_iters",
                         [p[1:] for p in PROPERTIES], ids=[p[0] for p in PROPERTIES])
def test_property_forms(formula, form, certificate, roles, max_iters, inputs):
    spec = checked(property_spec(formula, inputs=inputs))
    prop = spec.property
    assert prop.form == form
    assert prop.certificate == certificate
    expected = {"domain": "domain", **roles}
    if formula.startswith("from "):
        expected["initial"] = "init"
    assert set(prop.roles) == set(expected)
    for role, description in expected.items():
        assert prop.role(role) == expected_role(spec, description), role
    for role in {"initial", "unsafe", "safe", "goal", "final"} - set(expected):
        assert prop.role(role) is None
    assert spec.synthesis.max_iters == max_iters  # the default for this form
    assert spec.summary().startswith(f"{form} ({certificate}), 2 states, "
                                     f"{1 if inputs else 0} input")


def test_safe_set_and_unsafe_set_are_complements_within_the_domain():
    spec = checked(property_spec("from init: safe until goal"))
    safe, unsafe = spec.property.role("safe"), spec.property.role("unsafe")
    assert contains(safe, ["1.5", "0"]) and not contains(unsafe, ["1.5", "0"])
    assert contains(unsafe, ["1.8", "0"]) and not contains(safe, ["1.8", "0"])
    assert not contains(unsafe, ["3", "0"])  # outside the domain: not unsafe
    spec = checked(property_spec("from init: always not unsafe"))
    safe, unsafe = spec.property.role("safe"), spec.property.role("unsafe")
    assert contains(unsafe, ["1.5", "1.5"]) and not contains(safe, ["1.5", "1.5"])
    assert contains(safe, ["1.5", "1.49"]) and not contains(unsafe, ["1.5", "1.49"])
    assert not contains(safe, ["2.1", "0"])  # outside the domain: not safe


def test_initial_set_may_be_a_set_expression():
    spec = checked(AUTONOMOUS + "set unsafe = box([1.5, 1.5], [2, 2])\n"
                   "prove from ball([0, 0], 1) - ball([0, 0], 0.5): always not unsafe\n")
    initial = spec.property.role("initial")
    assert initial == S.Difference(S.Ball((num(0), num(0)), num(1)),
                                   S.Ball((num(0), num(0)), num(Fraction(1, 2))))


# =====================================================================================
# The synthesis block
# =====================================================================================
# SWA uses two functions, and the input allows a controller: every key applies.
def as_map(text: str) -> str:
    """The spec with WITH_INPUT's flow replaced by a map: every layer key may then hold
    relu, which a flow's certificate may not (its kinks leave dV/dt undefined)."""
    return edit(text, "dynamics continuous {\n    x0' = -x0 + x1 + u0\n    x1' = -x1\n}",
                "dynamics discrete {\n    next(x0) = 0.5*x0 + 0.1*x1 + u0\n"
                "    next(x1) = 0.5*x1\n}")


SYNTHESIS_BASE = as_map(property_spec("from init: stable and always not unsafe", inputs=True))
SAFETY_BASE = as_map(property_spec("from init: always not unsafe", inputs=True))
x0, x1 = E.Var("x0"), E.Var("x1")

SYNTHESIS_KEYS = [
    # (option line, attribute of SynthesisOptions, expected value)
    ("certificate: sigmoid(6), square(6)", "certificate",
     (Layer("sigmoid", 6), Layer("square", 6))),
    ("certificate2: poly4(3), relu(2), linear(1)", "certificate2",
     (Layer("poly4", 3), Layer("relu", 2), Layer("linear", 1))),
    ("controller: linear(8)", "controller", (Layer("linear", 8),)),
    ("controller: tanh(4), linear(2)", "controller", (Layer("tanh", 4), Layer("linear", 2))),
    ("candidate: x0^2 + 2*x1^2", "candidate", x0**2 + 2 * x1**2),
    ("candidate2: x0^2 + x1^2 - 1", "candidate2", x0**2 + x1**2 - 1),
    ("verifier: z3", "verifier", "z3"),
    ("verifier: cvc5", "verifier", "cvc5"),
    ("verifier: dreal", "verifier", "dreal"),
    ("verifier: interval", "verifier", "interval"),
    ("samples: 500", "samples", SampleCounts(default=500)),
    ("max_iters: 7", "max_iters", 7),
    ("seed: 42", "seed", 42),
    ("timeout: 12.5", "timeout", Fraction(25, 2)),
    ("learning_rate: 1e-3", "learning_rate", Fraction(1, 1000)),
    ("margin: 0.5", "margin", Fraction(1, 2)),
    ("margin: 0", "margin", Fraction(0)),
    ("delta: 0.001", "delta", Fraction(1, 1000)),
]


@pytest.mark.parametrize("line, attribute, value", SYNTHESIS_KEYS,
                         ids=[k[0] for k in SYNTHESIS_KEYS])
def test_synthesis_keys(line, attribute, value):
    spec = checked(SYNTHESIS_BASE + f"synthesis {{\n    {line}\n}}\n")
    assert getattr(spec.synthesis, attribute) == value
    # the other keys keep their defaults
    defaults = checked(SYNTHESIS_BASE).synthesis
    for other in ("certificate", "certificate2", "candidate", "candidate2", "controller",
                  "verifier", "samples", "max_iters", "seed", "timeout", "learning_rate",
                  "margin", "delta"):
        if other != attribute:
            assert getattr(spec.synthesis, other) == getattr(defaults, other), other


ACTIVATIONS = ["linear", "square", "cube", "poly2", "poly3", "poly4", "relu", "sigmoid",
               "tanh", "softplus"]


@pytest.mark.parametrize("key", ["certificate", "certificate2", "controller"])
@pytest.mark.parametrize("activation", ACTIVATIONS)
def test_every_activation_in_every_layer_key(key, activation):
    # V of SWA must not be odd (test_malformed: `odd-lyapunov-*`); a barrier's layers,
    # with biases, may be any
    base = SAFETY_BASE if key == "certificate" else SYNTHESIS_BASE
    spec = checked(base + f"synthesis {{\n    {key}: {activation}(3)\n}}\n")
    assert getattr(spec.synthesis, key) == (Layer(activation, 3),)


def test_layers_keep_their_order_and_widths():
    layers = ", ".join(f"{a}({i + 1})" for i, a in enumerate(ACTIVATIONS))
    spec = checked(SYNTHESIS_BASE + f"synthesis {{ certificate: {layers} }}\n")
    assert spec.synthesis.certificate == tuple(Layer(a, i + 1)
                                               for i, a in enumerate(ACTIVATIONS))
    assert [str(layer) for layer in spec.synthesis.certificate][:2] == ["linear(1)",
                                                                         "square(2)"]


def test_samples_per_set_and_domain():
    spec = checked(SYNTHESIS_BASE + "synthesis {\n    samples: init 500, domain 200\n}\n")
    samples = spec.synthesis.samples
    assert samples.default is None
    assert dict(samples.per_set) == {"init": 500, "domain": 200}
    assert samples.count("init", 1000) == 500
    assert samples.count("domain", 1000) == 200
    assert samples.count("unsafe", 1000) == 1000  # the reference's default: 1000 per set


def test_samples_one_number_applies_to_every_set():
    samples = checked(SYNTHESIS_BASE + "synthesis { samples: 300 }\n").synthesis.samples
    assert samples.default == 300 and dict(samples.per_set) == {}
    assert samples.count("init", 1000) == samples.count("domain", 1000) == 300


def test_synthesis_defaults():
    options = checked(SAFETY).synthesis
    assert options.max_iters == 25
    assert options.seed == 0
    assert options.timeout == Fraction(600)
    assert options.samples.count("init", 1000) == 1000
    # no choice made in the spec: the compiler chooses
    assert (options.certificate, options.certificate2, options.candidate, options.candidate2,
            options.controller, options.verifier) == (None,) * 6
    assert (options.learning_rate, options.margin, options.delta) == (None,) * 3


@pytest.mark.parametrize("formula, default", [
    ("from init: always not unsafe", 25),
    ("from init: not unsafe until goal", 25),
    ("from init: stable and always not unsafe", 100),  # SWA
    ("from init: not unsafe until (goal and always final)", 100),  # RAR
])
def test_max_iters_default_and_override(formula, default):
    assert checked(property_spec(formula)).synthesis.max_iters == default
    given = checked(property_spec(formula, extra="synthesis { max_iters: 7 }\n"))
    assert given.synthesis.max_iters == 7


def test_synthesis_block_with_every_key():
    spec = checked(SYNTHESIS_BASE + """\
synthesis {
    certificate2: poly4(6), relu(7)
    candidate:    x0^2 + 2*x1^2
    candidate2:   x0^2 + x1^2
    controller:   linear(2), tanh(3)
    verifier:     cvc5
    samples:      init 500, domain 200, unsafe 30
    max_iters:    7
    seed:         42
    timeout:      12.5
    learning_rate: 0.01
    margin:       0
    delta:        1e-3
}
""")
    options = spec.synthesis
    assert options.certificate is None and options.certificate2 == (Layer("poly4", 6),
                                                                    Layer("relu", 7))
    assert options.candidate == x0**2 + 2 * x1**2 and options.candidate2 == x0**2 + x1**2
    assert options.controller == (Layer("linear", 2), Layer("tanh", 3))
    assert options.verifier == "cvc5"
    assert dict(options.samples.per_set) == {"init": 500, "domain": 200, "unsafe": 30}
    assert (options.max_iters, options.seed, options.timeout) == (7, 42, Fraction(25, 2))
    assert (options.learning_rate, options.margin, options.delta) == (
        Fraction(1, 100), Fraction(0), Fraction(1, 1000))


# =====================================================================================
# The reference's whole example
# =====================================================================================
def test_whole_pendulum_example():
    result = check_text(PENDULUM, "examples/pendulum.fsl")
    assert result.ok, result.render()
    assert result.diagnostics == ()
    spec = result.spec
    assert spec.summary() == ("reach-avoid-remain (RWA + barrier), 2 states, 2 inputs, "
                              "continuous time")
    assert spec.name == "pendulum_rar"
    assert spec.states == ("x0", "x1") and spec.inputs == ("u0", "u1")
    assert dict(spec.constants) == {"m": num(Fraction(3, 20)), "L": num(Fraction(1, 2)),
                                    "g": num(Fraction(981, 100)), "b": num(Fraction(1, 10))}
    assert spec.dynamics[0] == E.Add((x1, E.Var("u0")))
    assert spec.domain == box(["-3.5", "-3.5"], ["3.5", "3.5"])
    assert set(spec.sets) == {"safe", "init", "goal", "final"}
    prop = spec.property
    assert prop.role("safe") == S.Intersection(spec.sets["safe"], spec.domain)
    assert prop.role("unsafe") == S.Complement(spec.sets["safe"], spec.domain)
    assert prop.role("initial") == spec.sets["init"]
    assert prop.role("goal") == spec.sets["goal"] and prop.role("final") == spec.sets["final"]
    assert spec.sets["goal"].value == box(["-0.1", "-0.1"], ["0.1", "0.1"])
    options = spec.synthesis
    assert options.certificate == options.certificate2 == (Layer("sigmoid", 6),
                                                           Layer("square", 6))
    assert options.controller == (Layer("linear", 8),)
    assert options.max_iters == 100  # RAR's default
    # the file shipped with the package is the same example
    shipped = Path(__file__).resolve().parent.parent / "specs" / "pendulum_rar.fsl"
    assert essentials(loads(shipped.read_text(), str(shipped))) == essentials(spec)


# =====================================================================================
# Regressions: bugs found while writing these tests, now fixed
# =====================================================================================
REACH_OUTSIDE_DOMAIN = """\
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-1, -1], [1, 1])
set safe = box([-5, -5], [0.9, 5])
set init = box([-3, -3], [-2, -2])
set goal = ball([0, 0], 0.1)
"""


def test_equivalent_arrangement_rejects_initial_set_outside_the_domain():
    """The `not U` arrangement is rejected (and so is the `S` one, below)."""
    result = check_text(REACH_OUTSIDE_DOMAIN + "set unsafe = ~safe\n"
                        "prove from init: not unsafe until goal\n")
    assert not result.ok
    assert any("`init`" in d.message for d in result.errors), result.render()


@pytest.mark.parametrize("formula", [
    "safe until goal",
    "safe until always goal",
    "safe until (goal and always goal)",
])
def test_safe_set_arrangement_rejects_initial_set_outside_the_domain(formula):
    result = check_text(REACH_OUTSIDE_DOMAIN + f"prove from init: {formula}\n")
    assert not result.ok, "init = box([-3,-3],[-2,-2]) lies outside the domain"


def test_no_unused_warning_for_the_initial_set_of_a_rejected_formula():
    result = check_text(property_spec("from init: always eventually final"))
    assert not result.ok  # the formula is outside the table
    assert not any("`init`" in w.message for w in result.warnings), result.render()
