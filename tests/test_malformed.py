"""A table of malformed specs: each gives an error with the expected message and line,
rendered as FILE:LINE:COL with the source line and a caret."""
import re

import pytest

from fossil_dsl import check_text

BASE = """\
state x0, x1
dynamics continuous {
    x0' = -x0
    x1' = -x1
}
domain box([-1, -1], [1, 1])
set init = box([-0.5, -0.5], [0.5, 0.5])
set unsafe = box([0.8, 0.8], [1, 1])
prove from init: always not unsafe
"""

REACH = BASE.replace("prove from init: always not unsafe", """\
set goal = box([-0.1, -0.1], [0.1, 0.1])
set final = box([-0.2, -0.2], [0.2, 0.2])
prove from init: not unsafe until (goal and always final)""")


def edit(old: str, new: str, base: str = BASE) -> str:
    assert old in base
    return base.replace(old, new)


def synthesis(*lines: str) -> str:
    return BASE + "synthesis {\n" + "".join(f"    {line}\n" for line in lines) + "}\n"


# (id, spec text, expected line of the error, fragment of its message)
CASES = [
    # ---- syntax: the labelled common mistakes ----
    ("unclosed-paren", edit("x0' = -x0", "x0' = -(x0 + 1"), 3, "unclosed parenthesis"),
    ("unclosed-paren-eof", BASE + "set s = box([0, 0], [1, 1]\n", 10, "unclosed parenthesis"),
    ("unclosed-bracket", edit("domain box([-1, -1], [1, 1])", "domain box([-1, -1], [1, 1)"),
     6, "does not match `[`"),
    ("unclosed-bracket-eol", BASE + "set s = box([0, 0, [1, 1])\n", 10, "unexpected `[`"),
    ("unclosed-brace", edit("    x1' = -x1\n}", "    x1' = -x1"), 2, "unclosed brace"),
    ("unclosed-synthesis", BASE + "synthesis {\n    seed: 1\n", 10, "unclosed brace"),
    ("unmatched-closer", edit("[1, 1])", "[1, 1]))"), 6, "unmatched `)`"),
    ("missing-equals-const", "const a 1\n" + BASE, 1, "missing `=`"),
    ("missing-equals-set", edit("set init = box", "set init box"), 7, "missing `=`"),
    ("missing-equals-equation", edit("x0' = -x0", "x0' -x0"), 3, "missing `=`"),
    ("unknown-keyword", edit("state x0, x1", "states x0, x1"), 1,
     "unknown statement `states` (did you mean `state`?)"),
    ("unknown-keyword-prove", edit("prove from", "proof from"), 9, "did you mean `prove`"),
    ("keyword-as-name", edit("state x0, x1", "state x0, next"), 1, "reserved keyword"),
    ("keyword-as-set-name", edit("set unsafe", "set open"), 8, "reserved keyword"),
    ("stray-token", edit("state x0, x1", "state x0, x1 )"), 1, "stray `)`"),
    ("missing-comma", edit("state x0, x1", "state x0 x1"), 1, "is a `,` missing"),
    ("missing-operator", edit("x0' = -x0", "x0' = 2 x0"), 3, "operator"),
    ("incomplete-expression", edit("x0' = -x0", "x0' = -x0 +"), 3, "incomplete statement"),
    ("prime-in-discrete", edit("continuous", "discrete"), 3, "discrete block"),
    ("next-in-continuous", edit("x0' = -x0", "next(x0) = -x0"), 3, "belongs in a discrete block"),
    ("plain-equation", edit("x0' = -x0", "x0 = -x0"), 3, "write the equation as `x0' = ...`"),
    ("bad-time-domain", edit("continuous", "continous"), 2, "did you mean `continuous`"),
    ("open-needs-shape", edit("domain box", "domain open {x0 < 1} | box"), 6,
     "`open` must be followed by a shape"),
    ("shape-as-name", edit("state x0, x1", "state x0, ball"), 1, "reserved keyword"),
    ("shape-as-set-name", edit("set unsafe", "set ellipsoid"), 8, "reserved keyword"),
    ("unknown-shape", edit("domain box", "domain boxes"), 6, "did you mean `box`"),
    ("semicolon", edit("state x0, x1", "state x0, x1;"), 1, "`;` is not used"),
    ("string-literal", edit("-x0\n", "'x0'\n"), 3, "strings are not part"),
    ("attribute-access", edit("-x0\n", "x0.real\n"), 3, "attribute access"),
    ("python-call", "__import__('os').system('true')\n" + BASE, 1, "unknown statement"),
    ("bang", edit("always not", "always !"), 9, "write `not`"),
    ("nul-byte", "state x0\x00\n", 1, "U+0000"),
    ("too-deep-brackets", "state x\ndynamics continuous { x' = " + "(" * 150 + "x"
     + ")" * 150 + " }\n", 2, "nested too deeply"),
    ("too-deep-expression", "state x\ndynamics continuous { x' = " + "+".join(["x"] * 2000)
     + " }\n", 2, "nested too deeply"),
    # ---- names ----
    ("undeclared-name", edit("x0' = -x0", "x0' = -y"), 3, "undeclared name `y`"),
    ("undeclared-suggest", edit("x0' = -x0", "x0' = -x2"), 3, "did you mean"),
    ("input-undeclared", edit("x0' = -x0", "x0' = -x0 + u0"), 3, "undeclared name `u0`"),
    ("declared-twice", edit("state x0, x1", "state x0, x1, x0"), 1, "already declared"),
    ("set-declared-twice", BASE + "set init = box([-1, -1], [1, 1])\n", 10, "already declared"),
    ("name-clash-kinds", "const x0 = 1\n" + BASE, 2, "already declared as a constant"),
    ("second-state-statement", BASE + "state x2\n", 10, "a second `state` statement"),
    ("second-prove", BASE + "prove from init: always unsafe\n", 10, "a second `prove`"),
    ("missing-state", "\n".join(BASE.splitlines()[1:]) + "\n", 1, "no `state` statement"),
    ("missing-prove", BASE.replace("prove from init: always not unsafe\n", ""), 1,
     "no `prove` statement"),
    ("state-without-equation", edit("    x1' = -x1\n", ""), 1, "`x1` has no equation"),
    ("state-with-two-equations", edit("    x1' = -x1\n", "    x1' = -x1\n    x1' = x0\n"),
     5, "two equations"),
    ("equation-for-non-state", edit("    x1' = -x1\n", "    x1' = -x1\n    y' = 1\n"), 5,
     "equations are for states"),
    ("vector-length", edit("box([-1, -1], [1, 1])", "box([-1, -1, -1], [1, 1, 1])"), 6,
     "3 entries but there are 2 states"),
    ("unknown-function", edit("x0' = -x0", "x0' = -sinh(x0)"), 3,
     "unknown function `sinh` (did you mean `sin`?)"),
    ("function-arity", edit("x0' = -x0", "x0' = -sin(x0, x1)"), 3, "takes 1 argument"),
    ("state-called", edit("x0' = -x0", "x0' = -x1(2)"), 3, "is a state, not a function"),
    ("function-as-name", edit("x0' = -x0", "x0' = -sin"), 3, "is a function"),
    ("state-in-constant", "const a = x0\n" + BASE, 1, "`x0` is a state"),
    ("constant-used-before", "const a = b, b = 2\n" + edit("-x0", "-a*b*x0"), 1,
     "declared later"),
    ("input-in-set", edit("prove", "set s = { u > 1 }\nprove",
                          edit("state x0, x1", "state x0, x1\ninput u",
                               edit("-x0\n", "-x0 + u\n"))), 10, "`u` is an input"),
    ("state-in-shape", edit("box([0.8, 0.8]", "box([x0, 0.8]"), 8, "`x0` is a state"),
    ("set-used-as-number", edit("x0' = -x0", "x0' = -init"), 3, "is a set"),
    ("undeclared-set", edit("not unsafe", "not unsafe_region"), 9, "undeclared set"),
    ("state-as-set", edit("not unsafe", "not x0"), 9, "is a state, not a set"),
    ("set-cycle", edit("set unsafe = box([0.8, 0.8], [1, 1])",
                       "set unsafe = other | box([0.8, 0.8], [1, 1])\nset other = unsafe"), 9,
     "defined in terms of itself"),
    ("complement-in-domain", edit("domain box([-1, -1], [1, 1])",
                                  "domain ~box([-1, -1], [1, 1])"), 6, "`~`"),
    # ---- numbers and exact arithmetic ----
    ("division-by-zero", "const a = 1/(2-2)\n" + edit("-x0", "-a*x0"), 1, "division by zero"),
    ("huge-power", "const a = 10^100000\n" + edit("-x0", "-a*x0"), 1, "too large"),
    ("huge-number", "const a = 1e99999999\n" + edit("-x0", "-a*x0"), 1, "out of range"),
    ("log-of-zero", "const a = log(0)\n" + edit("-x0", "-a*x0"), 1, "log of a non-positive"),
    # ---- sets ----
    ("box-lower-above-upper", edit("box([0.8, 0.8], [1, 1])", "box([0.8, 1.2], [1, 1])"), 8,
     "lower bound 1.2 > upper bound 1"),
    ("open-box-flat", edit("box([0.8, 0.8], [1, 1])", "open box([0.8, 1], [1, 1])"), 8,
     "empty box"),
    ("negative-radius", edit("box([0.8, 0.8], [1, 1])", "ball([0.9, 0.9], -0.1)"), 8,
     "radius must be positive"),
    ("zero-semi-axis", edit("box([0.8, 0.8], [1, 1])", "ellipsoid([0.9, 0.9], [0.1, 0])"), 8,
     "semi-axis must be positive"),
    ("shape-arity", edit("box([0.8, 0.8], [1, 1])", "box([0.8, 0.8])"), 8, "takes 2 arguments"),
    ("ball-radius-vector", edit("box([0.8, 0.8], [1, 1])", "ball([0.9, 0.9], [1, 1])"), 8,
     "single number"),
    ("empty-semialgebraic", edit("box([0.8, 0.8], [1, 1])", "{ x0^2 + x1^2 < 0 }"), 8,
     "`unsafe` is empty"),
    # ---- set relations (proved by Z3, with a witness) ----
    ("init-outside-domain", edit("box([-0.5, -0.5], [0.5, 0.5])", "box([-0.5, -0.5], [1.5, 0.5])"),
     7, "`init` is not inside the domain: (1.5,"),
    ("init-meets-unsafe", edit("box([0.8, 0.8], [1, 1])", "ball([0.5, 0.5], 0.1)"), 7,
     "`init` and `unsafe` overlap"),
    ("goal-outside-final", edit("set goal = box([-0.1, -0.1], [0.1, 0.1])",
                                "set goal = box([-0.25, -0.1], [0.1, 0.1])", REACH), 9,
     "`goal` is not inside `final`: (-0.25,"),
    ("final-meets-unsafe", edit("set final = box([-0.2, -0.2], [0.2, 0.2])",
                                "set final = box([-0.2, -0.2], [0.9, 0.9])", REACH), 10,
     "`final` and `unsafe` overlap"),
    ("init-on-safe-boundary", edit("box([-0.5, -0.5], [0.5, 0.5])", "box([-1, -0.5], [0.5, 0.5])",
                                   REACH), 7, "not inside the interior of the safe set"),
    ("origin-outside-goal", edit("x0' = -x0", "x0' = -x0 + u",
                                 edit("state x0, x1", "state x0, x1\ninput u",
                                      edit("set goal = box([-0.1, -0.1], [0.1, 0.1])",
                                           "set goal = box([0.05, 0.05], [0.1, 0.1])", REACH))),
     10, "does not contain the origin"),
    # ---- dynamics facts ----
    ("not-an-equilibrium", edit("prove from init: always not unsafe", "prove stable",
                                edit("x0' = -x0", "x0' = 1 - x0")), 3, "not an equilibrium"),
    ("not-an-equilibrium-transcendental", edit("prove from init: always not unsafe",
                                               "prove stable", edit("x0' = -x0", "x0' = cos(x1) - x0")),
     3, "not an equilibrium"),
    ("undefined-at-origin", edit("prove from init: always not unsafe", "prove stable",
                                 edit("x0' = -x0", "x0' = -1/x0")), 3, "undefined at the origin"),
    # ---- property ----
    ("unsupported-property", edit("always not unsafe", "always not unsafe or eventually init"), 9,
     "nearest supported form is `from I: always not U`"),
    ("needs-initial-set", edit("prove from init: always not unsafe", "prove always not unsafe"), 9,
     "needs an initial set"),
    ("stable-negated", edit("prove from init: always not unsafe", "prove not stable"), 9,
     "unsupported property"),
    # ---- synthesis block ----
    ("unknown-synthesis-key", synthesis("certficate: square(5)"), 11,
     "unknown synthesis key `certficate` (did you mean `certificate`?)"),
    ("bad-activation", synthesis("certificate: sigmod(5)"), 11,
     "unknown activation `sigmod` (did you mean `sigmoid`?)"),
    ("bad-width", synthesis("certificate: square(0)"), 11, "layer width"),
    ("layer-not-call", synthesis("certificate: square"), 11, "ACTIVATION(WIDTH)"),
    ("unknown-verifier", synthesis("verifier: z4"), 11, "unknown verifier `z4`"),
    ("duplicate-key", synthesis("seed: 1", "seed: 2"), 12, "given twice"),
    ("negative-seed", synthesis("seed: -1"), 11, "at least 0"),
    ("fractional-iterations", synthesis("max_iters: 2.5"), 11, "whole number"),
    ("zero-timeout", synthesis("timeout: 0"), 11, "must be positive"),
    ("samples-unknown-set", synthesis("samples: init 100, foo 20"), 11, "`foo` is not a declared set"),
    ("samples-zero", synthesis("samples: 0"), 11, "positive whole number"),
    ("candidate-uses-input", edit("x0' = -x0", "x0' = -x0 + u",
                                  edit("state x0, x1", "state x0, x1\ninput u",
                                       synthesis("candidate: u^2"))), 12, "`u` is an input"),
    ("controller-without-input", synthesis("controller: linear(2)"), 11,
     "declares no `input`"),
    ("odd-lyapunov-tanh", edit("prove from init: always not unsafe", "prove from init: stable",
                               synthesis("certificate: tanh(8)")), 11, "V an odd function"),
    ("odd-lyapunov-sigmoid", edit("prove from init: always not unsafe", "prove stable",
                                  synthesis("certificate: sigmoid(5)")), 11, "odd function"),
    ("odd-lyapunov-tanh-cube", edit("prove from init: always not unsafe",
                                    "prove from init: stable",
                                    synthesis("certificate: tanh(4), cube(3)")), 11,
     "odd function"),
    ("relu-flow-barrier", synthesis("certificate: relu(8), square(4)"), 11, "`relu` has a kink"),
    ("relu-flow-lyapunov", edit("prove from init: always not unsafe", "prove stable",
                                synthesis("certificate: softplus(4), relu(8), square(4)")), 11,
     "use `softplus`"),
]

