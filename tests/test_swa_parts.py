"""Stable while avoid from its parts found apart (engine/swa_parts.py): V and β of I's
region of attraction and the barrier program's B, where B = V - β fails because Ω
meets U."""
from __future__ import annotations

from pathlib import Path

import fossil_dsl
from fossil_dsl.engine import swa_parts
from fossil_dsl.plan.compile import compile_spec

SPECS = Path(__file__).resolve().parent.parent / "specs"


def test_the_pharmacokinetic_model_is_certified_from_its_parts():
    """probe69/as16: five compartments after an oral dose; any ellipsoid round the
    origin that holds the dose meets the toxic half-space e >= 0.5."""
    spec = fossil_dsl.load(SPECS / "probe69/as16_pharmacokinetics_michaelis_menten_swa_5d.fsl")
    result = fossil_dsl.synthesise(spec, seed=0, timeout=120)
    assert result.certified and result.kernel.certified, result.summary()
    assert result.strategy.startswith("V: ") and "; B: sum-of-squares" in result.strategy
    assert "never enter U" in result.kernel.guarantee


def test_the_attempt_is_for_autonomous_continuous_stable_while_avoid():
    names = ("probe69/as05_griffith_gene_feedback_swa.fsl", "swa_discrete.fsl",
             "swa_controlled.fsl", "roa_continuous.fsl", "swa_continuous.fsl")
    applies = [swa_parts.applies(compile_spec(fossil_dsl.load(SPECS / name)))
               for name in names]
    # (swa_continuous.fsl chooses its template: the engine's attempts are left out)
    assert applies == [True, False, False, False, False]
