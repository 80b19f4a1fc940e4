"""Checked spec -> certificate plan: the functions to learn, the conditions to prove (with
the set each ranges over), what to sample, and which verifier decides the queries."""
from __future__ import annotations

from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import Mapping

from fossil_dsl.certificates import Certificate, Condition, LearnedFunction, certificate_for
from fossil_dsl.certificates.base import UnsupportedProperty
from fossil_dsl.diagnostics import Diagnostic, FslError, Span, error
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.activations import ACTIVATIONS
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.smt import registry
from fossil_dsl.smt.smtlib import query_text

DEFAULT_SAMPLES = 1000


class CompileError(FslError):
    """A checked spec that cannot be compiled; `span` points at the spec element."""

    def __init__(self, message: str, span: Span | None = None):
        super().__init__(message)
        self.span = span

    def diagnostic(self) -> Diagnostic:
        return error(str(self), self.span)


@dataclass(frozen=True)
class RunOptions:
    max_iters: int
    seed: int
    timeout: float  # seconds for the whole run
    learning_rate: float = 0.05
    margin: float = 0.01
    digits: int = 3  # weights are rounded to this many decimals before verifying
    query_timeout: float = 60.0  # seconds per verifier query
    learn_steps: int = 1000  # gradient steps per CEGIS iteration at most
    counterexample_neighbours: int = 20


@dataclass(frozen=True)
class Plan:
    spec: CheckedSpec
    certificate: Certificate
    functions: tuple[LearnedFunction, ...]
    conditions: tuple[Condition, ...]
    verifier: str
    verifier_reason: str
    samples: Mapping[str, int]  # role -> number of samples
    options: RunOptions

    @property
    def states(self) -> tuple[str, ...]:
        return self.spec.states


def compile_spec(spec: CheckedSpec, **overrides) -> Plan:
    """The plan for a checked spec; `overrides` (verifier, seed, max_iters, timeout, ...)
    take precedence over the synthesis block, as command-line options do."""
    try:
        certificate = certificate_for(spec)
    except UnsupportedProperty as exc:
        raise CompileError(str(exc), spec.spans.get("prove")) from None
    if spec.inputs:
        raise CompileError("controller synthesis (a spec with `input`) is not available yet",
                           spec.spans.get(f"input:{spec.inputs[0]}"))
    functions = certificate.functions()
    for function in functions:
        _check_candidate(spec, function)
    conditions = certificate.conditions()
    verifier, reason = choose_verifier(spec, functions, overrides.pop("verifier", None))
    options = _options(spec, overrides)
    roles = {c.samples for c in conditions}
    samples = {role: spec.synthesis.samples.count(role, DEFAULT_SAMPLES) for role in roles}
    return Plan(spec, certificate, functions, conditions, verifier, reason,
                MappingProxyType(samples), options)


def _check_candidate(spec: CheckedSpec, function: LearnedFunction) -> None:
    """A given function must vanish at the origin where the certificate needs it to
    (learned networks do by construction)."""
    if function.candidate is None or not function.zero_at_origin:
        return
    try:
        at_origin = E.substitute(function.candidate, {s: E.ZERO for s in spec.states})
    except E.ExprError as exc:
        at_origin = exc
    if at_origin != E.ZERO:
        raise CompileError(f"the candidate {function.name} must be 0 at the origin, but "
                           f"{function.name}(0) = {at_origin}", spec.spans.get("option:candidate"))


def _options(spec: CheckedSpec, overrides: dict) -> RunOptions:
    given = spec.synthesis
    options = RunOptions(max_iters=given.max_iters, seed=given.seed, timeout=float(given.timeout))
    if given.learning_rate is not None:
        options = replace(options, learning_rate=float(given.learning_rate))
    if given.margin is not None:
        options = replace(options, margin=float(given.margin))
    unknown = set(overrides) - set(RunOptions.__dataclass_fields__)
    if unknown:
        raise TypeError(f"unknown options: {sorted(unknown)}")
    return replace(options, **{k: v for k, v in overrides.items() if v is not None})


def is_polynomial_problem(spec: CheckedSpec, functions) -> bool:
    expressions = list(spec.dynamics) + [f.candidate for f in functions if f.candidate]
    sets = [spec.domain, *spec.sets.values()]
    formulas = [s.contains_formula(spec.states) for s in sets]
    comparisons = [c for f in formulas for c in L.comparisons(f)]
    expressions += [side for c in comparisons for side in (c.left, c.right)]
    layers_polynomial = all(ACTIVATIONS[layer.activation].polynomial_degree is not None
                            for f in functions if f.candidate is None for layer in f.layers)
    return layers_polynomial and all(E.is_arithmetic(e) for e in expressions)


