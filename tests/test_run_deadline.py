"""The language's `timeout` is for the whole run: the kernel's judgement of the final
candidate gets what is left of it, not a fresh bound per obligation."""
import time

import fossil_dsl
from fossil_dsl.frontends import api
from fossil_dsl.kernel import not_certified

STABLE = """\
state x
dynamics continuous { x' = -x - x^3 }
domain box([-1], [1])
prove stable
synthesis { candidate: x^2 }
"""


def test_the_kernel_is_given_the_runs_deadline(monkeypatch):
    given = {}
    real = api.judge

    def spy(claim, **options):
        given.update(options)
        return real(claim, **options)

    monkeypatch.setattr(api, "judge", spy)
    before = time.monotonic()
    result = fossil_dsl.synthesise(fossil_dsl.loads(STABLE, "t.fsl"), timeout=20)
    assert result.certified
    assert before < given["deadline"] <= time.monotonic() + 20


def test_a_judgement_that_outlasts_the_timeout_says_so(monkeypatch):
    def slow(claim, **options):
        time.sleep(max(0.0, options["deadline"] - time.monotonic()) + 0.05)
        return not_certified("condition:decrease not proved: interval: timeout")

    monkeypatch.setattr(api, "judge", slow)
    result = fossil_dsl.synthesise(fossil_dsl.loads(STABLE, "t.fsl"), timeout=2)
    assert not result.certified
    assert "the run's timeout (2 s) passed while the kernel judged" in result.reason
    assert "condition:decrease not proved" in result.reason
