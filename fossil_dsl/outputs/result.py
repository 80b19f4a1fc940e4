"""The result of a run, what it means in words, and the files a user keeps: result.json,
certificate.txt and the SMT-LIB 2 proof obligations (one file per condition)."""
from __future__ import annotations

import platform
from importlib import metadata
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from fossil_dsl.version import __version__
from fossil_dsl.engine.loop import CegisOutcome
from fossil_dsl.ir import expr as E
from fossil_dsl.ir.symbolic import to_sympy
from fossil_dsl.kernel import Claim, NoRule, Verdict, not_certified
from fossil_dsl.kernel import list_obligations as kernel_obligations
from fossil_dsl.kernel.export import script
from fossil_dsl.plan.compile import Plan
from fossil_dsl.outputs.artefacts import write_artefacts
from fossil_dsl.outputs.plot import phase_portrait
from fossil_dsl.outputs.summary import summary_html, summary_text
from fossil_dsl.solvers import registry
from fossil_dsl.solvers.smtlib import query_text

SCHEMA_VERSION = 3  # docs/cli.md; 2 added networks, versions; 3 the kernel, spec text, ball


@dataclass(frozen=True)
class ConditionReport:
    name: str
    text: str
    status: str  # "unsat" (proved), "sat" (counterexample), "unknown", "not verified"
    reason: str
    counterexample: tuple[Fraction, ...] | None
    solver: str = ""  # which solver answered


@dataclass(frozen=True)
class Result:
    plan: Plan
    certified: bool
    reason: str
    formulas: dict[str, E.Expr]
    controller: dict[str, E.Expr]  # input -> k_i(x); empty without inputs
    levels: dict[str, Fraction]
    conditions: tuple[ConditionReport, ...]
    obligations: dict[str, str]  # condition name -> SMT-LIB 2 script (unsat = proved)
    iterations: int
    learn_seconds: float
    verify_seconds: float
    total_seconds: float
    digits: int = 3  # decimals the network weights were rounded to
    networks: dict = field(default_factory=dict)  # name -> trained torch module ("k": controller)
    kernel: Verdict = field(default_factory=lambda: not_certified("not judged"))
    interrupted: bool = False  # stopped by Ctrl-C (the shell's exit code 130)
    strategy: str = "learning"  # how the functions were found (not part of any proof)
    refutations: dict = field(default_factory=dict)  # obligation -> sum-of-squares evidence
    portfolio: dict = field(default_factory=dict)  # the race that found it (--portfolio)
    region: dict = field(default_factory=dict)  # region: largest (outputs/region.py)

    @property
    def verdict(self) -> str:
        return "certified" if self.certified else "not certified"

    @property
    def exit_code(self) -> int:
        return 130 if self.interrupted else 0 if self.certified else 1

    @property
    def learn_only(self) -> bool:
        return self.plan.options.learn_only

    def guarantee(self) -> str:
        """What is proved, in words: the kernel's, from the rule it proved."""
        return self.kernel.guarantee if self.certified else "nothing is proved"

    def assumptions(self) -> list[str]:
        plan = self.plan
        found = [_provers(self.conditions) + " (its queries were UNSAT) for the exact "
                 "formulas shown"]
        if self.kernel.strengthened is None:
            found.append("the conditions are checked only inside the domain D")
        for name in dict.fromkeys(c.solver for c in self.conditions):
            info = registry.BACKENDS.get(name)  # none for the exact sum-of-squares check
            if info is None:
                continue
            if info.caveat:
                found.append(info.caveat)
            if info.delta_decision:
                found.append(f"{name} is a delta-decision procedure: only its UNSAT "
                             "answers are used as proofs, and it proves the closed (stronger) "
                             "form of strict inequalities")
        if any(f.candidate is None for f in plan.functions):
            found.append(f"network weights were rounded to {self.digits} decimals "
                         "before verifying; the rounded function is the one proved")
        return found

    def summary(self) -> str:
        """The text `fossilc` prints: verdict, formulas, conditions, guarantee."""
        return summary_text(self)

    def _repr_html_(self) -> str:
        """Jupyter shows a Result as its summary and phase portrait."""
        return summary_html(self)

    @property
    def sympy(self) -> dict:
        """Each function of the certificate (by name) and each controller output (by
        input name) as an exact sympy expression over real symbols named after the
        states."""
        symbols: dict = {}
        found = {name: to_sympy(f, symbols) for name, f in self.formulas.items()}
        found.update({u: to_sympy(k, symbols) for u, k in self.controller.items()})
        return found

    def save(self, directory: str | Path) -> Path:
        """Write result.json, certificate.txt, obligations/*.smt2 and networks.pt."""
        return write_artefacts(self, directory)

    def plot(self, path: str | Path | None = None):
        """The phase portrait (a matplotlib Figure), also written to `path` (.png or
        .svg) if given. 2- and 3-state specs only."""
        return phase_portrait(self, path)

    def to_json(self) -> dict:
        plan = self.plan
        return {
            "schema": SCHEMA_VERSION,
            "fossil_dsl": __version__,
            "spec": {"name": plan.spec.name, "path": plan.spec.path,
                     "text": plan.spec.source},
            "property": {"form": plan.spec.property.form, "formula": plan.spec.property.text,
                         "roles": {role: region.text()
                                   for role, region in plan.spec.property.roles.items()}},
            "certificate": plan.certificate.title,
            "certificate_kind": type(plan.certificate).__name__,
            "verdict": self.verdict,
            "reason": self.reason,
            "guarantee": self.guarantee(),
            "assumptions": self.assumptions() if self.certified else [],
            "functions": {name: str(f) for name, f in self.formulas.items()},
            "networks": {name: network_json(n, self.digits) for name, n in self.networks.items()},
            "controller": {name: str(f) for name, f in self.controller.items()},
            "levels": {name: str(v) for name, v in self.levels.items()},
            "excluded_ball": str(plan.origin_radius),
            "learn_only": self.learn_only,
            "interrupted": self.interrupted,
            "strategy": self.strategy,
            **({"portfolio": self.portfolio} if self.portfolio else {}),
            **({"region": self.region} if self.region else {}),
            "conditions": [_condition_json(c) for c in self.conditions],
            "kernel": kernel_json(self.kernel),
            "verifier": plan.verifier,
            "fallback": plan.fallback,
            "iterations": self.iterations,
            "seed": plan.options.seed,
            "digits": self.digits,
            "seconds": {"learn": _seconds(self.learn_seconds),
                        "verify": _seconds(self.verify_seconds),
                        "total": _seconds(self.total_seconds)},
            "versions": versions(),
        }


