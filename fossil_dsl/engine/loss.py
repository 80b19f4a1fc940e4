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


def guard_mask(guard: L.Formula, env, batch: int, band: float) -> torch.Tensor:
    if guard == L.TRUE:
        return torch.ones(batch, dtype=torch.bool)
    scale = max((float(v.detach().abs().mean()) for k, v in env.items()
                 if k.startswith("$") and isinstance(v, torch.Tensor) and v.dim() > 0),
                default=1.0)
    detached = {k: v.detach() if isinstance(v, torch.Tensor) else v for k, v in env.items()}
    return holds(guard, detached, batch, band * scale)


def shortfall_of(condition: Condition, env, margin) -> torch.Tensor:
    """How far each sample is from meeting the claim with the margin (0: met)."""
    shortfall = torch.relu(violation_of(condition.claim, env) + margin)
    if condition.escapable_guard:
        escape = torch.relu(margin - violation_of(condition.guard, env))
        shortfall = torch.minimum(shortfall, escape)
    return shortfall


def is_met(shortfall: torch.Tensor, guard: L.Formula, env) -> bool:
    """Whether the condition is met on the samples where its guard holds exactly. A
    guard that holds exactly on no sample (a level set, B(x) = 0) is judged on the band
    trained on."""
    mask = guard_mask(guard, env, len(shortfall), 0.0)
    if not mask.any():
        mask = guard_mask(guard, env, len(shortfall), GUARD_BAND)
    return bool((shortfall[mask] == 0).all())


def condition_loss(condition: Condition, points: torch.Tensor, env, margin: float):
    """The mean shortfall, with the plan's margin, where the guard holds (within a
    band), and whether the samples meet the condition: with half that margin where the
    guard holds, or, for an escapable guard, with the margin on the whole band."""
    if condition.scaled_margin:
        margin = margin * (points ** 2).sum(1).detach()
    mask = guard_mask(condition.guard, env, len(points), GUARD_BAND)
    if not mask.any():
        return torch.zeros((), dtype=torch.float64), True
    shortfall = shortfall_of(condition, env, margin)
    if condition.escapable_guard:  # a point may meet it by leaving the guard's band
        satisfied = bool((shortfall[mask] == 0).all())
    else:
        satisfied = is_met(shortfall_of(condition, env, margin / 2).detach(), condition.guard,
                           env)
    return shortfall[mask].mean(), satisfied
