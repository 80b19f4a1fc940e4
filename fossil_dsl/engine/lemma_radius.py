"""The radius of the ball round the origin that the engine leaves out of a found
function's conditions, chosen so that the kernel's Taylor lemma (kernel/local.py) can
cover it: a choice, not a proof (the lemma's obligations still decide)."""
from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

from fossil_dsl.kernel.obligations import Claim, Facts
from fossil_dsl.kernel.rules import no_ball_left_out


def lemma_radius(claim: Claim, halvings: int = 4) -> Fraction | None:
    """The largest of r, r/2, ..., r/2^halvings (r: the claim's excluded ball) at which
    the Taylor lemma's own choices of μ and M pass for V and its change, so that its
    obligations can cover the ball; None if at none. Not above r: a ball 8 times larger
    (where D holds ten times it) cost probe58/ab01's kernel 12.1 s instead of 5.8 s (the
    third derivatives bounded on the larger ball), and its decrease, refuted by a program,
    gained nothing."""
    radius = claim.ball_radius
    for _ in range(halvings + 1):
        if radius > 0 and no_ball_left_out(Facts(replace(claim, ball_radius=radius))):
            return radius
        radius /= 2
    return None