def kernel_json(verdict: Verdict) -> dict:
    """The kernel's verdict and each obligation it decided, with its procedure."""
    return {"verdict": "certified" if verdict.certified else "not certified",
            "reason": verdict.reason, "seconds": _seconds(verdict.seconds),
            "strengthening": verdict.strengthened,
            "variant": verdict.variant,
            "obligations": [{"name": p.obligation.name, "text": p.obligation.text,
                             "outcome": p.outcome.value, "procedure": p.procedure,
                             "detail": p.detail, "witness": None if p.witness is None
                             else [str(v) for v in p.witness]} for p in verdict.proofs]}


def network_json(network, digits: int) -> dict:
    """A network's layers with every weight and bias as an exact rational ("p/q"): the
    values that the formulas above were built from (weights on x itself, so a first
    layer that sees x / input_divisor is given with its weights divided)."""
    linears = [*network.linears, network.output]
    activations = [act.name for act in network.activations] + ["identity"]
    layers = [{"activation": activation,
               "weight": [[str(w) for w in row] for row in weights],
               "bias": None if linear.bias is None else [str(b) for b in biases]}
              for linear, activation, (weights, biases)
              in zip(linears, activations, network.exact_layers(digits))]
    return {"inputs": linears[0].in_features, "outputs": network.outputs,
            "subtracts_value_at_origin": network.subtract_origin, "layers": layers}


