"""Syntax tree -> checked spec. Runs every check of the reference's "Checks" section and
collects all findings; the spec is produced only when there is no error."""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import PurePath
from types import MappingProxyType
from typing import Sequence

from fossil_dsl.check.context import CheckContext
from fossil_dsl.check.expressions import ExpressionChecker
from fossil_dsl.check.options import OptionReader, template_findings
from fossil_dsl.check.properties import (LARGEST_REGION, PropertyChecker, PropertyForm,
                                         formula_set_names)
from fossil_dsl.check.relations import RelationProver, Subject, check_equilibrium
from fossil_dsl.check.sets import SetChecker, set_reference_names
from fossil_dsl.diagnostics import Diagnostic, Span, article, has_errors
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.spec import CheckedSpec, Property, TimeDomain
from fossil_dsl.solvers.z3_backend import Z3Backend
from fossil_dsl.syntax import ast

_SINGLE = {ast.SpecDecl: "spec", ast.StateDecl: "state", ast.InputDecl: "input",
           ast.DynamicsDecl: "dynamics", ast.DomainDecl: "domain", ast.ProveDecl: "prove",
           ast.SynthesisDecl: "synthesis"}
_REQUIRED = ("state", "dynamics", "domain", "prove")
_START = Span(1, 1)


@dataclass(frozen=True)
class CheckReport:
    spec: CheckedSpec | None
    diagnostics: tuple[Diagnostic, ...]

    @property
    def ok(self) -> bool:
        return self.spec is not None


def check(tree: ast.SpecFile) -> CheckReport:
    checker = Checker(tree)
    spec = checker.run()
    diagnostics = sorted(checker.context.diagnostics,
                         key=lambda d: (d.span.line, d.span.column) if d.span else (0, 0))
    return CheckReport(spec, tuple(diagnostics))


