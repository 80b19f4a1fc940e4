"""The synthesis block: one reader per key; unknown keys get the nearest valid one."""
from __future__ import annotations

from dataclasses import replace
from fractions import Fraction
from types import MappingProxyType
from typing import Callable

from fossil_dsl.check.context import CheckContext
from fossil_dsl.check.expressions import ExpressionChecker
from fossil_dsl.diagnostics import Span, did_you_mean
from fossil_dsl.ir import expr as E
from fossil_dsl.ir.activations import ACTIVATIONS, odd_without_biases, poly_neurons
from fossil_dsl.ir.spec import Layer, SampleCounts, SynthesisOptions
from fossil_dsl.solvers import registry
from fossil_dsl.syntax import ast

MAX_WIDTH = 10_000


class Invalid(Exception):
    """An option value is wrong; already reported."""


class OptionReader:
    def __init__(self, context: CheckContext, set_names):
        self.context = context
        self.set_names = set(set_names)
        self.numbers = ExpressionChecker(context, {"constant"}, "parameter")
        self.candidates = ExpressionChecker(context, {"state", "constant"}, "candidate")

    def read(self, decl: ast.SynthesisDecl | None) -> tuple[SynthesisOptions, dict, set]:
        """The options, the span of each key given, and the keys given."""
        values, spans = {}, {}
        for option in (decl.options if decl else ()):
            key = option.key.text
            if key in spans:
                first = spans[key]
                self.context.error(f"synthesis key `{key}` is given twice (first at "
                                   f"{first.line}:{first.column})", option.key.span)
                continue
            spans[key] = option.key.span
            reader = READERS.get(key)
            if reader is None:
                self.context.error(f"unknown synthesis key `{key}`{did_you_mean(key, READERS)}"
                                   "; the keys are: " + ", ".join(READERS), option.key.span)
                continue
            try:
                values[key] = reader(self, option)
            except Invalid:
                pass
        return replace(SynthesisOptions(), **values), spans, set(values)

    # ---- item readers ----
    def single(self, option: ast.Option):
        if len(option.items) != 1:
            self.fail(f"`{option.key.text}` takes one value, not {len(option.items)}",
                      option.span)
        item = option.items[0]
        if isinstance(item, ast.NamedCount):
            self.fail(f"`{option.key.text}` takes a single value", item.span)
        return item

    def number(self, option: ast.Option) -> tuple[Fraction, Span]:
        item = self.single(option)
        value = self.numbers.convert(item)
        if not isinstance(value, E.Num):
            self.fail(f"`{option.key.text}` must be a number", item.span)
        return value.value, item.span

    def fail(self, message: str, span: Span):
        self.context.error(message, span)
        raise Invalid

    def layers(self, option: ast.Option) -> tuple[Layer, ...]:
        return tuple(self.layer(option.key.text, item) for item in option.items)

    def layer(self, key: str, item) -> Layer:
        if not isinstance(item, ast.Call):
            self.fail(f"`{key}` lists layers as ACTIVATION(WIDTH), e.g. `square(6)`", item.span)
        name = item.func.text
        if name not in ACTIVATIONS:
            self.fail(f"unknown activation `{name}`{did_you_mean(name, ACTIVATIONS)}; the "
                      "activations are: " + ", ".join(ACTIVATIONS), item.func.span)
        if len(item.args) != 1:
            self.fail(f"`{name}(WIDTH)` takes one width", item.span)
        width = self.numbers.convert(item.args[0])
        if not (isinstance(width, E.Num) and width.value.denominator == 1
                and 0 < width.value <= MAX_WIDTH):
            self.fail(f"a layer width must be a whole number from 1 to {MAX_WIDTH}",
                      item.args[0].span)
        return Layer(name, int(width.value))

    def candidate(self, option: ast.Option) -> E.Expr:
        return self.candidates.convert(self.single(option))

    def verifier(self, option: ast.Option) -> str:
        item = self.single(option)
        names = registry.names()
        if not isinstance(item, ast.Name) or item.name not in names:
            word = item.name if isinstance(item, ast.Name) else "this"
            self.fail(f"unknown verifier `{word}`{did_you_mean(word, names)}; the verifiers "
                      "are: " + ", ".join(names), item.span)
        return item.name

    def region(self, option: ast.Option) -> str:
        item = self.single(option)
        if not isinstance(item, ast.Name) or item.name != "largest":
            self.fail("`region` takes `largest` (the largest region of attraction the "
                      "kernel proves for the learned V)", item.span)
        return item.name

    def samples(self, option: ast.Option) -> SampleCounts:
        if len(option.items) == 1 and not isinstance(option.items[0], ast.NamedCount):
            return SampleCounts(default=self.count(option.items[0]))
        per_set, valid = {}, True
        for item in option.items:
            try:
                per_set.update(self.named_count(item))
            except Invalid:
                valid = False
        if not valid:
            raise Invalid
        return SampleCounts(per_set=MappingProxyType(per_set))

    def named_count(self, item) -> dict[str, int]:
        if not isinstance(item, ast.NamedCount):
            self.fail("write `samples: N` or `samples: SET N, ...`", item.span)
        name = item.name.text
        if name != "domain" and name not in self.set_names:
            self.fail(f"`{name}` is not a declared set"
                      f"{did_you_mean(name, self.set_names | {'domain'})}", item.name.span)
        return {name: self.count(item.count)}

    def count(self, item) -> int:
        value = self.numbers.convert(item)
        if not (isinstance(value, E.Num) and value.value.denominator == 1 and value.value > 0):
            self.fail("a sample count must be a positive whole number", item.span)
        return int(value.value)

    def whole(self, option: ast.Option, minimum: int) -> int:
        value, span = self.number(option)
        if value.denominator != 1 or value < minimum:
            self.fail(f"`{option.key.text}` must be a whole number of at least {minimum}", span)
        return int(value)

    def positive(self, option: ast.Option, allow_zero: bool = False) -> Fraction:
        value, span = self.number(option)
        if value < 0 or (value == 0 and not allow_zero):
            bound = "at least 0" if allow_zero else "positive"
            self.fail(f"`{option.key.text}` must be {bound}", span)
        return value


