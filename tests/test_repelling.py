"""A barrier round a repelling equilibrium in U (engine/repelling.py): B = d - x^T P x
with P from the time-reversed linearisation, proved like any candidate."""
from pathlib import Path

import fossil_dsl
from fossil_dsl.engine import repelling
from fossil_dsl.plan.compile import compile_spec

ROOT = Path(__file__).resolve().parent.parent
HOPF = ROOT / "specs" / "probe52" / "m03_hopf_annulus_safety.fsl"


def test_an_annulus_round_an_unstable_focus_is_kept_off_it():
    """probe52/m03: the Hopf normal form, I the annulus 0.6 <= r <= 1.5, U the disc
    r <= 0.3 round the unstable origin. Learning timed out (120 s); B = d - |x|^2
    grows towards the origin and is proved at once."""
    result = fossil_dsl.synthesise(fossil_dsl.load(HOPF), seed=0, timeout=60)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("a barrier round the repelling equilibrium")
    B = result.sympy["B"]
    x, y = sorted(B.free_symbols, key=str)
    assert float(B.subs({x: 0, y: 0})) > 0 > float(B.subs({x: 0.6, y: 0}))


def test_a_stable_equilibrium_in_u_gives_no_candidate():
    """The same sets with the flow reversed: the origin attracts, orbits from I reach U
    (the property is false), and the origin's linearisation has no eigenvalue to the
    right: nothing is proposed."""
    text = HOPF.read_text().replace("x' = x - y - x*(x^2 + y^2)", "x' = -x + y + x*(x^2 + y^2)") \
        .replace("y' = x + y - y*(x^2 + y^2)", "y' = -x - y + y*(x^2 + y^2)")
    plan = compile_spec(fossil_dsl.loads(text, "reversed.fsl"))
    assert repelling.applies(plan)
    assert list(repelling.candidates(plan)) == []
    assert not fossil_dsl.synthesise(fossil_dsl.loads(text, "reversed.fsl"), seed=0,
                                     timeout=10, max_iters=2).certified


def test_orbits_that_leave_an_unstable_focus_for_an_outer_unsafe_set_are_not_certified():
    """specs/false/f35: I close round the unstable origin, U outside r = 0.98; orbits
    tend to the cycle r = 1. No ellipsoid round the origin holds U and misses I."""
    spec = fossil_dsl.load(ROOT / "specs" / "false" / "f35_hopf_reaches_outer_shell.fsl")
    assert list(repelling.candidates(compile_spec(spec))) == []
    assert not fossil_dsl.synthesise(spec, seed=0, timeout=10, max_iters=2).certified
