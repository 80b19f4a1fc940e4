"""Region of attraction: I lies in the origin's basin, shown by a sublevel set of V."""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.plan.certificates.base import (Certificate, Condition, Level, change_of, level_of,
                                               register, value_of, velocity_of)
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.sets import Ball, Boundary, Box, SetExpr
from fossil_dsl.ir.spec import Layer, TimeDomain

DEFAULT_LAYERS = (Layer("square", 8),)
# the forms whose certificate is a V with a sublevel set Ω in the region of attraction
ROA_FORMS = ("region of attraction", "largest region of attraction")
FACE_PREFIX = "inward:"  # the names of the variant's conditions on D's faces


def roa_conditions(certificate: Certificate, name: str = "V", level: str = "beta",
                   prefix: str = "", initial: SetExpr | None = None,
                   initial_words: str = "I") -> tuple[Condition, ...]:
    """With Ω = {x in D : V(x) <= β}: V > β on ∂D (in discrete time: f(x) ∈ D for x in
    Ω, since a step can jump over ∂D), V <= β on I (or `initial`), and V > 0, dV < 0 on
    Ω minus the origin."""
    V, dV, beta = value_of(name), change_of(name), level_of(level)
    domain = certificate.spec.domain
    inside_level = L.Compare("<=", V, beta)
    change = certificate.change_word(name)
    if certificate.discrete:
        kept = certificate.lands_in(f"{prefix}image", "f(x) ∈ D for every x in Ω", domain,
                                    domain, inside_level)
    else:
        kept = Condition(f"{prefix}boundary", f"{name}(x) > β for every x on the boundary "
                         "of D", Boundary(domain), L.Compare(">", V, beta))
    return (
        kept,
        Condition(f"{prefix}initial", f"{name}(x) <= β for every x in {initial_words}",
                  initial or certificate.role("initial"), inside_level),
        Condition(f"{prefix}positive", f"{name}(x) > 0 for every x ≠ 0 in Ω",
                  domain, L.Compare(">", V, E.ZERO), guard=inside_level,
                  exclude_origin=True, scaled_margin=True),
        Condition(f"{prefix}decrease", f"{change} < 0 for every x ≠ 0 in Ω", domain,
                  L.Compare("<", dV, E.ZERO), guard=inside_level, exclude_origin=True,
                  scaled_margin=True),
    )


def inward_conditions(certificate: Certificate, name: str = "V",
                      level: str = "beta") -> tuple[Condition, ...] | None:
    """For Ω reaching ∂D (continuous time, D a box; kernel/inward_rules.py): on each face
    of D, where V <= β, the field points into D. None where the variant does not apply."""
    domain = certificate.spec.domain
    if certificate.discrete or not isinstance(domain, Box):
        return None
    inside_level = L.Compare("<=", value_of(name), level_of(level))
    found = []
    for i, state in enumerate(certificate.spec.states):
        for end, relation, side in ((domain.lower[i], ">", "lower"),
                                    (domain.upper[i], "<", "upper")):
            lower, upper = list(domain.lower), list(domain.upper)
            lower[i] = upper[i] = end
            found.append(Condition(
                f"{FACE_PREFIX}{state}:{side}", f"the field points into D on its face {state} = "
                f"{E.to_text(end)} where {name}(x) <= β", Box(tuple(lower), tuple(upper)),
                L.Compare(relation, velocity_of(state), E.ZERO), guard=inside_level))
    return tuple(found)


def initial_reaches_boundary(spec) -> bool:
    """I's bounding box meets a face of D's (where no sublevel set holding I fits inside
    D: the variant's conditions are the ones to learn)."""
    initial, domain = spec.property.role("initial"), spec.domain.bounding_box()
    inner = initial.bounding_box() if initial is not None else None
    if spec.time is not TimeDomain.CONTINUOUS or inner is None or domain is None:
        return False
    return any(a <= low or b >= high for a, b, low, high in zip(*inner, *domain))


class ReachingBoundary:
    """The kernel's variant for an Ω that reaches ∂D (kernel/inward_rules.py): β just
    over V on I, and the variant's conditions learned where I touches ∂D."""

    def variant_levels(self):
        return (Level("beta", "V", above=None, below="initial",
                      text="β: just over the largest V on I"),)

    def chosen_conditions(self):
        variant = self.variant_conditions()
        if variant is not None and initial_reaches_boundary(self.spec):
            return variant, self.variant_levels()
        return self.conditions(), self.levels()


def roa_level(certificate: Certificate, name: str = "V", level: str = "beta",
              prefix: str = "") -> Level:
    # the smallest Ω that holds I: in discrete time the least to map into D; with
    # `region: largest` the least to prove first, before the kernel enlarges β
    if certificate.discrete or certificate.spec.synthesis.region == "largest":
        return Level(level, name, above=None, below=f"{prefix}initial",
                     text=f"β: just over the largest {name} on I")
    return Level(level, name, above=f"{prefix}boundary", below=f"{prefix}initial",
                 text=f"β: between the largest {name} on I and the smallest on ∂D")


@register
class RegionOfAttraction(ReachingBoundary, Certificate):
    form = "region of attraction"
    title = "region-of-attraction certificate (Lyapunov function and sublevel set)"
    discrete_time = True

    def functions(self):
        return (self.first_function("V", DEFAULT_LAYERS, zero_at_origin=True),)

    def conditions(self):
        return roa_conditions(self)

    def levels(self):
        return (roa_level(self),)

    def variant_conditions(self):
        inward = inward_conditions(self)
        return None if inward is None else inward + roa_conditions(self)[1:]


# the ball round the origin whose V the first β must cover, as a share of the distance
# from the origin to the edge of D's bounding box (the kernel raises β from there)
STARTING_BALL_SHARE = 0.05


@register
class LargestRegion(RegionOfAttraction):
    """`prove stable` with `region: largest`: no initial set, so the search starts from
    a small ball round the origin (a starting point, not an obligation: the kernel's
    rule has no I) and the kernel raises β."""

    form = "largest region of attraction"
    title = "region-of-attraction certificate (Lyapunov function and its largest sublevel set)"

    def conditions(self):
        ball = self.starting_ball()
        return roa_conditions(self, initial=ball,
                              initial_words=f"{ball} (where the search starts)")

    def levels(self):
        return (Level("beta", "V", above=None, below="initial",
                      text="β: just over the largest V on a small ball round the origin"),)

    def variant_conditions(self):
        return None  # the kernel's variant is for a region of attraction of a given I

    def starting_ball(self) -> Ball:
        low, high = self.spec.domain.bounding_box() or ((-1.0,) * len(self.spec.states),
                                                         (1.0,) * len(self.spec.states))
        room = min(min(-a, b) for a, b in zip(low, high))
        radius = float(f"{STARTING_BALL_SHARE * room:.2g}") if 0 < room < float("inf") else 0.05
        return Ball((E.ZERO,) * len(self.spec.states), E.Num(Fraction(str(radius))))