@pytest.mark.parametrize("layers, prove", [
    ("tanh(8)", "prove from init: always not unsafe"),  # a barrier has biases
    ("tanh(8), square(8)", "prove from init: stable"),
    ("sigmoid(5), tanh(5)", "prove stable"),  # sigmoid(0) = 1/2 is passed on as a bias
    ("poly3(6)", "prove stable"),
])
def test_layers_that_can_give_a_positive_v_are_accepted(layers, prove):
    text = edit("prove from init: always not unsafe", prove, synthesis(f"certificate: {layers}"))
    result = check_text(text, "spec.fsl")
    assert result.ok, result.render()


LOCATION = re.compile(r"^spec\.fsl:(\d+):(\d+): (error|warning): ", re.M)


@pytest.mark.parametrize("text, line, fragment",
                         [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_malformed_spec_gives_labelled_error(text, line, fragment):
    result = check_text(text, "spec.fsl")
    assert not result.ok and result.spec is None
    matching = [d for d in result.errors if fragment in d.message]
    assert matching, f"no error containing {fragment!r}; got:\n{result.render()}"
    assert matching[0].span is not None and matching[0].span.line == line, result.render()


@pytest.mark.parametrize("text", [case[1] for case in CASES], ids=[case[0] for case in CASES])
def test_every_finding_renders_with_location_and_caret(text):
    result = check_text(text, "spec.fsl")
    rendered = result.render()
    headers = LOCATION.findall(rendered)
    assert len(headers) == len(result.diagnostics)
    for diagnostic in result.diagnostics:
        block = diagnostic.render(result.source).splitlines()
        if result.source.line_text(diagnostic.span.line).strip():
            assert set(block[2].strip()) == {"^"}, rendered


def test_table_is_large_and_ids_unique():
    assert len(CASES) >= 40
    assert len({case[0] for case in CASES}) == len(CASES)


def test_all_findings_are_collected_not_only_the_first():
    text = edit("x0' = -x0", "x0' = -y", edit("x1' = -x1", "x1' = -sinh(x1)",
                                              synthesis("certficate: square(5)")))
    messages = [d.message for d in check_text(text).errors]
    assert any("undeclared name `y`" in m for m in messages)
    assert any("unknown function `sinh`" in m for m in messages)
    assert any("unknown synthesis key" in m for m in messages)


def test_unsupported_property_names_every_supported_form():
    text = edit("always not unsafe", "always eventually unsafe")
    [error] = check_text(text).errors
    notes = " ".join(error.notes)
    for form in ("`stable`", "`from I: stable`", "`from I: always not U`",
                 "`from I: stable and always not U`", "`from I: not U until G`",
                 "`from I: not U until always F`", "`from I: not U until (G and always F)`",
                 "`from I: eventually G`"):
        assert form in notes


@pytest.mark.parametrize("text, fragment", [
    ("const k = 2\n" + BASE, "constant `k` is declared but it is never used"),
    (BASE + "set spare = ball([0, 0], 1)\n", "set `spare` is declared but the property never uses it"),
    (edit("x0' = -x0", "x0' = -x0", edit("state x0, x1", "state x0, x1\ninput u")),
     "input `u` does not appear in the dynamics"),
    (synthesis("certificate2: square(3)"), "`certificate2` is ignored"),
    (edit("x0' = -x0", "x0' = -x0 + u + 1", edit("state x0, x1", "state x0, x1\ninput u",
                                                 edit("prove from init: always not unsafe",
                                                      "prove stable"))),
     "not an equilibrium of the open loop"),
])
def test_warnings_do_not_block_the_spec(text, fragment):
    result = check_text(text)
    assert result.ok, result.render()
    assert any(fragment in w.message for w in result.warnings), result.render()


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"], ids=["lf", "crlf", "cr"])
def test_positions_agree_for_every_line_ending(newline):
    text = newline.join(["state x0", "dynamics continuous {", "  x0' = -y", "}",
                         "domain ball([0], 1)", "prove stable", ""])
    [error] = check_text(text, "spec.fsl").errors
    assert (error.span.line, error.span.column) == (3, 10)
    assert check_text(text, "spec.fsl").render().splitlines()[1] == "    x0' = -y"


def test_byte_order_mark_is_ignored():
    text = "\ufeffstate x0\ndynamics continuous { x0' = -x0 }\ndomain ball([0], 1)\nprove stable\n"
    assert check_text(text).ok
