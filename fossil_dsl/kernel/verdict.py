"""The verdict: CERTIFIED exactly when every obligation of the claim is proved.

`judge` is the only place a certified Verdict is made: the constructor refuses
`certified=True` without this module's seal, so nothing the learner, the loop or a
heuristic does can produce one.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

from fossil_dsl.kernel import rules, step_rules  # noqa: F401  (registers the rules)
from fossil_dsl.kernel.obligations import (Claim, NoRule, Obligation, derive, derive_facts,
                                           derive_strengthenings)
from fossil_dsl.kernel.prove import Outcome, Proof, discharge

_SEAL = object()
OBLIGATION_TIMEOUT = 60.0  # seconds per obligation; running out is "not proved"
STRENGTHENING_TIMEOUT = 20.0  # per further obligation of an optional strengthening


@dataclass(frozen=True)
class Verdict:
    certified: bool
    reason: str
    proofs: tuple[Proof, ...] = ()
    seconds: float = 0.0
    guarantee: str = "nothing is proved"  # in words, from the rule; only when certified
    strengthened: str | None = None  # the strengthening whose obligations were proved too
    _seal: object = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        if self.certified and self._seal is not _SEAL:
            raise PermissionError("only the kernel's judge() makes a certified verdict")

    @property
    def failed(self) -> tuple[Proof, ...]:
        return tuple(p for p in self.proofs if not p.proved)


def not_certified(reason: str) -> Verdict:
    return Verdict(False, reason)


def list_obligations(claim: Claim, strengthened: str | None = None) -> list[Obligation]:
    """Every obligation of the claim, with the named strengthening's (raises NoRule where
    the kernel has no rule)."""
    return derive(claim, strengthened)


def judge(claim: Claim, timeout: float = OBLIGATION_TIMEOUT,
          delta: float | None = None, pieces=None) -> Verdict:
    """Prove every obligation; stop at the first that is not proved. `pieces` checks
    the pieces of split interval queries in parallel (their cover is checked here)."""
    started = time.monotonic()
    try:
        found, guarantee = derive_facts(claim)
    except NoRule as exc:
        return not_certified(f"the kernel cannot judge this claim: {exc}")
    proofs, proved = _prove_all(found, claim, timeout, delta, pieces)
    if not proved:
        return Verdict(False, _failure_text(proofs[-1]), tuple(proofs),
                       time.monotonic() - started)
    strengthened = None
    for option, extra, stronger in derive_strengthenings(claim):
        more, proved = _prove_all(extra, claim, min(timeout, STRENGTHENING_TIMEOUT), delta,
                                  pieces)
        if proved:
            proofs += more
            guarantee, strengthened = stronger, option.name
            break
    return Verdict(True, f"all {len(proofs)} obligations proved", tuple(proofs),
                   time.monotonic() - started, guarantee, strengthened, _SEAL)


def _prove_all(obligations: list[Obligation], claim: Claim, timeout: float,
               delta: float | None, pieces=None) -> tuple[list[Proof], bool]:
    """The proofs up to the first obligation not proved, and whether all were proved.
    The procedure that proved a condition in the run goes first (only the order)."""
    proofs = []
    for obligation in obligations:
        first = claim.procedures.get(obligation.name.removeprefix("condition:"),
                                     obligation.first)
        proofs.append(discharge(obligation, claim.spec.states, timeout, delta, first,
                                claim.refutations.get(obligation.name), pieces))
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