READERS: dict[str, Callable[[OptionReader, ast.Option], object]] = {
    "certificate": OptionReader.layers,
    "certificate2": OptionReader.layers,
    "candidate": OptionReader.candidate,
    "candidate2": OptionReader.candidate,
    "controller": OptionReader.layers,
    "verifier": OptionReader.verifier,
    "samples": OptionReader.samples,
    "max_iters": lambda reader, option: reader.whole(option, 1),
    "seed": lambda reader, option: reader.whole(option, 0),
    "timeout": OptionReader.positive,
    "learning_rate": OptionReader.positive,
    "margin": lambda reader, option: reader.positive(option, allow_zero=True),
    "delta": OptionReader.positive,
    "region": OptionReader.region,
}


def template_findings(options: SynthesisOptions, given: set, stable_type: bool,
                      continuous: bool, states: int) -> list[tuple[str, str, str]]:
    """(level, message, key) for templates that can never give a certificate (findings: an
    odd V for a stable-type form; relu in a continuous-time certificate, whose kinks leave
    dV/dt undefined on a surface through D that no proof can avoid), or hardly ever
    (a warning: a single polyN layer with fewer quadratic neurons than states)."""
    findings = []
    layers = options.certificate if "certificate" in given else None
    if stable_type and layers and len(layers) == 1 and layers[0].activation.startswith("poly"):
        degree, width = ACTIVATIONS[layers[0].activation].polynomial_degree, layers[0].width
        squares = len(poly_neurons(width, degree, 2))
        if squares < states:
            findings.append(("warning", f"`{layers[0].activation}({width})` splits its neurons "
                           f"into {degree} chunks of powers 1 to {degree}: only {squares} "
                           f"square a linear form, so V's quadratic part is singular in "
                           f"{states} states and V hardly ever decreases near the origin; use "
                           f"`{layers[0].activation}({degree * states})` or wider",
                           "certificate"))
    if "certificate" in given and "candidate" not in given and stable_type \
            and odd_without_biases(options.certificate):
        findings.append(("error", "these layers make V an odd function (V(-x) = -V(x)), "
                       "never positive on both sides of the origin as a Lyapunov function "
                       "must be; end with an even layer, e.g. `tanh(8), square(8)`",
                       "certificate"))
    for key in ("certificate", "certificate2"):
        layers = getattr(options, key)
        if continuous and key in given and layers \
                and any(layer.activation == "relu" for layer in layers):
            findings.append(("error", "`relu` has a kink where its input is 0, so dV/dt "
                           "(dB/dt) is undefined there and the flow condition cannot be "
                           "proved; use `softplus`, its smooth counterpart (relu suits maps and "
                           "controllers)", key))
    return findings
