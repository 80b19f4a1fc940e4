"""The loss: for each condition, how far its samples are from meeting its claim where
its guard holds, and whether they meet it."""
from __future__ import annotations

import functools

import torch

from fossil_dsl.engine.evaluate import evaluate, holds
from fossil_dsl.ir import logic as L
from fossil_dsl.plan.certificates.base import Condition

GUARD_BAND = 0.1  # a guard such as B(x) = 0 is learned on a band this wide (relative)


def placeholders(condition: Condition) -> frozenset[str]:
    return frozenset(n for n in L.free_vars(condition.claim) | L.free_vars(condition.guard)
                     if n.startswith("$"))


def violation_of(claim: L.Formula, env) -> torch.Tensor:
    """How far the claim is from holding (positive: violated). A comparison's is the
    difference of its sides; a conjunction's the largest of its parts', a disjunction's
    the smallest, a negation's the opposite (a claim such as f(x) ∈ S, with S a box
    or a difference of sets, is learned like any other)."""
    if isinstance(claim, L.Compare):
        difference = evaluate(claim.left, env) - evaluate(claim.right, env)
        return difference if claim.relation in ("<", "<=") else -difference
    if isinstance(claim, L.Not):
        return -violation_of(claim.arg, env)
    if isinstance(claim, (L.And, L.Or)):
        parts = [torch.as_tensor(violation_of(a, env), dtype=torch.float64)
                 for a in claim.args]
        combine = torch.maximum if isinstance(claim, L.And) else torch.minimum
        return functools.reduce(combine, parts)
    raise TypeError(f"a claim cannot be the constant {claim}")


def guard_scale(env) -> float:
    """The size of the batch's placeholder values (the mean of each one's magnitude, the
    largest of them): a guard's band is relative to it."""
    return max((float(v.detach().abs().mean()) for k, v in env.items()
                if k.startswith("$") and isinstance(v, torch.Tensor) and v.dim() > 0),
               default=1.0)


def _detached(env) -> dict:
    return {k: v.detach() if isinstance(v, torch.Tensor) else v for k, v in env.items()}


class GuardMasks:
    """Where a guard holds on one batch, loosened by bands relative to the batch's values;
    each band's mask, and the scale, computed once (a training step asks for up to
    three per condition)."""

    def __init__(self, guard: L.Formula, env, batch: int):
        self.guard, self.env, self.batch = guard, env, batch
        self._scale, self._detached, self._masks = None, None, {}

    def __call__(self, band: float) -> torch.Tensor:
        if band not in self._masks:
            self._masks[band] = self._mask(band)
        return self._masks[band]

    def _mask(self, band: float) -> torch.Tensor:
        if self.guard == L.TRUE:
            return torch.ones(self.batch, dtype=torch.bool)
        if self._scale is None:
            self._scale, self._detached = guard_scale(self.env), _detached(self.env)
        return holds(self.guard, self._detached, self.batch, band * self._scale)

    def judged(self) -> torch.Tensor:
        """Where the condition is judged met or not: where the guard holds exactly, or,
        for a guard that holds exactly on no sample (a level set, B(x) = 0), on the band
        trained on."""
        mask = self(0.0)
        return mask if mask.any() else self(GUARD_BAND)


def guard_mask(guard: L.Formula, env, batch: int, band: float) -> torch.Tensor:
    return GuardMasks(guard, env, batch)(band)


class Shortfall:
    """How far each sample is from meeting a condition's claim with a margin (0: met);
    the claim's (and the guard's) violation evaluated once for every margin asked."""

    def __init__(self, condition: Condition, env):
        self.violation = violation_of(condition.claim, env)
        self.guard_violation = violation_of(condition.guard, env) \
            if condition.escapable_guard else None

    def __call__(self, margin) -> torch.Tensor:
        shortfall = torch.relu(self.violation + margin)
        if self.guard_violation is not None:
            escape = torch.relu(margin - self.guard_violation)
            shortfall = torch.minimum(shortfall, escape)
        return shortfall


def is_met(shortfall: torch.Tensor, guard: L.Formula, env) -> bool:
    """Whether the condition is met on the samples where its guard holds exactly (a
    guard that holds exactly on no sample is judged on the band trained on)."""
    return bool((shortfall[GuardMasks(guard, env, len(shortfall)).judged()] == 0).all())


def condition_loss(condition: Condition, points: torch.Tensor, env, margin: float):
    """The mean shortfall, with the plan's margin, where the guard holds (within a
    band), and whether the samples meet the condition: with half that margin where the
    guard holds, or, for an escapable guard, with the margin on the whole band."""
    if condition.scaled_margin:
        margin = margin * (points ** 2).sum(1).detach()
    masks = GuardMasks(condition.guard, env, len(points))
    mask = masks(GUARD_BAND)
    if not mask.any():
        return torch.zeros((), dtype=torch.float64), True
    shortfall_with = Shortfall(condition, env)
    shortfall = shortfall_with(margin)
    if condition.escapable_guard:  # a point may meet it by leaving the guard's band
        satisfied = bool((shortfall[mask] == 0).all())
    else:
        half = shortfall_with(margin / 2).detach()
        satisfied = bool((half[masks.judged()] == 0).all())
    return shortfall[mask].mean(), satisfied
