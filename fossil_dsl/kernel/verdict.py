"""The verdict: CERTIFIED exactly when every obligation of the claim is proved.

`judge` is the only place a certified Verdict is made: the constructor refuses
`certified=True` without this module's seal, so nothing the learner, the loop or a
heuristic does can produce one.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from fossil_dsl.kernel import inward_rules, rules, safety_rules, step_rules  # noqa: F401 (rules)
from fossil_dsl.kernel.obligations import Claim, NoRule, Obligation
from fossil_dsl.kernel.registry import (derive, derive_facts, derive_strengthenings,
                                        rule_variants)
from fossil_dsl.kernel.prove import Outcome, Proof, discharge

_SEAL = object()
OBLIGATION_TIMEOUT = 60.0  # seconds per obligation; running out is "not proved"
STRENGTHENING_TIMEOUT = 20.0  # per further obligation of an optional strengthening
LAST_SECONDS = 0.5  # for each obligation once a judge's deadline has passed


@dataclass(frozen=True)
class Verdict:
    certified: bool
    reason: str
    proofs: tuple[Proof, ...] = ()
    seconds: float = 0.0
    guarantee: str = "nothing is proved"  # in words, from the rule; only when certified
    strengthened: str | None = None  # the strengthening whose obligations were proved too
    _seal: object = field(default=None, repr=False, compare=False)
    variant: str | None = None  # the variant of the rule that was proved (None: the main)

    def __post_init__(self):
        if self.certified and self._seal is not _SEAL:
            raise PermissionError("only the kernel's judge() makes a certified verdict")

    @property
    def failed(self) -> tuple[Proof, ...]:
        return tuple(p for p in self.proofs if not p.proved)


def not_certified(reason: str) -> Verdict:
    return Verdict(False, reason)


def list_obligations(claim: Claim, strengthened: str | None = None,
                     variant: str | None = None) -> list[Obligation]:
    """Every obligation of the claim by the main rule or the named variant, with the
    named strengthening's (raises NoRule where the kernel has no rule)."""
    return derive(claim, strengthened, variant)


def judge(claim: Claim, timeout: float = OBLIGATION_TIMEOUT,
          delta: float | None = None, pieces=None, deadline: float | None = None) -> Verdict:
    """Prove every obligation of the main rule, stopping at the first that is not
    proved; where one is not, the same for each variant of the rule (an obligation they
    share is proved once). `pieces` checks the pieces of split interval queries in
    parallel (their cover is checked here). With a `deadline` (time.monotonic()), no
    obligation gets more than what is left of it (LAST_SECONDS once it has passed):
    one that needs more is not proved."""
    started = time.monotonic()
    try:
        derive_facts(claim)
    except NoRule as exc:
        return not_certified(f"the kernel cannot judge this claim: {exc}")
    proved, proofs, variant, guarantee = _first_rule_proved(
        claim, _Budget(timeout, deadline), delta, pieces)
    if not proved:
        return Verdict(False, _failure_text(proofs[-1]), tuple(proofs),
                       time.monotonic() - started)
    strengthened = None
    for option, extra, stronger in derive_strengthenings(claim, variant):
        budget = _Budget(min(timeout, STRENGTHENING_TIMEOUT), deadline)
        more, done = _prove_all(extra, claim, budget, delta, pieces)
        if done:
            proofs += more
            guarantee, strengthened = stronger, option.name
            break
    return Verdict(True, f"all {len(proofs)} obligations proved", tuple(proofs),
                   time.monotonic() - started, guarantee, strengthened, _SEAL, variant)


def _first_rule_proved(claim: Claim, budget: "_Budget", delta, pieces):
    """(proved, proofs, variant, guarantee) for the first of the main rule and its
    variants whose obligations are all proved; else (False, the main rule's proofs up
    to its first failure, None, "")."""
    known: dict[Obligation, Proof] = {}
    first_failure = None
    for variant in rule_variants(claim.spec):
        found, guarantee = derive_facts(claim, variant)
        proofs, proved = _prove_all(found, claim, budget, delta, pieces, known)
        if proved:
            return True, proofs, variant, guarantee
        first_failure = first_failure or proofs
    return False, first_failure, None, ""


class _Budget:
    """Seconds for the next obligation: the timeout, or what is left of the deadline."""

    def __init__(self, timeout: float, deadline: float | None):
        self.timeout, self.deadline = timeout, deadline

    def seconds(self) -> float:
        if self.deadline is None:
            return self.timeout
        return min(self.timeout, max(LAST_SECONDS, self.deadline - time.monotonic()))


def _prove_all(obligations: list[Obligation], claim: Claim, timeout: _Budget,
               delta: float | None, pieces=None,
               known: dict | None = None) -> tuple[list[Proof], bool]:
    """The proofs up to the first obligation not proved, and whether all were proved.
    The procedure that proved a condition in the run goes first (only the order);
    `known` holds the proofs of obligations decided before, and gains these."""
    proofs = []
    known = {} if known is None else known
    for obligation in obligations:
        if obligation not in known:
            first = claim.procedures.get(obligation.name.removeprefix("condition:"),
                                         obligation.first)
            known[obligation] = discharge(obligation, claim.spec.states, timeout.seconds(),
                                          delta, first,
                                          claim.refutations.get(obligation.name), pieces)
        proofs.append(known[obligation])
        if not proofs[-1].proved:
            return proofs, False
    return proofs, True


def _failure_text(proof: Proof) -> str:
    obligation = proof.obligation
    where = ""
    if proof.witness is not None:
        where = " at (" + ", ".join(format(float(v), ".6g") for v in proof.witness) + ")"
    word = "fails" if proof.outcome is Outcome.FAILS else "is not proved"
    detail = f" ({proof.procedure}: {proof.detail})" if proof.detail else \
        f" ({proof.procedure})"
    return f"{obligation.name} ({obligation.text}) {word}{where}{detail}"