class Checker:
    def __init__(self, tree: ast.SpecFile):
        self.tree = tree
        self.context = CheckContext()
        self.singles: dict[str, object] = {}
        self.constant_decls: list[ast.ConstDef] = []
        self.set_decls: dict[str, ast.SetDecl] = {}
        self.spans: dict[str, Span] = {}
        self.domain: S.SetExpr | None = None

    # ---- statements and names ----
    def run(self) -> CheckedSpec | None:
        self.collect_statements()
        self.declare_names()
        self.fold_constants()
        time, dynamics, equation_spans = self.check_dynamics()
        sets = SetChecker(self.context, self.set_decls)
        domain = self.domain = self.check_domain(sets)
        named = {name: sets.named(name, self.set_decls[name].name.span)
                 for name in self.set_decls}
        checked = self.check_property(sets)
        options, option_spans, given = OptionReader(self.context, self.set_decls).read(
            self.singles.get("synthesis"))
        self.spans.update({f"option:{key}": span for key, span in option_spans.items()})
        if checked is None or has_errors(self.context.diagnostics) or domain is None:
            self.warn_unused()
            return None
        prop, form = checked
        options = self.check_option_use(options, given, form, time)
        if options.region == "largest" and form.name == "stability":
            form = LARGEST_REGION
            prop = replace(prop, form=form.name, certificate=form.certificate)
        self.prove_facts(form, prop, domain, dynamics, equation_spans, time)
        self.warn_unused()
        if has_errors(self.context.diagnostics):
            return None
        return self.build(time, dynamics, domain, named, prop, options)

    def collect_statements(self) -> None:
        for statement in self.tree.statements:
            if isinstance(statement, ast.ConstDecl):
                self.constant_decls.extend(statement.definitions)
            elif isinstance(statement, ast.SetDecl):
                self.set_decls.setdefault(statement.name.text, statement)
            else:
                self.single(statement)
        for keyword in _REQUIRED:
            if keyword not in self.singles:
                self.context.error(f"the spec has no `{keyword}` statement "
                                   f"({_REQUIRED_HELP[keyword]})", _START)

    def single(self, statement) -> None:
        keyword = _SINGLE[type(statement)]
        if keyword in self.singles:
            first = self.singles[keyword].span
            self.context.error(f"a second `{keyword}` statement: a spec has one (the first "
                               f"is at {first.line}:{first.column})", statement.span)
            return
        self.singles[keyword] = statement
        self.spans[keyword] = statement.span

    def declare_names(self) -> None:
        for statement in self.tree.statements:
            if isinstance(statement, ast.StateDecl) and statement is self.singles.get("state"):
                self._declare_all("state", statement.names, self.context.states)
            elif isinstance(statement, ast.InputDecl) and statement is self.singles.get("input"):
                self._declare_all("input", statement.names, self.context.inputs)
            elif isinstance(statement, ast.ConstDecl):
                for definition in statement.definitions:
                    self.context.declare("constant", definition.name)
            elif isinstance(statement, ast.SetDecl):
                self.context.declare("set", statement.name)

    def _declare_all(self, kind: str, names: Sequence[ast.Ident], into: list[str]) -> None:
        for ident in names:
            if self.context.declare(kind, ident):
                into.append(ident.text)
                self.spans[f"{kind}:{ident.text}"] = ident.span

    def fold_constants(self) -> None:
        """Constants in file order; each may use only those before it."""
        positions = {d.name.text: d.name.span for d in self.constant_decls}
        for definition in self.constant_decls:
            name = definition.name.text
            if self.context.names[name].ident is not definition.name:
                continue  # a duplicate, already reported
            reader = ExpressionChecker(self.context, {"constant"}, "constant")
            later = self._later_constant(definition.value, positions, definition.name.span)
            if later:
                self.context.error(f"constant `{name}` uses `{later}`, which is declared "
                                   "later; a constant may only use earlier constants",
                                   definition.value.span)
                self.context.constants[name] = E.ZERO
                continue
            self.context.constants[name] = reader.convert(definition.value)
            self.spans[f"constant:{name}"] = definition.name.span

    def _later_constant(self, value: ast.Expr, positions, here: Span) -> str | None:
        for node in _expression_names(value):
            span = positions.get(node.name)
            if node.name not in self.context.constants and span is not None:
                if (span.line, span.column) >= (here.line, here.column):
                    return node.name
        return None

    # ---- dynamics ----
    def check_dynamics(self):
        decl = self.singles.get("dynamics")
        if decl is None:
            return TimeDomain.CONTINUOUS, (), ()
        time = TimeDomain(decl.time)
        reader = ExpressionChecker(self.context, {"state", "input", "constant"}, "dynamics")
        equations: dict[str, ast.Equation] = {}
        for equation in decl.equations:
            self._equation_form(equation, time)
            name = equation.state.text
            if self.context.kind_of(name) != "state":
                self._not_a_state(equation.state)
            elif name in equations:
                first = equations[name].span
                self.context.error(f"state `{name}` has two equations (the first is at "
                                   f"{first.line}:{first.column})", equation.span)
            else:
                equations[name] = equation
        for name in self.context.states:
            if name not in equations:
                self.context.error(f"state `{name}` has no equation in the dynamics",
                                   self.spans[f"state:{name}"])
        ordered = [equations[n] for n in self.context.states if n in equations]
        values = tuple(reader.convert(eq.value) for eq in ordered)
        self._warn_unused_inputs(values)
        return time, values, tuple(eq.span for eq in ordered)

    def _equation_form(self, equation: ast.Equation, time: TimeDomain) -> None:
        name = equation.state.text
        if equation.form == "derivative" and time is TimeDomain.DISCRETE:
            self.context.error(f"`{name}'` is a derivative, but this is a discrete block: "
                               f"write `next({name}) = ...`", equation.state.span)
        elif equation.form == "next" and time is TimeDomain.CONTINUOUS:
            self.context.error(f"`next({name})` belongs in a discrete block; in a "
                               f"continuous block write `{name}' = ...`", equation.span)
        elif equation.form == "plain":
            wanted = f"{name}' = ..." if time is TimeDomain.CONTINUOUS else f"next({name}) = ..."
            self.context.error(f"write the equation as `{wanted}` in a {time.value} block",
                               equation.state.span)

    def _not_a_state(self, ident: ast.Ident) -> None:
        kind = self.context.kind_of(ident.text)
        what = article(kind) if kind else "not declared"
        self.context.error(f"`{ident.text}` is {what}; equations are for states "
                           f"({', '.join(self.context.states) or 'none declared'})",
                           ident.span)

    def _warn_unused_inputs(self, values) -> None:
        used = set().union(*(E.free_vars(v) for v in values)) if values else set()
        for name in self.context.inputs:
            if name not in used:
                self.context.warning(f"input `{name}` does not appear in the dynamics",
                                     self.spans[f"input:{name}"])

    # ---- sets and property ----
    def check_domain(self, sets: SetChecker) -> S.SetExpr | None:
        decl = self.singles.get("domain")
        return sets.build_domain(decl.value) if decl else None

    def check_property(self, sets: SetChecker) -> tuple[Property, PropertyForm] | None:
        decl = self.singles.get("prove")
        if decl is not None:
            self.context.used.update(formula_set_names(decl.formula))
            self.context.used.update(set_reference_names(decl.initial))
        if decl is None or sets.domain is None:
            return None
        return PropertyChecker(self.context, sets).check(decl)

    def check_option_use(self, options, given: set, form: PropertyForm, time):
        if "max_iters" not in given:
            options = replace(options, max_iters=form.max_iters)
        if "controller" in given and not self.context.inputs:
            self.context.error("`controller` is given, but the spec declares no `input`",
                               self.spans["option:controller"])
        for key in ("certificate2", "candidate2"):
            if key in given and form.functions < 2:
                self.context.warning(f"`{key}` is ignored: {form.name} uses one function "
                                     "(only SWA and RAR use two)", self.spans[f"option:{key}"])
        if "region" in given and form.name not in ("region of attraction", "stability"):
            self.context.error("`region: largest` enlarges a region of attraction: it needs "
                               f"`prove stable` or `prove from init: stable`, not {form.name}",
                               self.spans["option:region"])
        if "candidate" in given and "certificate" in given:
            self.context.warning("`certificate` is ignored: `candidate` gives the function "
                                 "to verify", self.spans["option:certificate"])
        for level, message, key in template_findings(
                options, given, form.stable_type, time is TimeDomain.CONTINUOUS,
                len(self.context.states)):
            getattr(self.context, level)(message, self.spans[f"option:{key}"])
        return options

    def prove_facts(self, form, prop, domain, dynamics, equation_spans, time) -> None:
        prover = RelationProver(self.context, self.context.states, Z3Backend())
        domain_subject = Subject(domain, "the domain", self.spans.get("domain"))
        prover.nonempty(domain_subject)
        prover.bounded(domain_subject)
        if form.stable_type:
            prover.origin_interior(domain_subject)
        for value in {id(v): v for v in prop.roles.values()}.values():
            if isinstance(value, S.Named):  # the sets the property names must not be empty
                prover.nonempty(self.subject(value))
        subjects = {role: self.subject(value, role) for role, value in prop.roles.items()}
        for kind, first, second in form.relations:
            prover.prove(kind, subjects[first], subjects[second])
        if self.context.inputs:
            for role in form.origin_roles:
                prover.contains_origin(subjects[role])
        if form.stable_type:
            check_equilibrium(self.context, self.context.states, self.context.inputs,
                              dynamics, equation_spans, time is TimeDomain.DISCRETE)

    def subject(self, value: S.SetExpr, role: str = "") -> Subject:
        """A set named for messages: by its name, or by its role in the property."""
        if isinstance(value, S.Named):
            return Subject(value, f"`{value.name}`", self.context.names[value.name].ident.span)
        if value is self.domain:
            return Subject(value, "the domain", self.spans.get("domain"))
        derived = _DERIVED.get((role, type(value)))
        if derived and isinstance(_given(value), S.Named):
            name = _given(value).name
            return Subject(value, derived.format(name), self.context.names[name].ident.span)
        return Subject(value, f"the {role or 'set'} {value.text()}", self.spans.get("prove"))

    def warn_unused(self) -> None:
        for name, declared in self.context.names.items():
            if name in self.context.used or declared.kind not in ("constant", "set"):
                continue
            what = "the property never uses it" if declared.kind == "set" else "it is never used"
            self.context.warning(f"{declared.kind} `{name}` is declared but {what}",
                                 declared.ident.span)

    def build(self, time, dynamics, domain, named, prop, options) -> CheckedSpec:
        spec_decl = self.singles.get("spec")
        name = spec_decl.name.text if spec_decl else PurePath(self.tree.path).stem
        return CheckedSpec(
            name=name, path=self.tree.path, states=tuple(self.context.states),
            inputs=tuple(self.context.inputs),
            constants=MappingProxyType(dict(self.context.constants)), time=time,
            dynamics=dynamics, domain=domain, sets=MappingProxyType(named),
            property=prop, synthesis=options, spans=MappingProxyType(self.spans))


# How a role's set reads when the property derived it from a declared set.
_DERIVED = {
    ("safe", S.Complement): "the safe set (the domain minus `{}`)",
    ("unsafe", S.Complement): "the unsafe set (the domain minus `{}`)",
    ("safe", S.Intersection): "the safe set `{}` (within the domain)",
}


def _given(value: S.SetExpr) -> S.SetExpr:
    return value.operand if isinstance(value, S.Complement) else value.left


_REQUIRED_HELP = {
    "state": "declare the state variables, e.g. `state x0, x1`",
    "dynamics": "e.g. `dynamics continuous { x0' = ... }`",
    "domain": "e.g. `domain box([-1, -1], [1, 1])`",
    "prove": "the property, e.g. `prove stable`",
}


def _expression_names(node: ast.Expr):
    stack = [node]
    while stack:
        item = stack.pop()
        if isinstance(item, ast.Name):
            yield item
        elif isinstance(item, ast.Unary):
            stack.append(item.operand)
        elif isinstance(item, ast.Binary):
            stack.extend((item.left, item.right))
        elif isinstance(item, ast.Call):
            stack.extend(item.args)