def choose_verifier(spec: CheckedSpec, functions, requested: str | None) -> tuple[str, str]:
    span = None if requested else spec.spans.get("option:verifier")
    requested = requested or spec.synthesis.verifier
    if requested:
        if requested not in registry.BACKENDS:
            raise CompileError(f"unknown verifier `{requested}`; the verifiers are: "
                               + ", ".join(registry.names()), span)
        if not registry.is_installed(requested):
            available = [n for n in registry.names() if registry.is_installed(n)]
            raise CompileError(f"verifier `{requested}` is not available here; available: "
                               + ", ".join(available), span)
        return requested, "named in the spec or on the command line"
    if is_polynomial_problem(spec, functions):
        return "z3", "the problem is polynomial arithmetic, which Z3 decides completely"
    for info in sorted(registry.BACKENDS.values(), key=lambda b: b.rank):
        if info.transcendental and registry.is_installed(info.name):
            return info.name, f"the problem has transcendental functions; {info.summary}"
    raise CompileError("no installed verifier handles transcendental functions")


# ---- readable forms ---------------------------------------------------------------------
def plan_text(plan: Plan) -> str:
    spec = plan.spec
    lines = [f"spec {spec.name}: {spec.property.form} ({spec.property.text})",
             f"certificate: {plan.certificate.title}"]
    for function in plan.functions:
        shape = f"candidate {function.candidate}" if function.candidate else \
            "network " + ", ".join(map(str, function.layers))
        origin = f", {function.name}(0) = 0 by construction" if function.zero_at_origin else ""
        lines.append(f"  learn {function.name}: {shape}{origin}")
    lines.append("conditions (each proved by showing its negation unsatisfiable):")
    for condition in plan.conditions:
        lines.append(f"  [{condition.name}] {condition.text}")
        lines.append(f"      x ranges over {_set_words(spec, condition.region)}; "
                     f"trained on samples of {condition.samples}")
    lines.append("dynamics (" + spec.time.value + " time):")
    mark = "'" if spec.time.value == "continuous" else ""
    for state, f in zip(spec.states, spec.dynamics):
        left = f"{state}{mark}" if mark else f"next({state})"
        lines.append(f"  {left} = {f}")
    lines.append("samples: " + ", ".join(f"{role} {n}" for role, n in plan.samples.items()))
    lines.append(f"verifier: {plan.verifier} ({plan.verifier_reason})")
    options = plan.options
    lines.append(f"loop: at most {options.max_iters} iterations, {options.timeout:g} s, "
                 f"seed {options.seed}")
    lines.append(f"guarantee: {plan.certificate.guarantee()}")
    return "\n".join(lines)


def loss_text(plan: Plan) -> str:
    """The learner's loss terms: one per condition, summed."""
    margin = plan.options.margin
    lines = ["loss = sum of one term per condition (mean over that condition's samples):"]
    for condition in plan.conditions:
        claim = condition.claim
        if claim.relation in ("<", "<="):
            violation = f"({claim.left}) - ({claim.right})"
        else:
            violation = f"({claim.right}) - ({claim.left})"
        shown_margin = f"{margin:g}*|x|^2" if condition.scaled_margin else f"{margin:g}"
        where = f"samples of {condition.samples}"
        if condition.exclude_origin:
            where += ", x != 0"
        if condition.guard != L.TRUE:
            where += f", where {condition.guard} (within a band)"
        lines.append(f"  [{condition.name}] relu({violation} + {shown_margin}) over {where}")
    lines.append("  ($V is the network's value, $dV its "
                 + ("one-step difference)" if plan.certificate.discrete
                    else "derivative along the flow by automatic differentiation)"))
    return "\n".join(lines)


def _set_words(spec: CheckedSpec, region: S.SetExpr) -> str:
    if region is spec.domain:
        return f"the domain D = {region.text()}"
    return region.text()


def symbolic_queries(plan: Plan) -> dict[str, str]:
    """The verifier queries as SMT-LIB 2, with each learned function still unknown."""
    functions = {}
    for function in plan.functions:
        functions[function.name] = None
        functions[f"d{function.name}"] = None
    result = {}
    for condition in plan.conditions:
        comments = [f"{plan.spec.name}: condition {condition.name}: {condition.text}",
                    "unsat means the condition holds; d" + plan.functions[0].name +
                    (" is the one-step difference" if plan.certificate.discrete
                     else " is the derivative along the flow")]
        result[condition.name] = query_text(condition.query(plan.states), plan.states,
                                            functions, comments)
    return result
