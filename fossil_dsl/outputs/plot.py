"""Phase portraits of a result, as in the tool paper's case-study figure: the closed-loop
vector field, trajectories from the initial set, every named set, and the zero (or
level) contours of the certificate's functions. 2-state specs get one picture; 3-state
specs get three 2-D slices through the centre of the domain.

Everything is computed from the exact formulas of the result (with the controller
substituted), never from the trained networks, so the picture shows what was proved.
"""
from __future__ import annotations

from itertools import combinations
from pathlib import Path

import numpy as np

from fossil_dsl.diagnostics import FslError
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.engine.sampling import sample
from fossil_dsl.outputs.simulate import closed_loop, column, in_region, rk4_step

GRID = 200  # points per axis for sets and contours
ARROWS = 24  # points per axis for the vector field
TRAJECTORIES = 16
SET_COLOURS = ("tab:green", "tab:red", "tab:blue", "tab:orange", "tab:purple", "tab:brown")
FUNCTION_COLOURS = ("black", "tab:cyan", "tab:pink", "tab:olive")


class PlotError(FslError):
    pass


def phase_portrait(result, path: str | Path | None = None, seed: int = 0):
    """The matplotlib Figure of the result's phase portrait; written to `path` too if
    given (the suffix, .png or .svg, picks the format)."""
    import matplotlib
    matplotlib.use("Agg")  # files only: no display is needed or wanted
    import matplotlib.pyplot as plt

    states = result.plan.states
    if len(states) not in (2, 3):
        raise PlotError(f"phase portraits are drawn for 2- and 3-state specs; "
                        f"{result.plan.spec.name} has {len(states)} states")
    portrait = _Portrait(result, seed)
    pairs = [(0, 1)] if len(states) == 2 else list(combinations(range(3), 2))
    figure, axes = plt.subplots(1, len(pairs), figsize=(6.4 * len(pairs), 5.6), squeeze=False)
    for ax, pair in zip(axes[0], pairs):
        portrait.draw(ax, pair)
    figure.suptitle(f"{result.plan.spec.name}: {result.verdict}")
    figure.tight_layout()
    if path is not None:
        suffix = Path(path).suffix.lower()
        if suffix not in (".png", ".svg"):
            raise PlotError(f"{path}: a phase portrait is written as .png or .svg")
        figure.savefig(path, dpi=120)
        plt.close(figure)
    return figure


class _Portrait:
    def __init__(self, result, seed: int):
        self.result = result
        self.spec = result.plan.spec
        self.states = result.plan.states
        self.low, self.high = _box(self.spec)
        self._field_at = closed_loop(result)
        self.centre = [_slice_value(a, b) for a, b in zip(self.low, self.high)]
        self.paths = self._trajectories(seed)

    # ---- drawing ----
    def draw(self, ax, pair: tuple[int, int]) -> None:
        i, j = pair
        grid, X, Y = self._grid(pair, GRID)
        for (name, region), colour in zip(self._sets(), SET_COLOURS * 4):
            inside = holds(region.contains_formula(self.states),
                           state_env(self.states, grid), len(grid)).reshape(X.shape)
            mask = inside.astype(np.float64)
            ax.contourf(X, Y, mask, levels=[0.5, 1.5], colors=[colour], alpha=0.12)
            ax.contour(X, Y, mask, levels=[0.5], colors=[colour], linewidths=1.2)
            ax.plot([], [], color=colour, label=name)
        if self.result.region:
            self._draw_region(ax, grid, X, Y)
        self._draw_field(ax, pair)
        self._draw_functions(ax, grid, X, Y)
        # a map's trajectory is its iterates: points, joined by thin lines in order
        style = dict(marker="o", markersize=2.5, linewidth=0.4) \
            if self.spec.time is TimeDomain.DISCRETE else dict(linewidth=0.8)
        for path in self.paths:
            ax.plot(path[:, i], path[:, j], color="tab:gray", alpha=0.9, **style)
        ax.set_xlim(self.low[i], self.high[i])
        ax.set_ylim(self.low[j], self.high[j])
        ax.set_xlabel(self.states[i])
        ax.set_ylabel(self.states[j])
        if len(self.states) == 3:
            k = 3 - i - j
            ax.set_title(f"slice {self.states[k]} = {self.centre[k]:g} "
                         "(trajectories projected)")
        ax.legend(loc="upper right", fontsize="small", framealpha=0.8)

    def _draw_region(self, ax, grid, X, Y) -> None:
        """`region: largest`: the certified Ω = {x in D : V(x) <= β}, filled."""
        inside = in_region(self.result, grid).reshape(X.shape).astype(np.float64)
        ax.contourf(X, Y, inside, levels=[0.5, 1.5], colors=["tab:purple"], alpha=0.25)
        ax.plot([], [], color="tab:purple", alpha=0.4, linewidth=6,
                label=f"certified Ω ({100 * self.result.region['basin_coverage']:.0f} % of "
                "the simulated basin in D)")

    def _draw_field(self, ax, pair) -> None:
        i, j = pair
        grid, X, Y = self._grid(pair, ARROWS)
        values = self._field_at(grid)
        if self.spec.time is TimeDomain.DISCRETE:
            values = values - grid  # the step a point takes
        U, V = values[:, i].reshape(X.shape), values[:, j].reshape(X.shape)
        ax.quiver(X, Y, U, V, color="tab:blue", alpha=0.35, angles="xy", pivot="mid")

    def _draw_functions(self, ax, grid, X, Y) -> None:
        env = state_env(self.states, grid)
        for (name, formula), colour in zip(self.result.formulas.items(), FUNCTION_COLOURS * 4):
            values = column(evaluate(formula, env), len(grid)).reshape(X.shape)
            levels = self._levels_of(name)
            if not levels or not values.min() < max(levels) or not min(levels) < values.max():
                levels = [0.0] if values.min() < 0 < values.max() else \
                    self._sublevels(values, grid, X.shape)
            if levels:
                ax.contour(X, Y, values, levels=sorted(set(levels)), colors=[colour],
                           linewidths=2.0)
                shown = ", ".join(f"{v:.3g}" for v in sorted(set(levels)))
                ax.plot([], [], color=colour, linewidth=2.0, label=f"{name} = {shown}")

    def _sublevels(self, values, grid, shape) -> list[float]:
        """For a function with no level of its own (a Lyapunov V): three sublevel sets
        inside the domain."""
        inside = holds(self.spec.domain.contains_formula(self.states),
                       state_env(self.states, grid), len(grid)).reshape(shape)
        # a hole around the origin (an annulus) is not where V leaves the domain
        far = np.linalg.norm(grid, axis=1) > 0.5 * min(h - l for l, h in zip(self.low, self.high)) / 2
        outside = values[~inside & far.reshape(shape)]
        top = float(outside.min()) if outside.size else float(values.max())
        return [top * f for f in (0.1, 0.4, 0.9)] if top > 0 else []

    def _levels_of(self, function: str) -> list[float]:
        named = {level.name: level.function for level in self.result.plan.levels}
        found = [float(v) for k, v in self.result.levels.items() if named.get(k) == function]
        zero_level = any(f.name == function and not f.zero_at_origin
                         for f in self.result.plan.functions)
        return found + ([0.0] if zero_level else [])

    # ---- numbers ----
    def _grid(self, pair, count: int):
        i, j = pair
        xs = np.linspace(self.low[i], self.high[i], count)
        ys = np.linspace(self.low[j], self.high[j], count)
        X, Y = np.meshgrid(xs, ys, indexing="xy")
        grid = np.tile(np.asarray(self.centre, dtype=np.float64), (X.size, 1))
        grid[:, i], grid[:, j] = X.reshape(-1), Y.reshape(-1)
        return grid, X, Y

    def _sets(self) -> list[tuple[str, object]]:
        named = dict(self.spec.sets)
        return [("domain", self.spec.domain)] + [(n, s) for n, s in named.items()
                                                   if s is not self.spec.domain]

    def _trajectories(self, seed: int) -> list:
        start_set = self.spec.property.role("initial") or self.spec.domain
        generator = np.random.default_rng(seed)
        starts = self._region_edge(generator) if self.result.region else \
            sample(start_set, self.states, TRAJECTORIES, generator, (self.low, self.high))
        if self.spec.time is TimeDomain.DISCRETE:
            return _iterate(self._field_at, starts, 60, self.low, self.high)
        span = max(h - l for l, h in zip(self.low, self.high))
        return _integrate(self._field_at, starts, span, self.low, self.high)

    def _region_edge(self, generator) -> np.ndarray:
        """Points of Ω next to its edge (the largest V in Ω), to start trajectories."""
        points = sample(self.spec.domain, self.states, 4000, generator, (self.low, self.high))
        kept = points[in_region(self.result, points)]
        values = column(evaluate(self.result.formulas["V"], state_env(self.states, kept)),
                         len(kept))
        return kept[np.argsort(values)[-TRAJECTORIES:]]


