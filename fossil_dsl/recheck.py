"""`fossilc recheck DIR`: re-prove the proof obligations a run exported, each with an
installed solver other than the one that proved it, so that a certificate can be trusted
without trusting the solver, or the code, that produced it.

Each obligation (obligations/NAME.smt2) is read back from its SMT-LIB 2 text, the only
input; result.json says which solver proved it first. UNSAT means the condition holds.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

from fossil_dsl.diagnostics import FslError
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel.obligations import file_stem
from fossil_dsl.smt import registry
from fossil_dsl.smt.api import Status
from fossil_dsl.smt.smtlib_reader import SmtlibError, read_script

# Which solver to try first: complete ones for polynomial queries, delta-complete ones
# for the rest (Z3 decides no transcendental function).
POLYNOMIAL_ORDER = ("cvc5", "z3", "interval", "dreal")
TRANSCENDENTAL_ORDER = ("dreal", "interval", "cvc5")


class RecheckError(FslError):
    pass


@dataclass(frozen=True)
class Recheck:
    condition: str
    proved_by: str  # the solver the run used ("" if the run proved nothing)
    solver: str | None  # the solver used here; None if no other one is installed
    status: str  # "unsat" (re-proved), "sat", "unknown", "not rechecked"
    reason: str
    seconds: float

    @property
    def reproved(self) -> bool:
        return self.status == "unsat"


def recheck(directory: str | Path, timeout: float = 60.0,
            solver: str | None = None) -> list[Recheck]:
    """Re-decide every obligation in `directory` (written by `fossilc SPEC -o DIR`)."""
    folder = Path(directory)
    used = _solvers_used(folder)
    scripts = sorted((folder / "obligations").glob("*.smt2"))
    if not scripts:
        raise RecheckError(f"{folder}: no obligations/*.smt2 to re-check")
    return [_recheck_one(path, used.get(path.stem, ""), timeout, solver) for path in scripts]


def _solvers_used(folder: Path) -> dict[str, str]:
    try:
        data = json.loads((folder / "result.json").read_text())
    except (OSError, ValueError) as exc:
        raise RecheckError(f"{folder}: cannot read result.json ({exc})") from exc
    used = {c["name"]: c.get("solver", "") for c in data.get("conditions", [])
            if c.get("status") == "unsat"}
    kernel = data.get("kernel", {}).get("obligations", [])
    used.update({file_stem(o["name"]): o.get("procedure", "") for o in kernel
                 if o.get("outcome") == "proved"})
    return used


def _recheck_one(path: Path, used: str, timeout: float, wanted: str | None) -> Recheck:
    try:
        script = read_script(path.read_text())
    except (OSError, SmtlibError) as exc:
        return Recheck(path.stem, used, None, "not rechecked", f"unreadable: {exc}", 0.0)
    name = wanted or choose_solver(used, script.formula)
    if name is None:
        return Recheck(path.stem, used, None, "not rechecked",
                       f"no installed solver other than {used} can decide it", 0.0)
    if name == used:
        return Recheck(path.stem, used, name, "not rechecked",
                       f"{name} proved it in the run; a re-check needs another solver", 0.0)
    started = time.monotonic()
    answer = registry.load(name).check(script.formula, script.variables, timeout)
    return Recheck(path.stem, used, name, answer.status.value,
                   _reason(answer), time.monotonic() - started)


def choose_solver(used: str, formula: L.Formula) -> str | None:
    """The first installed solver, other than `used`, suited to the formula."""
    polynomial = all(E.is_polynomial(side) for c in L.comparisons(formula)
                     for side in (c.left, c.right))
    order = POLYNOMIAL_ORDER if polynomial else TRANSCENDENTAL_ORDER
    return next((n for n in order if n != used and registry.is_installed(n)), None)


def _reason(answer) -> str:
    if answer.status is Status.SAT and answer.model:
        point = ", ".join(f"{k} = {float(v):.6g}" for k, v in answer.model.items())
        return f"counterexample {point}"
    return answer.reason or ""


def report_text(checks: list[Recheck]) -> str:
    lines = []
    for check in checks:
        before = f"proved by {check.proved_by}" if check.proved_by else "not proved in the run"
        if check.solver is None or check.status == "not rechecked":
            lines.append(f"  [not rechecked] {check.condition} ({before}): {check.reason}")
            continue
        verdict = {"unsat": "re-proved", "sat": "FAILS", "unknown": "unknown"}[check.status]
        extra = f": {check.reason}" if check.reason and not check.reproved else ""
        lines.append(f"  [{verdict}] {check.condition} ({before}; rechecked by "
                     f"{check.solver}, {check.seconds:.2f} s){extra}")
    done = sum(c.reproved for c in checks)
    lines.append(f"{done} of {len(checks)} obligations re-proved"
                 + (" by another solver" if done == len(checks) else ""))
    return "\n".join(lines)
