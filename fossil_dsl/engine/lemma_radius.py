"""The radius of the ball round the origin that the engine leaves out of a found
function's conditions, chosen so that the kernel's Taylor lemma (kernel/local.py) can
cover it: a choice, not a proof (the lemma's obligations still decide)."""
from __future__ import annotations

import itertools
import math
from dataclasses import replace
from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir.enclosure import enclose
from fossil_dsl.ir.sets import Ball, Box
from fossil_dsl.kernel.obligations import BALL_ROOM, Claim, Facts
from fossil_dsl.kernel.rules import no_ball_left_out


def lemma_radius(claim: Claim, halvings: int = 4, doublings: int = 3) -> Fraction | None:
    """The largest of 2^doublings r, ..., 2r, r, r/2, ..., r/2^halvings (r: the claim's
    excluded ball; above r only where D is a box or ball that holds BALL_ROOM times the
    ball, and V stays below half of each level on it) at which the Taylor lemma's own
    choices of μ and M pass for V and its change, so that its obligations can cover the
    ball; None if at none. A choice for the engine, not a proof: the lemma's obligations
    still decide. A larger ball leaves less to the verifier, whose boxes near the origin
    must shrink with |x|."""
    room = _room(claim.spec.domain)
    larger = [claim.ball_radius * 2 ** k for k in range(doublings, 0, -1)
              if BALL_ROOM * claim.ball_radius * 2 ** k <= room
              and _well_below_levels(claim, claim.ball_radius * 2 ** k)]
    for radius in larger + [claim.ball_radius / 2 ** k for k in range(halvings + 1)]:
        if radius > 0 and no_ball_left_out(Facts(replace(claim, ball_radius=radius))):
            return radius
    return None


def _well_below_levels(claim: Claim, radius: Fraction) -> bool:
    """V below half of each level at the ball's 2n points on the axes and the 2^n on the
    diagonals (the rules need the excluded ball inside Ω)."""
    V = claim.functions.get("V")
    if not claim.levels or V is None:
        return True
    n, states = len(claim.spec.states), claim.spec.states
    points = [tuple(sign * radius if i == k else 0 for i in range(n))
              for k in range(n) for sign in (1, -1)]
    if n <= 8:
        points += [tuple(radius * s / _isqrt_up(n) for s in signs)
                   for signs in itertools.product((1, -1), repeat=n)]
    highest = max(enclose(traversal.substitute(V, {s: E.Num(v) for s, v in zip(states, p)}))[1]
                  for p in points)
    return highest < min(claim.levels.values()) / 2


def _isqrt_up(n: int) -> Fraction:
    """A rational at least sqrt(n): the diagonal points stay in the ball."""
    return Fraction(math.isqrt(n * 10 ** 6) + 1, 1000)


def _room(domain) -> Fraction:
    """The largest R with the ball |x| <= R in D, where D is a closed box round the origin
    or a closed ball centred at it (else 0: nothing is assumed)."""
    if isinstance(domain, Ball) and not domain.is_open and isinstance(domain.radius, E.Num) \
            and all(isinstance(c, E.Num) and c.value == 0 for c in domain.centre):
        return domain.radius.value
    if not isinstance(domain, Box) or domain.is_open or \
            not all(isinstance(end, E.Num) for end in (*domain.lower, *domain.upper)):
        return Fraction(0)
    return min(min(-low.value, high.value) for low, high in zip(domain.lower, domain.upper))