def versions() -> dict[str, str | None]:
    """The versions of Python and of every package that took part."""
    found = {"python": platform.python_version(), "fossil_dsl": __version__}
    for package in ("torch", "z3-solver", "cvc5", "codac", "dreal", "sympy", "lark"):
        try:
            found[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            found[package] = None
    return found


def _provers(conditions) -> str:
    by_solver: dict[str, list[str]] = {}
    for condition in conditions:
        by_solver.setdefault(condition.solver, []).append(condition.name)
    if len(by_solver) == 1:
        return f"every condition was proved by {next(iter(by_solver))}"
    return "each condition was proved by the solver named: " + "; ".join(
        f"{solver} ({', '.join(names)})" for solver, names in by_solver.items())


def _seconds(value: float) -> float:
    return float(f"{value:.3f}")


def _condition_json(report: ConditionReport) -> dict:
    point = [str(v) for v in report.counterexample] if report.counterexample else None
    return {"name": report.name, "text": report.text, "status": report.status,
            "reason": report.reason, "counterexample": point, "solver": report.solver}


def claim_of(plan: Plan, outcome: CegisOutcome) -> Claim:
    """What the engine proposes to the kernel: the spec and the final exact formulas."""
    candidate = outcome.candidate
    return Claim(plan.spec, dict(candidate.formulas), dict(candidate.controller),
                 dict(candidate.levels), plan.origin_radius,
                 {v.condition: v.solver for v in outcome.verdicts if v.solver},
                 dict(outcome.refutations))


def build_result(plan: Plan, outcome: CegisOutcome, verdict: Verdict,
                 total_seconds: float) -> Result:
    """The result of a run; certified exactly when the kernel's verdict is."""
    # the queries left out the ball |x| <= r (the kernel may prove its inside apart)
    texts = {c.name: c.text + (f" (queried for |x| > {E.Num(plan.origin_radius)})"
                               if c.exclude_origin and plan.origin_radius > 0 else "")
             for c in plan.conditions}
    reports = tuple(ConditionReport(v.condition, texts[v.condition],
                                    "not verified" if plan.options.learn_only else v.status.value,
                                    v.reason, v.counterexample, v.solver or plan.verifier)
                    for v in outcome.verdicts)
    candidate = outcome.candidate
    reason = outcome.reason
    if outcome.certified and not verdict.certified:
        reason = f"the engine proved its conditions, but the kernel did not certify: " \
            f"{verdict.reason}"
    return Result(plan, verdict.certified, reason, dict(candidate.formulas),
                  dict(candidate.controller), dict(candidate.levels), reports,
                  obligations(plan, outcome, verdict.strengthened, verdict.variant),
                  len(outcome.history), outcome.learn_seconds,
                  outcome.verify_seconds, total_seconds, candidate.digits,
                  dict(outcome.networks), verdict, outcome.interrupted, outcome.strategy,
                  {**outcome.refutations, **_found_by_kernel(verdict)})


def _found_by_kernel(verdict: Verdict) -> dict:
    """The refutations that proved obligations (handed over, or found by the kernel), to
    be exported with them."""
    return {p.obligation.name: p.evidence for p in verdict.proofs if p.evidence is not None}


def obligations(plan: Plan, outcome: CegisOutcome, strengthened: str | None = None,
                variant: str | None = None) -> dict[str, str]:
    """The kernel's obligations for the final formulas (with those of the strengthening
    it proved) as SMT-LIB 2 scripts (unsat means proved); the engine's condition queries
    where the kernel has no rule."""
    try:
        found = kernel_obligations(claim_of(plan, outcome), strengthened, variant)
    except NoRule:
        return condition_scripts(plan, outcome)
    return {o.file_stem: script(o, plan.states, plan.spec.name) for o in found}


def condition_scripts(plan: Plan, outcome: CegisOutcome) -> dict[str, str]:
    """Each condition's query with the certificate as a named, defined function."""
    candidate = outcome.candidate
    functions = {}
    for name, formula in candidate.formulas.items():
        functions[name] = formula
        functions[f"d{name}"] = candidate.changes[name]
    functions.update({f"next_{s}": f for s, f in candidate.next_state.items()})
    change = "one-step difference C(f(x)) - C(x)" if plan.certificate.discrete else \
        "derivative along the flow, grad C . f"
    loop = [f"closed loop with the controller {u} = {k}" for u, k in candidate.controller.items()]
    scripts = {}
    for condition in plan.conditions:
        comments = [f"{plan.spec.name}: condition {condition.name}: {condition.text}",
                    "unsat means the condition holds",
                    f"each dC below is the {change}, computed exactly from C", *loop]
        scripts[condition.name] = query_text(plan.query(condition), plan.states,
                                             functions, comments, levels=candidate.levels)
    return scripts
