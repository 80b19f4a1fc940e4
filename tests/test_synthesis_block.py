"""Synthesis options one per line, or several on a line separated by commas."""
from __future__ import annotations

from fractions import Fraction

import pytest

from fossil_dsl import check_text

SPEC = """\
state x, y
dynamics continuous {
    x' = -x + y
    y' = -y
}
domain box([-1, -1], [1, 1])
prove stable
"""

ONE_PER_LINE = """synthesis {
    verifier: interval
    delta: 0.001
    certificate: tanh(4), square(3)
    samples: domain 300
    max_iters: 7
}
"""

SHARED_LINES = """synthesis { verifier: interval, delta: 0.001, certificate: tanh(4), square(3), \\
              samples: domain 300, max_iters: 7 }
"""


def synthesis_of(block: str):
    result = check_text(SPEC + block)
    assert result.ok, result.render()
    return result.spec.synthesis


def test_options_sharing_a_line_mean_what_they_mean_one_per_line():
    shared, alone = synthesis_of(SHARED_LINES), synthesis_of(ONE_PER_LINE)
    assert shared == alone
    assert shared.verifier == "interval" and shared.max_iters == 7
    assert Fraction(shared.delta) == Fraction(1, 1000)
    assert [(layer.activation, layer.width) for layer in shared.certificate] == \
        [("tanh", 4), ("square", 3)]


@pytest.mark.parametrize("block, column", [
    ("synthesis { seed: 1, max_iter: 3 }\n", 22),
    ("synthesis { seed: 1, seed: 2 }\n", 22),
])
def test_an_option_on_a_shared_line_is_reported_at_its_own_position(block, column):
    result = check_text(SPEC + block)
    assert not result.ok
    assert [(d.span.line, d.span.column) for d in result.errors] == [(8, column)], \
        result.render()


def test_a_trailing_comma_is_a_syntax_error_at_the_brace():
    result = check_text(SPEC + "synthesis { seed: 1, }\n")
    assert not result.ok
    assert result.errors[0].span.line == 8 and "}" in result.errors[0].message


def test_a_line_ending_in_a_comma_goes_on():
    block = ("synthesis { verifier: interval, delta: 0.001,\n"
             "            certificate: tanh(4),\n                         square(3),\n"
             "            samples: domain 300, max_iters: 7 }\n")
    assert synthesis_of(block) == synthesis_of(ONE_PER_LINE)
