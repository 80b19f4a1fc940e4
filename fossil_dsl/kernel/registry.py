"""Which rule judges a claim, and what its obligations give once proved: the registry
of rules (one per property form and time domain, in rules.py and step_rules.py), their
variants (another sound rule for the same property, tried where the main one fails) and
strengthenings (further obligations for a stronger guarantee)."""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Callable

from fossil_dsl.ir import expr as E
from fossil_dsl.ir.spec import CheckedSpec, TimeDomain
from fossil_dsl.kernel.obligations import Claim, Facts, NoRule, Obligation, common


RULES: dict[tuple[str, TimeDomain], Callable[[Facts], None]] = {}
# What the rule's obligations prove, in words: a text, or a function of "discrete".
GUARANTEES: dict[tuple[str, TimeDomain], str | Callable[[bool], str]] = {}


@dataclass(frozen=True)
class Strengthening:
    """Further obligations that, proved on top of a rule's, give a stronger guarantee
    (e.g. safety without "while they remain in D"). Not proving them never costs the
    verdict, only the stronger words."""

    name: str
    add: Callable[[Facts], bool | None]  # False: does not apply to this claim
    guarantee: str | Callable[[bool], str]


STRENGTHENINGS: dict[tuple[str, TimeDomain], list[Strengthening]] = {}


def strengthening(form: str, *times: TimeDomain, name: str,
                  guarantee: str | Callable[[bool], str]):
    def register(function):
        for time in times:
            STRENGTHENINGS.setdefault((form, time), []).append(
                Strengthening(name, function, guarantee))
        return function
    return register


@dataclass(frozen=True)
class Variant:
    """Another sound rule for the same property (docs/certificates.md gives its
    argument), tried where the main rule's obligations are not all proved. Its own
    strengthenings replace the main rule's."""

    name: str
    add: Callable[[Facts], None]
    guarantee: str | Callable[[bool], str]
    strengthenings: tuple[Strengthening, ...] = ()


VARIANTS: dict[tuple[str, TimeDomain], list[Variant]] = {}


def variant_rule(form: str, *times: TimeDomain, name: str,
                 guarantee: str | Callable[[bool], str], strengthenings=()):
    def register(function):
        for time in times:
            VARIANTS.setdefault((form, time), []).append(
                Variant(name, function, guarantee, tuple(strengthenings)))
        return function
    return register


def rule_variants(spec: CheckedSpec) -> list[str | None]:
    """The rules the kernel may judge a claim of this spec by: the main one (None) first."""
    return [None] + [v.name for v in VARIANTS.get((spec.property.form, spec.time), [])]


def _variant(spec: CheckedSpec, name: str | None) -> Variant | None:
    if name is None:
        return None
    for option in VARIANTS.get((spec.property.form, spec.time), []):
        if option.name == name:
            return option
    raise NoRule(f"no rule {name!r} for {spec.property.form} in {spec.time.value} time")


def rule(form: str, *times: TimeDomain, guarantee: str | Callable[[bool], str]):
    """Register a rule, and the guarantee that its obligations, once proved, give."""
    def register(function):
        for time in times or (TimeDomain.CONTINUOUS,):
            RULES[(form, time)] = function
            GUARANTEES[(form, time)] = guarantee
        return function
    return register


def guarantee_text(spec: CheckedSpec, ball_radius: Fraction, controlled: bool,
                   strengthened: Strengthening | None = None,
                   variant: Variant | None = None) -> str:
    """What a certified claim guarantees, in words: the rule's guarantee (or a proved
    strengthening's), weakened where a ball round the origin was left out, and said of
    the closed loop where there is a controller."""
    key = (spec.property.form, spec.time)
    if key not in GUARANTEES:
        raise NoRule(f"no sound rule for {key[0]} in {key[1].value} time")
    text = strengthened.guarantee if strengthened is not None else \
        variant.guarantee if variant is not None else GUARANTEES[key]
    text = text if isinstance(text, str) else text(spec.time is TimeDomain.DISCRETE)
    if ball_radius > 0:
        r = E.Num(ball_radius)
        text = (f"ε-stability for ε = {r}: the conditions that exclude the origin were "
                f"proved outside the ball |x| <= {r} only, so trajectories reach, and stay "
                "in, the smallest sublevel set of V that contains that ball, rather than "
                f"converging to the origin itself. Apart from that ball: {text}")
    return text + (" (for the closed loop with the controller shown)" if controlled else "")


def derive(claim: Claim, strengthened: str | None = None,
           variant: str | None = None) -> list[Obligation]:
    """The complete list of obligations for the claim's property by the main rule or the
    named variant (with those of the named strengthening); NoRule if none is sound."""
    obligations = derive_facts(claim, variant)[0]
    for option, extra, _ in derive_strengthenings(claim, variant):
        if option.name == strengthened:
            obligations += extra
    return obligations


def derive_facts(claim: Claim, variant: str | None = None) -> tuple[list[Obligation], str]:
    """The obligations of the main rule (or the named variant), and the guarantee they
    give once proved."""
    facts = Facts(claim)
    key = (claim.spec.property.form, claim.spec.time)
    if key not in RULES:
        raise NoRule(f"no sound rule for {key[0]} in {key[1].value} time")
    chosen = _variant(claim.spec, variant)
    common(facts)
    (RULES[key] if chosen is None else chosen.add)(facts)
    excluded = facts.ball_left_out and not facts.ball_covered
    guarantee = guarantee_text(claim.spec, claim.ball_radius if excluded else 0,
                               bool(claim.controller), variant=chosen)
    return _unique(facts.obligations), guarantee


def derive_strengthenings(claim: Claim, variant: str | None = None
                          ) -> list[tuple[Strengthening, list[Obligation], str]]:
    """For each strengthening of the claim's rule (or variant), strongest first: its
    further obligations and the guarantee the rule's and these give together."""
    found = []
    chosen = _variant(claim.spec, variant)
    options = STRENGTHENINGS.get((claim.spec.property.form, claim.spec.time), []) \
        if chosen is None else chosen.strengthenings
    for option in options:
        facts = Facts(claim)
        if option.add(facts) is False:
            continue
        guarantee = guarantee_text(claim.spec, claim.ball_radius if facts.ball_left_out
                                   else 0, bool(claim.controller), option)
        found.append((option, _unique(facts.obligations), guarantee))
    return found


def _unique(obligations: list[Obligation]) -> list[Obligation]:
    found: dict[str, Obligation] = {}
    for obligation in obligations:
        found.setdefault(obligation.name, obligation)
    return list(found.values())


