"""BarrierBench problems as .fsl specs.

    python benchmarks/barrierbench_specs.py ../shared/barrierbench-dev.json specs/barrierbench
    python benchmarks/barrierbench_specs.py benchmarks/data/barrierbench-unsolved.json \
        specs/barrierbench-unsolved unsolved_problems bbu

The second: BarrierBench's problems published without a barrier (no method has solved
them), kept in benchmarks/data/.

BarrierBench (L4DC 2026) states dynamics, an initial set and an unsafe set, and no
domain: its claims are global ("never enter U"). A spec needs a bounded domain, chosen
here as follows:
- unsafe = the complement of a ball B(c, r): the domain is B(c, 1.1 r), so `unsafe` is
  the ring between r and 1.1 r. In continuous time a trajectory cannot leave the domain
  without crossing that ring, so "never enters U while in D" is the global claim.
- otherwise: the box round every set of the problem, widened by half its size on each
  side (at least 1), centred on the sets.
The published barrier and controller are kept in the header as comments (not used).
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

RING = 1.1  # the domain's radius over the unsafe ball's, for a complement-of-ball unsafe set
WIDEN = 0.5  # each side of the box domain, as a share of the sets' hull's size


def equations(dynamics: str) -> tuple[str, list[tuple[str, str]]]:
    """('continuous' or 'discrete', [(state, expression)]) in .fsl syntax."""
    discrete = "[k+1]" in dynamics
    head = r"x(\d+)\[k\+1\]\s*=" if discrete else r"dx(\d+)/dt\s*="
    parts = re.split(head, dynamics)
    found = []
    for index, expression in zip(parts[1::2], parts[2::2]):
        expression = expression.strip().rstrip(",").strip()
        expression = re.sub(r"\[k\]", "", expression).replace("**", "^")
        found.append((f"x{index}", expression))
    return ("discrete" if discrete else "continuous"), found


def vector(values) -> str:
    return "[" + ", ".join(format(float(v), "g") for v in values) + "]"


def set_text(region: dict) -> str:
    text = _plain_set_text(region)
    if not region.get("complement"):
        return text
    return f"~({text})" if region["type"] == "union" else f"~{text}"


def _plain_set_text(region: dict) -> str:
    kind = region["type"]
    if kind == "ball":
        return f"ball({vector(region['center'])}, {format(float(region['radius']), 'g')})"
    if kind in ("box", "bounds"):
        lows, highs = zip(*region["bounds"])
        return f"box({vector(lows)}, {vector(highs)})"
    if kind == "union":
        return " | ".join(f"({set_text(part)})" for part in region["sets"])
    raise ValueError(f"unknown set type {kind!r}")


def hull(region: dict, n: int) -> tuple[list[float], list[float]]:
    kind = region["type"]
    if kind == "ball":
        c, r = region["center"], float(region["radius"])
        return [x - r for x in c], [x + r for x in c]
    if kind in ("box", "bounds"):
        lows, highs = zip(*region["bounds"])
        return list(map(float, lows)), list(map(float, highs))
    pieces = [hull(part, n) for part in region["sets"]]
    return ([min(p[0][i] for p in pieces) for i in range(n)],
            [max(p[1][i] for p in pieces) for i in range(n)])


def domain_text(problem: dict, n: int) -> str:
    unsafe = problem["unsafe_set"]
    if unsafe["type"] == "ball" and unsafe.get("complement"):
        return f"ball({vector(unsafe['center'])}, {format(RING * float(unsafe['radius']), 'g')})"
    boxes = [hull(problem[k], n) for k in ("initial_set", "unsafe_set")]
    low = [min(b[0][i] for b in boxes) for i in range(n)]
    high = [max(b[1][i] for b in boxes) for i in range(n)]
    margin = [max(1.0, WIDEN * (h - l)) for l, h in zip(low, high)]
    return f"box({vector(l - m for l, m in zip(low, margin))}, " \
           f"{vector(h + m for h, m in zip(high, margin))})"


def spec_text(name: str, entry: dict, part: str = "dev half") -> str:
    problem = entry["problem"]
    time, found = equations(problem["dynamics"])
    states = [s for s, _ in found]
    inputs = [u.strip() for u in problem.get("controller_parameters", "").split(",") if u.strip()]
    lines = [f"# BarrierBench (L4DC 2026), {part}: {name}.",
             f"# Published barrier: {entry.get('barrier', '?')}"]
    if entry.get("controllers"):
        lines.append(f"# Published controller: {entry['controllers']}")
    lines += ["# Domain chosen by benchmarks/barrierbench_specs.py (BarrierBench states none).",
              f"spec {name}", "", f"state {', '.join(states)}"]
    if inputs:
        lines.append(f"input {', '.join(inputs)}")
    left = (lambda s: f"{s}'") if time == "continuous" else (lambda s: f"next({s})")
    lines += [f"dynamics {time} {{"] + [f"    {left(s)} = {e}" for s, e in found] + ["}", ""]
    lines += [f"domain {domain_text(problem, len(states))}",
              f"set init   = {set_text(problem['initial_set'])}",
              f"set unsafe = {set_text(problem['unsafe_set'])}", "",
              "prove from init: always not unsafe", ""]
    return "\n".join(lines)


def main(source: str, target: str, key: str = "solved_problems", prefix: str = "bb") -> None:
    problems = json.loads(Path(source).read_text())[key]
    part = "dev half" if key == "solved_problems" else key.replace("_", " ")
    out = Path(target)
    out.mkdir(parents=True, exist_ok=True)
    for index, entry in enumerate(problems):
        name = f"{prefix}{index:02d}"
        (out / f"{name}.fsl").write_text(spec_text(name, entry, part))
    print(f"{len(problems)} specs written to {out}")


if __name__ == "__main__":
    main(*sys.argv[1:5])
