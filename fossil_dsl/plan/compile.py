"""Checked spec -> certificate plan: the functions to learn, the conditions to prove (with
the set each ranges over), what to sample, and which verifier decides the queries."""
from __future__ import annotations

from dataclasses import dataclass, replace
from fractions import Fraction
from types import MappingProxyType
from typing import Mapping

from fossil_dsl.plan.certificates import (Certificate, Condition, LearnedFunction, Level,
                                     certificate_for)
from fossil_dsl.plan.certificates.base import UnsupportedProperty
from fossil_dsl.diagnostics import Diagnostic, FslError, Span, error
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.activations import ACTIVATIONS
from fossil_dsl.ir.spec import CheckedSpec, Layer, TimeDomain
from fossil_dsl.kernel.obligations import BALL_ROOM
from fossil_dsl.solvers import registry

DEFAULT_SAMPLES = 1000


class CompileError(FslError):
    """A checked spec that cannot be compiled; `span` points at the spec element."""

    def __init__(self, message: str, span: Span | None = None):
        super().__init__(message)
        self.span = span

    def diagnostic(self) -> Diagnostic:
        return error(str(self), self.span)


ORIGIN_RADIUS = Fraction(1, 100)  # the reference tool's annulus (its "torus" domains)
MIN_ORIGIN_RADIUS = Fraction(1, 10 ** 6)


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
    control_weight: float = 0.1  # of the control loss (f(x) pointing to the goal or origin)
    learn_only: bool = False  # train, measure violations on fresh samples, prove nothing
    delta: float | None = None  # precision of a delta-decision verifier (its default if None)
    largest_region: bool = False  # enlarge β to the largest level the kernel proves


@dataclass(frozen=True)
class ControllerPlan:
    """u = k(x): a network from the states to the inputs, substituted into the dynamics."""

    inputs: tuple[str, ...]
    layers: tuple[Layer, ...]
    zero_at_origin: bool  # k(0) = 0, so the closed loop keeps the equilibrium
    # the set the closed loop is steered towards (the property's goal), else the origin
    target: S.SetExpr | None = None


@dataclass(frozen=True)
class Plan:
    spec: CheckedSpec
    certificate: Certificate
    functions: tuple[LearnedFunction, ...]
    conditions: tuple[Condition, ...]
    levels: tuple[Level, ...]
    controller: ControllerPlan | None
    verifier: str
    verifier_reason: str
    samples: Mapping[str, int]  # condition name -> number of training samples
    options: RunOptions
    # conditions that exclude the origin exclude the ball of this radius (a delta-decision
    # verifier cannot refute a closed set that touches the origin, where V = dV = 0)
    origin_radius: Fraction = Fraction(0)
    fallback: str | None = None  # run alongside the verifier where it does not answer at once

    @property
    def states(self) -> tuple[str, ...]:
        return self.spec.states

    def query(self, condition: Condition) -> L.Formula:
        """The condition's query (satisfiable exactly when it fails), before the learned
        functions are substituted."""
        return condition.query(self.states, self.origin_radius)

    @property
    def excludes_a_ball(self) -> bool:
        return self.origin_radius > 0 and any(c.exclude_origin for c in self.conditions)


def compile_spec(spec: CheckedSpec, certificate: type[Certificate] | None = None,
                 **overrides) -> Plan:
    """The plan for a checked spec; `overrides` (verifier, seed, max_iters, timeout, ...)
    take precedence over the synthesis block, as command-line options do. `certificate`
    replaces the registered rule for the spec's property (a user-defined one)."""
    rule = _certificate(spec, certificate)
    functions = rule.functions()
    for function in functions:
        _check_candidate(spec, function)
    conditions, levels = rule.chosen_conditions()
    controller = _controller(spec, rule)
    requested = overrides.pop("verifier", None)
    verifier, reason = choose_verifier(spec, functions, controller, requested)
    options = _options(spec, overrides)
    samples = {c.name: _sample_count(spec, c.region) for c in conditions}
    radius = origin_radius(spec) if registry.BACKENDS[verifier].delta_decision else Fraction(0)
    fallback = None if requested or spec.synthesis.verifier else _fallback(verifier)
    if fallback:
        reason += f"; where it does not answer at once, {fallback} alongside"
    return Plan(spec, rule, functions, conditions, tuple(levels), controller,
                verifier, reason, MappingProxyType(samples), options, radius, fallback)


def default_synthesis(plan: Plan) -> bool:
    """No template, candidate or controller chosen by the user (at most the default
    linear controller), no torch dynamics, and not learn-only: where the engine may put
    functions of its own choosing (a program's, a conserved quantity) in the templates'
    place."""
    spec = plan.spec
    linear_controller = plan.controller is None or (
        spec.synthesis.controller is None
        and all(layer.activation == "linear" for layer in plan.controller.layers))
    return (linear_controller and spec.torch_dynamics is None
            and spec.synthesis.certificate is None and spec.synthesis.certificate2 is None
            and spec.synthesis.candidate is None and not plan.options.learn_only)


def with_conditions(plan: Plan, conditions, levels=None) -> Plan:
    """The plan with other conditions (those of a variant of the kernel's rule), their
    sample counts, and the levels that go with them."""
    samples = {c.name: _sample_count(plan.spec, c.region) for c in conditions}
    return replace(plan, conditions=tuple(conditions), samples=MappingProxyType(samples),
                   levels=plan.levels if levels is None else tuple(levels))


def variant_plan(plan: Plan) -> Plan | None:
    """The plan with the conditions of the kernel rule's variant, if it has one (and is
    not already on it)."""
    conditions = plan.certificate.variant_conditions()
    return None if conditions is None or tuple(conditions) == plan.conditions else \
        with_conditions(plan, conditions, plan.certificate.variant_levels())