def _integrate(field, starts, span: float, low, high, steps: int = 600) -> list:
    """RK4 paths, each cut where it leaves the (slightly enlarged) domain box."""
    speed = float(np.nan_to_num(np.linalg.norm(field(starts), axis=1)).max()) or 1.0
    dt = 4 * span / speed / steps
    points, history = starts.copy(), [starts.copy()]
    for _ in range(steps):
        points = rk4_step(field, points, dt)
        history.append(points.copy())
    return _cut(np.stack(history, 1), low, high)


def _iterate(step, starts, steps: int, low, high) -> list:
    points, history = starts.copy(), [starts.copy()]
    for _ in range(steps):
        points = step(points)
        history.append(points.copy())
    return _cut(np.stack(history, 1), low, high)


def _cut(paths: np.ndarray, low, high) -> list:
    margin = 0.05 * (np.asarray(high) - np.asarray(low))
    lo, hi = np.asarray(low) - margin, np.asarray(high) + margin
    result = []
    with np.errstate(invalid="ignore"):
        for path in paths:
            inside = ((path >= lo) & (path <= hi)).all(1) & np.isfinite(path).all(1)
            stop = int(np.cumprod(inside.astype(np.int64)).sum())
            result.append(path[:max(stop, 1)])
    return result


def _box(spec) -> tuple[list[float], list[float]]:
    box = spec.domain.bounding_box()
    if box is None:
        boxes = [s.bounding_box() for s in spec.sets.values()]
        boxes = [b for b in boxes if b is not None]
        if not boxes:
            return [-1.0] * len(spec.states), [1.0] * len(spec.states)
        low = [min(b[0][i] for b in boxes) for i in range(len(spec.states))]
        high = [max(b[1][i] for b in boxes) for i in range(len(spec.states))]
        return low, high
    return [float(v) for v in box[0]], [float(v) for v in box[1]]


def _slice_value(low: float, high: float) -> float:
    """Where a 3-state slice cuts an axis: at 0 (the equilibrium) if the domain
    reaches it, else through the middle."""
    return 0.0 if low <= 0.0 <= high else (low + high) / 2


def write_portraits(result, stem: str | Path) -> list[Path]:
    """PNG and SVG pictures, `stem`.png and `stem`.svg."""
    written = []
    for suffix in (".png", ".svg"):
        path = Path(f"{stem}{suffix}")
        phase_portrait(result, path)
        written.append(path)
    return written

