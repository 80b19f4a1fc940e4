"""Samples of sets: uniform in a bounding box, kept where the exact membership formula
holds (evaluated numerically). With a torch.Generator the points are torch tensors (for
learning); with a numpy Generator, numpy arrays (verifier-only runs import no torch)."""
from __future__ import annotations

import math
import sys

from typing import Sequence

import numpy as np

from fossil_dsl.ir.sets import Boundary, SetExpr
from fossil_dsl.engine.evaluate import holds, state_env

MAX_ROUNDS = 50
BISECTION_STEPS = 40


def sample(region: SetExpr, states: Sequence[str], count: int, generator, fallback_box=None):
    """Up to `count` points of `region` (fewer if the set is very thin in its box)."""
    if isinstance(region, Boundary):
        return _boundary(region.inner, states, count, generator, fallback_box)
    own = region.own_samples(count, generator)
    if own is not None:
        return _array(own, generator).reshape(-1, len(states))[:count]
    box = region.bounding_box() or fallback_box
    if box is None:
        raise ValueError(f"cannot sample {region}: no bounding box")
    low, high = _array(box[0], generator), _array(box[1], generator)
    formula = region.contains_formula(states)
    found = []
    total = 0
    for _ in range(MAX_ROUNDS):
        batch = low + (high - low) * _uniform(generator, max(count, 64) * 2, len(states))
        inside = batch[holds(formula, state_env(states, batch), len(batch))]
        found.append(inside)
        total += len(inside)
        if total >= count:
            break
    return _concatenate(found, generator)[:count]


def around(points, region: SetExpr, states: Sequence[str], count: int, radius: float,
           generator, box=None):
    """The points plus `count` random neighbours of each that lie in `region`. A
    neighbour that leaves the region's box (or `box`) through a face is reflected back
    through it: at a corner of a box in n dimensions, a 2^-n share of neighbours would
    otherwise survive, and verifiers often answer with such corners."""
    if count == 0 or len(points) == 0:
        return points
    noise = _normal(generator, len(points) * count, points.shape[1]) * radius
    neighbours = points.repeat_interleave(count, 0) + noise
    box = region.bounding_box() or box
    if box is not None:
        neighbours = _reflect_into(neighbours, box, generator)
    keep = holds(region.contains_formula(states), state_env(states, neighbours),
                 len(neighbours))
    return _concatenate([points, neighbours[keep]], generator)


def _reflect_into(points, box, generator):
    low, high = _array(box[0], generator), _array(box[1], generator)
    points = _where(points < low, 2 * low - points, points)
    points = _where(points > high, 2 * high - points, points)
    return _where(points < low, low, _where(points > high, high, points))  # clamped


def _boundary(inner: SetExpr, states, count: int, generator, fallback_box):
    """Points within ~1e-12 of the boundary of `inner`: bisect segments from a point of
    the set to a point outside it (in its box grown by a fifth). Any set shape works; the
    verifier, not these points, decides the condition on the exact boundary."""
    box = inner.bounding_box() or fallback_box
    if box is None:
        raise ValueError(f"cannot sample the boundary of {inner}: no bounding box")
    low, high = _array(box[0], generator), _array(box[1], generator)
    grow = 0.2 * (high - low) + 1e-3
    formula = inner.contains_formula(states)
    inside = sample(inner, states, count, generator, fallback_box)
    if len(inside) == 0:
        return inside
    outside = sample_outside(formula, states, low - grow, high + grow, len(inside), generator)
    if len(outside) == 0:
        return outside
    a, b = inside[:len(outside)], outside[:len(inside)]
    for _ in range(BISECTION_STEPS):
        middle = (a + b) / 2
        in_set = holds(formula, state_env(states, middle), len(middle))[:, None]
        a, b = _where(in_set, middle, a), _where(in_set, b, middle)
    return a


def sample_outside(formula, states, low, high, count: int, generator):
    found, total = [], 0
    for _ in range(MAX_ROUNDS):
        batch = low + (high - low) * _uniform(generator, max(count, 64) * 2, len(states))
        outside = batch[~holds(formula, state_env(states, batch), len(batch))]
        found.append(outside)
        total += len(outside)
        if total >= count:
            break
    return _concatenate(found, generator)[:count]


# ---- the same few operations on torch (a torch.Generator) and numpy (np.random.Generator)
def _numpy(generator) -> bool:
    return isinstance(generator, np.random.Generator)


def _array(values, generator):
    if _numpy(generator):
        return np.asarray(values, dtype=np.float64)
    import torch
    return torch.as_tensor(values, dtype=torch.float64)


def _uniform(generator, rows: int, columns: int):
    if _numpy(generator):
        return generator.random((rows, columns))
    import torch
    return torch.rand(rows, columns, generator=generator, dtype=torch.float64)


def _normal(generator, rows: int, columns: int):
    if _numpy(generator):
        return generator.standard_normal((rows, columns))
    import torch
    return torch.randn(rows, columns, generator=generator, dtype=torch.float64)


def _concatenate(arrays, generator):
    if _numpy(generator):
        return np.concatenate(arrays)
    import torch
    return torch.cat(arrays)


def _where(mask, yes, no):
    return np.where(mask, yes, no) if isinstance(mask, np.ndarray) else \
        sys.modules["torch"].where(mask, yes, no)


def box_centre(box) -> list[float] | None:
    if box is None:
        return None
    centre = [(low + high) / 2 for low, high in zip(*box)]
    return centre if all(map(math.isfinite, centre)) else None


def box_scale(box) -> float:
    if box is None:
        return 1.0
    return max(high - low for low, high in zip(*box))