def richer_plan(plan: Plan) -> Plan | None:
    """The plan with each function of the compiler's quadratic template (`square(w)`)
    given a quartic one (`poly4(w)`), for a second learning run where the first gave up:
    no quadratic V reaches a goal round an equilibrium off the origin when I is far on
    one side and D's boundary near on the other (probe70/at17). None where the user chose
    the templates, or none is quadratic."""
    if not default_synthesis(plan):
        return None
    functions = tuple(replace(f, layers=tuple(Layer("poly4", layer.width)
                                              if layer.activation == "square" else layer
                                              for layer in f.layers))
                      for f in plan.functions)
    return None if functions == plan.functions else replace(plan, functions=functions)


def origin_radius(spec: CheckedSpec) -> Fraction:
    """The ball a delta-decision verifier leaves out round the origin: ORIGIN_RADIUS, or
    a power of ten small enough that ten times it fits in the domain's box (the kernel
    proves that the larger ball lies in D)."""
    box = spec.domain.bounding_box()
    room = min(min(-low, high) for low, high in zip(*box)) if box else 0.0
    radius = ORIGIN_RADIUS
    while BALL_ROOM * radius > room and radius > MIN_ORIGIN_RADIUS:
        radius /= 10
    return radius


def _fallback(verifier: str) -> str | None:
    """The interval verifier after Z3 (when no verifier is named)."""
    return "interval" if verifier == "z3" and registry.is_installed("interval") else None


def _certificate(spec: CheckedSpec, given: type[Certificate] | None) -> Certificate:
    try:
        rule = given(spec) if given is not None else certificate_for(spec)
    except UnsupportedProperty as exc:
        raise CompileError(str(exc), spec.spans.get("prove")) from None
    if spec.time is TimeDomain.DISCRETE and not rule.discrete_time:
        raise CompileError(
            f"{spec.property.form} in discrete time is not supported: the {rule.title} "
            "is proved sound for continuous time only (docs/certificates.md says why)",
            spec.spans.get("dynamics"))
    return rule


def _controller(spec: CheckedSpec, rule: Certificate) -> ControllerPlan | None:
    if not spec.inputs:
        return None
    layers = spec.synthesis.controller or (Layer("linear", len(spec.inputs)),)
    return ControllerPlan(spec.inputs, layers, rule.keeps_equilibrium, rule.control_target())


def _sample_count(spec: CheckedSpec, region: S.SetExpr) -> int:
    """`samples: NAME N` counts for the set named NAME, and for its boundary."""
    counts = spec.synthesis.samples
    while isinstance(region, S.Boundary):
        region = region.inner
    if region is spec.domain:
        return counts.count("domain", DEFAULT_SAMPLES)
    name = region.name if isinstance(region, S.Named) else None
    return counts.count(name, DEFAULT_SAMPLES) if name else \
        (counts.default or DEFAULT_SAMPLES)


def _check_candidate(spec: CheckedSpec, function: LearnedFunction) -> None:
    """A given function must vanish at the origin where the certificate needs it to
    (learned networks do by construction)."""
    if function.candidate is None or not function.zero_at_origin:
        return
    try:
        at_origin = traversal.substitute(function.candidate, {s: E.ZERO for s in spec.states})
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
    if given.delta is not None:
        options = replace(options, delta=float(given.delta))
    if given.region == "largest":
        options = replace(options, largest_region=True)
    unknown = set(overrides) - set(RunOptions.__dataclass_fields__)
    if unknown:
        raise TypeError(f"unknown options: {sorted(unknown)}")
    return replace(options, **{k: v for k, v in overrides.items() if v is not None})


def is_polynomial_problem(spec: CheckedSpec, functions, controller=None) -> bool:
    expressions = list(spec.dynamics) + [f.candidate for f in functions if f.candidate]
    sets = [spec.domain, *spec.sets.values()]
    formulas = [s.contains_formula(spec.states) for s in sets]
    comparisons = [c for f in formulas for c in L.comparisons(f)]
    expressions += [side for c in comparisons for side in (c.left, c.right)]
    layers = [layer for f in functions if f.candidate is None for layer in f.layers]
    layers += list(controller.layers) if controller else []
    layers_polynomial = all(ACTIVATIONS[layer.activation].polynomial_degree is not None
                            for layer in layers)
    return layers_polynomial and all(traversal.is_arithmetic(e) for e in expressions)


def choose_verifier(spec: CheckedSpec, functions, controller,
                    requested: str | None) -> tuple[str, str]:
    span = None if requested else spec.spans.get("option:verifier")
    requested = requested or spec.synthesis.verifier
    if requested:
        if requested not in registry.BACKENDS:
            raise CompileError(f"unknown verifier `{requested}`; the verifiers are: "
                               + ", ".join(registry.names()), span)
        if not registry.is_installed(requested):
            available = [n for n in registry.names() if registry.is_installed(n)]
            raise CompileError(f"verifier `{requested}` is not available here (it needs the "
                               f"Python package `{registry.BACKENDS[requested].requires}`); "
                               "available: " + ", ".join(available), span)
        return requested, "named in the spec or on the command line"
    if is_polynomial_problem(spec, functions, controller):
        return "z3", "the problem is polynomial arithmetic, which Z3 decides completely"
    missing = []
    for info in sorted(registry.BACKENDS.values(), key=lambda b: b.rank):
        if not info.transcendental:
            continue
        if registry.is_installed(info.name):
            unavailable = f" ({', '.join(missing)} not installed)" if missing else ""
            return info.name, (f"the problem has transcendental functions; {info.summary}"
                               f"{unavailable}")
        missing.append(info.name)
    raise CompileError("no installed verifier handles transcendental functions")
