"""Moving sample points uphill on a condition's violation, to find where a candidate
fails: random samples rarely land on a level set or in the corners of a box, where
verifiers find the violations of near-linear certificates. Nothing here proves
anything; the points found are training samples."""
from __future__ import annotations

from typing import Callable

import torch

# at points x (requiring gradients): the claim's violation, and the guard's level-set
# value (zero on the set), or None where the guard is not a level set
Objective = Callable[[torch.Tensor], tuple[torch.Tensor, torch.Tensor | None]]

PROJECTION_STEPS = 3  # Newton steps back onto the level set after each move


def climb(points: torch.Tensor, objective: Objective, box, steps: int,
          step_fraction: float) -> torch.Tensor:
    """Signed-gradient ascent of the violation within the box, each move along the
    level set (the gradient's part across it removed) and followed by a projection
    back onto it. A move is `step_fraction` of the box's width in each coordinate."""
    low = torch.tensor(box[0], dtype=torch.float64)
    high = torch.tensor(box[1], dtype=torch.float64)
    move = step_fraction * (high - low)
    x = points.detach()
    for _ in range(steps):
        x = x.clone().requires_grad_(True)
        violation, level = objective(x)
        uphill, = torch.autograd.grad(violation.sum(), x, retain_graph=level is not None)
        if level is not None:
            across = _gradient(level, x)
            uphill = uphill - _component(uphill, across) * across
        x = _clamp(x.detach() + move * torch.sign(uphill), low, high)
        if level is not None:
            x = _project(x, objective, low, high)
    return x.detach()


def _project(x: torch.Tensor, objective: Objective, low, high) -> torch.Tensor:
    """Newton steps onto the level set, moving only coordinates that are not pressed
    against the side of the box they would move through."""
    for _ in range(PROJECTION_STEPS):
        x = x.clone().requires_grad_(True)
        _, level = objective(x)
        across = _gradient(level, x)
        outward = -level.detach().unsqueeze(1) * across
        pressed = ((x <= low) & (outward < 0)) | ((x >= high) & (outward > 0))
        across = torch.where(pressed, torch.zeros_like(across), across)
        x = _clamp(x.detach() - level.detach().unsqueeze(1) / _squared_norm(across) * across,
                   low, high)
    return x


def _gradient(value: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    gradient, = torch.autograd.grad(value.sum(), x, retain_graph=True)
    return gradient


def _squared_norm(v: torch.Tensor) -> torch.Tensor:
    return (v * v).sum(1, keepdim=True).clamp_min(1e-30)


def _component(v: torch.Tensor, along: torch.Tensor) -> torch.Tensor:
    return (v * along).sum(1, keepdim=True) / _squared_norm(along)


def _clamp(x: torch.Tensor, low: torch.Tensor, high: torch.Tensor) -> torch.Tensor:
    return torch.minimum(torch.maximum(x, low), high)
