"""A run's folder read back as a `Result`: `fossil_dsl.load_result(DIR)`.

Everything comes from the files `-o DIR` wrote: the spec from its text in result.json
(checked and compiled again), the formulas read by the language's own parser (never
evaluated), levels and counterexamples as exact rationals, the networks from
networks.pt. The verdict is not taken from the file: the kernel judges the claim again
(`judge=True`, the default), so a loaded result is certified only if its obligations are
proved now; with `judge=False` it is returned unjudged (not certified) and quickly.
"""
from __future__ import annotations

import json
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

from fossil_dsl.kernel import Claim, judge, not_certified
from fossil_dsl.outputs.recheck import RecheckError, checked_spec, read_formulas, read_refutations
from fossil_dsl.outputs.result import ConditionReport, Result
from fossil_dsl.plan.compile import Plan, compile_spec


class LoadError(Exception):
    """The folder does not hold a readable result."""


def load_result(directory: str | Path, judge_again: bool = True, timeout: float = 60.0) -> Result:
    folder = Path(directory)
    try:
        data = json.loads((folder / "result.json").read_text())
    except (OSError, ValueError) as exc:
        raise LoadError(f"{folder}: cannot read result.json ({exc})") from exc
    plan = _plan(data)
    states = plan.states
    try:
        formulas = read_formulas(data.get("functions", {}), states)
        controller = read_formulas(data.get("controller", {}), states)
    except RecheckError as exc:
        raise LoadError(str(exc)) from exc
    levels = {k: Fraction(v) for k, v in data.get("levels", {}).items()}
    # the procedure that proved each obligation before goes first: only the order
    procedures = {o["name"].removeprefix("condition:"): o.get("procedure", "")
                  for o in data.get("kernel", {}).get("obligations", [])}
    claim = Claim(plan.spec, formulas, controller, levels, plan.origin_radius, procedures,
                  read_refutations(folder))
    verdict = judge(claim, timeout=timeout) if judge_again else \
        not_certified("loaded without judging (judge_again=False); result.json says "
                      f"{data.get('verdict')!r}")
    seconds = data.get("seconds", {})
    # a run that was not certified keeps its own reason (a property refuted, say)
    own = verdict.certified or data.get("verdict") != "certified"
    return Result(plan, verdict.certified, data.get("reason", "") if own
                  else verdict.reason, formulas, controller, levels,
                  tuple(_condition(c) for c in data.get("conditions", [])),
                  _obligations(folder), int(data.get("iterations", 0)),
                  float(seconds.get("learn", 0)), float(seconds.get("verify", 0)),
                  float(seconds.get("total", 0)), int(data.get("digits", 3)),
                  _networks(folder, plan), verdict, bool(data.get("interrupted", False)),
                  str(data.get("strategy", "learning")), claim.refutations,
                  data.get("portfolio", {}), data.get("region", {}))


def _plan(data: dict) -> Plan:
    try:
        spec = checked_spec(data)
    except RecheckError as exc:
        raise LoadError(str(exc)) from exc
    options = {"seed": data.get("seed"), "verifier": data.get("verifier")}
    plan = compile_spec(spec, **{k: v for k, v in options.items() if v is not None})
    # the ball the run left out (a V shaped to the basin leaves one out even with Z3):
    # the kernel proves it apart or weakens the guarantee to ε-stability, as in the run
    ball = Fraction(data.get("excluded_ball", "0"))
    return replace(plan, origin_radius=ball) if ball > 0 else plan


def _condition(entry: dict) -> ConditionReport:
    point = entry.get("counterexample")
    return ConditionReport(entry["name"], entry.get("text", ""), entry.get("status", ""),
                           entry.get("reason", ""),
                           None if point is None else tuple(Fraction(v) for v in point),
                           entry.get("solver", ""))


def _obligations(folder: Path) -> dict[str, str]:
    return {path.stem: path.read_text()
            for path in sorted((folder / "obligations").glob("*.smt2"))}


def _networks(folder: Path, plan: Plan) -> dict:
    """The trained networks (torch modules) from networks.pt, shaped by the plan."""
    path = folder / "networks.pt"
    if not path.exists():
        return {}
    import torch
    from fossil_dsl.engine.networks import Network
    states = torch.load(path, weights_only=True)
    shapes = {f.name: (f.layers, f.zero_at_origin, 1) for f in plan.functions}
    if plan.controller is not None:
        c = plan.controller
        shapes["k"] = (c.layers, c.zero_at_origin, len(c.inputs))
    found = {}
    for name, state in states.items():
        if name not in shapes:
            continue
        layers, zero_at_origin, outputs = shapes[name]
        divisor = state.get("input_divisor")
        network = Network(len(plan.states), layers, zero_at_origin, outputs=outputs,
                          input_divisor=None if divisor is None else divisor.tolist())
        network.load_state_dict(state)
        found[name] = network
    return found
