"""`fossilc recheck DIR`: check a result again without trusting the run that made it.

From the spec's text and the exact formulas in result.json, the kernel derives the
obligations of the property afresh; each must be among the exported SMT-LIB files,
unaltered (a missing or altered file is a failure), and each is proved again by an
installed solver other than the one that proved it in the run. A folder without the
spec's text (written before schema 3) is checked from its SMT-LIB files alone.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, replace
from fractions import Fraction
from pathlib import Path

from fossil_dsl.check.checker import check as check_tree
from fossil_dsl.check.context import CheckContext, Declared
from fossil_dsl.check.expressions import ExpressionChecker
from fossil_dsl.diagnostics import FslError, Source, Span
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.kernel import Claim, NoRule, list_obligations
from fossil_dsl.kernel.export import script
from fossil_dsl.kernel.obligations import file_stem
from fossil_dsl.solvers.ball_split import pieces, split_from_json
from fossil_dsl.solvers.evidence_json import refutation_from_json
from fossil_dsl.solvers.positivstellensatz import refutation_problem
from fossil_dsl.kernel.prove import SUM_OF_SQUARES, bisection_first
from fossil_dsl.solvers import registry
from fossil_dsl.solvers.api import Status
from fossil_dsl.solvers.smtlib_reader import SmtlibError, read_script
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.parser import parse_expression, parse_source

# Which solver to try first: complete ones for polynomial queries, delta-complete ones
# for the rest (Z3 decides no transcendental function). For polynomial queries the
# sum-of-squares procedure comes second: it shares no code with the SMT solvers, and
# what it finds is checked in exact arithmetic (4- to 6-state flow conditions that Z3
# proved in the run were left UNKNOWN by CVC5 and the interval search at 10 s each).
POLYNOMIAL_ORDER = ("cvc5", SUM_OF_SQUARES, "z3", "interval", "arb", "taylor", "dreal")
# ... but Arb first for a polynomial of high degree in few states (kernel/prove.py's
# rule for the interval procedure): a degree-8 decrease condition of a V shaped to a
# basin, which the interval procedure proved in the run, was left UNKNOWN by CVC5, the
# sum-of-squares procedure and Z3 at 20 s each; Arb's mean-value form refutes it in 4 s
# Arb's ball arithmetic (solvers/arb_backend.py) is the other procedure for a
# transcendental query the interval verifier proved: CVC5 left four BarrierBench flow
# conditions with sin and cos UNKNOWN at 60 s, which Arb refutes in 0.7 to 9 s.
# A refutation of the polynomial form goes before Arb: it settles at once what Arb's
# bisection, which has no contraction, needs boxes for (the part of a 4-state decrease
# condition beyond a ball, where V <= β and |x| >= R meet in no point: 39 s by Arb).
TRANSCENDENTAL_ORDER = ("dreal", "interval", SUM_OF_SQUARES, "arb", "taylor", "cvc5")
# division and abs: decided by the SMT solvers (a delta-decision procedure cannot refute
# the boxes round the origin where a rational V's decrease vanishes), and by a refutation
# where the divisors are evidently positive (probe43/x06's decrease, proved by a solver
# in a run on a loaded machine, is left UNKNOWN by CVC5, Z3, the interval search and Arb
# at 12 s each; its refutation takes a second)
ARITHMETIC_ORDER = ("cvc5", SUM_OF_SQUARES, "z3", "interval", "arb", "taylor", "dreal")
# procedures that are not verifiers of a run; "taylor" (solvers/taylor_boxes.py, numpy
# and its own elementary functions) is the interval verifier's first try in a run, and
# here apart from it: "interval" re-checks with codac alone
RECHECK_ONLY = (SUM_OF_SQUARES, "arb", "taylor")


class RecheckError(FslError):
    pass


@dataclass(frozen=True)
class Recheck:
    condition: str
    proved_by: str  # the solver the run used ("" if the run proved nothing)
    solver: str | None  # the solver used here; None if no other one is installed
    status: str  # "unsat" (re-proved), "sat", "unknown", "not rechecked", "missing", "altered"
    reason: str
    seconds: float

    @property
    def reproved(self) -> bool:
        return self.status == "unsat"


def recheck(directory: str | Path, timeout: float = 60.0,
            solver: str | None = None) -> list[Recheck]:
    """Re-derive and re-decide every obligation of the result in `directory`."""
    folder = Path(directory)
    data = _result(folder)
    used = _solvers_used(data)
    if not data.get("spec", {}).get("text"):
        return _from_files(folder, used, timeout, solver)
    spec, derived = _derive(data)
    refutations, splits = read_refutations(folder), read_splits(folder)
    checks = []
    for obligation in derived:
        stem = obligation.file_stem
        path = folder / "obligations" / f"{stem}.smt2"
        problem = _compare(path, script(obligation, spec.states, spec.name))
        if problem:
            checks.append(Recheck(stem, used.get(stem, ""), None, *problem, 0.0))
        elif obligation.name in refutations and used.get(stem) == SUM_OF_SQUARES \
                and not solver:
            checks.append(_refutation_checked(stem, obligation, refutations[obligation.name],
                                              spec.states, used.get(stem, "")))
        elif obligation.name in splits and not solver:
            checks.append(_split_checked(stem, obligation, splits[obligation.name],
                                         spec.states, used.get(stem, ""), timeout))
        else:
            checks.append(_decide(stem, obligation.query, spec.states, used.get(stem, ""),
                                  timeout, solver))
    return checks


def read_splits(folder: Path) -> dict:
    """obligation name -> its split at a ball (solvers/ball_split.py), from
    obligations/*.split.json (unreadable files are left out, as for refutations)."""
    return _read_evidence(folder, "split", split_from_json)


def _split_checked(stem: str, obligation, split, states, used: str, timeout: float) -> Recheck:
    """The refutation within the ball checked again exactly against the piece derived
    afresh, and the piece beyond it decided by a procedure other than the run's there."""
    started = time.monotonic()
    within, beyond = pieces(obligation.query, states, split.radius)
    where = f"within |x| <= {split.radius}"
    problem = refutation_problem(split.inner, within, states)
    if problem is not None:
        return Recheck(stem, used, f"{SUM_OF_SQUARES} from {stem}.split.json", "unknown",
                       f"{where}: {problem}", time.monotonic() - started)
    check = _decide(stem, beyond, states, split.procedure, timeout, None)
    return replace(check, proved_by=used, solver=f"{SUM_OF_SQUARES} from {stem}.split.json "
                   f"{where}, {check.solver} beyond", seconds=time.monotonic() - started)


def read_refutations(folder: Path) -> dict:
    """obligation name -> refutation, from obligations/*.sos.json (unreadable files are
    left out: the obligation is then decided by a solver)."""
    return _read_evidence(folder, "sos", refutation_from_json)


def _read_evidence(folder: Path, kind: str, reader) -> dict:
    found = {}
    for path in sorted((folder / "obligations").glob(f"*.{kind}.json")):
        try:
            data = json.loads(path.read_text())
            found[data["obligation"]] = reader(data)
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return found


def _refutation_checked(stem: str, obligation, refutation, states, used: str) -> Recheck:
    """The exported refutation, checked again exactly against the obligation derived
    afresh (a polynomial identity and positive semidefinite Gram matrices)."""
    started = time.monotonic()
    problem = refutation_problem(refutation, obligation.query, states)
    return Recheck(stem, used, f"{SUM_OF_SQUARES} from {stem}.sos.json",
                   "unsat" if problem is None else "unknown", problem or "",
                   time.monotonic() - started)


def _result(folder: Path) -> dict:
    try:
        return json.loads((folder / "result.json").read_text())
    except (OSError, ValueError) as exc:
        raise RecheckError(f"{folder}: cannot read result.json ({exc})") from exc


def _solvers_used(data: dict) -> dict[str, str]:
    used = {c["name"]: c.get("solver", "") for c in data.get("conditions", [])
            if c.get("status") == "unsat"}
    kernel = data.get("kernel", {}).get("obligations", [])
    used.update({file_stem(o["name"]): o.get("procedure", "") for o in kernel
                 if o.get("outcome") == "proved"})
    return used


def _derive(data: dict):
    """The checked spec from its text, and the kernel's obligations for the formulas."""
    if not data.get("functions"):  # a property refuted before any function was sought
        raise RecheckError(f"nothing to re-prove: the run found no function "
                           f"({data.get('reason', 'no reason recorded')})")
    spec = checked_spec(data)
    claim = Claim(spec, read_formulas(data.get("functions", {}), spec.states),
                  read_formulas(data.get("controller", {}), spec.states),
                  {k: Fraction(v) for k, v in data.get("levels", {}).items()},
                  Fraction(data.get("excluded_ball", "0")))
    try:
        kernel = data.get("kernel", {})
        return spec, list_obligations(claim, kernel.get("strengthening"), kernel.get("variant"))
    except NoRule as exc:
        raise RecheckError(f"the kernel has no rule for this result: {exc}") from exc


def checked_spec(data: dict):
    """The spec of a result.json, from its text, checked again."""
    if not data.get("spec", {}).get("text"):
        raise RecheckError("result.json has no spec text (written before schema 3)")
    source = Source(data["spec"].get("path") or "<result>", data["spec"]["text"])
    report = check_tree(parse_source(source))
    if report.spec is None:
        raise RecheckError(f"{source.path}: the spec in result.json no longer checks")
    return report.spec


def read_formulas(texts: dict[str, str], states) -> dict[str, E.Expr]:
    """Formulas read back by the language's own parser (never evaluated)."""
    context = CheckContext()
    for name in states:
        context.names[name] = Declared("state", ast.Ident(name, Span(1, 1)))
    reader = ExpressionChecker(context, {"state"}, "candidate")
    found = {name: reader.convert(parse_expression(text)) for name, text in texts.items()}
    if context.diagnostics:
        raise RecheckError("a formula in result.json does not read back: "
                           + "; ".join(d.message for d in context.diagnostics))
    return found


def _compare(path: Path, expected: str) -> tuple[str, str] | None:
    try:
        exported = path.read_text()
    except OSError:
        return "missing", f"{path.name} is not in obligations/: the run did not export it"
    if exported != expected:
        return "altered", f"{path.name} differs from the obligation derived from the spec"
    return None


def _decide(name: str, formula: L.Formula, variables, used: str, timeout: float,
            wanted: str | None) -> Recheck:
    solvers = [wanted] if wanted else other_solvers(used, formula)
    if not solvers:
        return Recheck(name, used, None, "not rechecked",
                       f"no installed solver other than {used} can decide it", 0.0)
    if solvers == [used]:
        return Recheck(name, used, used, "not rechecked",
                       f"{used} proved it in the run; a re-check needs another solver", 0.0)
    # the others in turn, sharing the time, until one decides (CVC5 can stall on a
    # 6-variable set relation that the interval search refutes at once); what one leaves
    # unused goes to the next (a refutation that fails in 0.2 s: Arb gets the rest)
    ends = time.monotonic() + timeout
    for index, solver in enumerate(solvers):
        started = time.monotonic()
        share = max(ends - started, 0.5) / (len(solvers) - index)
        answer = _backend(solver).check(formula, variables, share)
        status = answer.status.value
        if answer.status is Status.SAT and answer.approximate:
            # delta-SAT: a box too narrow to refute, not a counterexample
            status = "unknown"
        check = Recheck(name, used, solver, status, _reason(answer),
                        time.monotonic() - started)
        if status != "unknown":
            break
    return check


def _from_files(folder: Path, used: dict[str, str], timeout: float,
                solver: str | None) -> list[Recheck]:
    scripts = sorted((folder / "obligations").glob("*.smt2"))
    if not scripts:
        raise RecheckError(f"{folder}: no obligations/*.smt2 to re-check")
    checks = []
    for path in scripts:
        try:
            read = read_script(path.read_text())
        except (OSError, SmtlibError) as exc:
            checks.append(Recheck(path.stem, used.get(path.stem, ""), None, "not rechecked",
                                  f"unreadable: {exc}", 0.0))
            continue
        checks.append(_decide(path.stem, read.formula, read.variables,
                              used.get(path.stem, ""), timeout, solver))
    return checks


def _backend(name: str):
    if name == SUM_OF_SQUARES:
        from fossil_dsl.solvers.sos_refutation import SosBackend
        return SosBackend()
    if name == "arb":
        from fossil_dsl.solvers.arb_backend import ArbBackend
        return ArbBackend()
    if name == "taylor":
        from fossil_dsl.solvers import taylor_boxes
        return taylor_boxes
    if name == "interval":
        from fossil_dsl.solvers.interval_backend import IntervalBackend
        return IntervalBackend(taylor=False)
    return registry.load(name)


def other_solvers(used: str, formula: L.Formula) -> list[str]:
    """The installed solvers other than `used` suited to the formula, best first."""
    sides = [side for c in L.comparisons(formula) for side in (c.left, c.right)]
    polynomial = all(map(traversal.is_polynomial, sides))
    order = POLYNOMIAL_ORDER if polynomial \
        else ARITHMETIC_ORDER if all(map(traversal.is_arithmetic, sides)) \
        else TRANSCENDENTAL_ORDER
    if polynomial and bisection_first(formula, sorted(L.free_vars(formula))):
        order = ("arb",) + tuple(n for n in order if n != "arb")
    if not L.free_vars(formula):  # a fact about numbers: no box to search
        order = ("z3", "cvc5")
    return [n for n in order if n != used
            and (n in RECHECK_ONLY or registry.is_installed(n))]


def _reason(answer) -> str:
    if answer.status is Status.SAT and answer.model:
        point = ", ".join(f"{k} = {float(v):.6g}" for k, v in answer.model.items())
        if answer.approximate:
            return f"delta-sat: a box round {point} it could not refute (not a counterexample)"
        return f"counterexample {point}"
    return answer.reason or ""


def report_text(checks: list[Recheck]) -> str:
    lines = []
    for check in checks:
        before = f"proved by {check.proved_by}" if check.proved_by else "not proved in the run"
        if check.status in ("missing", "altered"):
            lines.append(f"  [{check.status.upper()}] {check.condition}: {check.reason}")
            continue
        if check.solver is None or check.status == "not rechecked":
            lines.append(f"  [not rechecked] {check.condition} ({before}): {check.reason}")
            continue
        verdict = {"unsat": "re-proved", "sat": "FAILS", "unknown": "unknown"}[check.status]
        extra = f": {check.reason}" if check.reason and not check.reproved else ""
        lines.append(f"  [{verdict}] {check.condition} ({before}; rechecked by "
                     f"{check.solver}, {check.seconds:.2f} s){extra}")
    done = sum(c.reproved for c in checks)
    exported = sum(c.reproved and (c.solver or "").endswith(".sos.json") for c in checks)
    how = ""
    if done == len(checks):
        how = " by another solver" if not exported else \
            f" ({done - exported} by another solver, {exported} by checking the exported " \
            "sum-of-squares refutation again)"
    lines.append(f"{done} of {len(checks)} obligations re-proved{how}")
    return "\n".join(lines)
