"""Specs built in Python rather than written in a .fsl file.

The dynamics come as sympy expressions (or numbers), optionally with a torch function
of the same field for fast learning; sets come as .fsl set expressions or as
`BespokeSet`s (a formula for the solvers and a sampler of their own). The spec is
written out as .fsl text (`spec_text`) and goes through the same parser and checker as
a file, so it gets every check and every diagnostic a file gets; the bespoke sets and
the torch field are then put in place in the checked spec.

Nothing here evaluates a string: set and property texts are parsed by the grammar, and
sympy expressions are converted node by node.
"""
from __future__ import annotations

import dataclasses
from fractions import Fraction
from typing import Callable, Mapping, Sequence

import sympy

from fossil_dsl.check.checker import check as check_tree
from fossil_dsl.check.context import CheckContext
from fossil_dsl.check.relations import RelationProver
from fossil_dsl.diagnostics import FslError, Source, SpecError, has_errors
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.expr import to_text
from fossil_dsl.ir.expr import Num
from fossil_dsl.ir.sets import Bespoke, Box, Intersection, Named, Semialgebraic, SetExpr
from fossil_dsl.ir.spec import CheckedSpec
from fossil_dsl.ir.symbolic import SympyConversionError, from_sympy
from fossil_dsl.engine.evaluate import evaluate, state_env
from fossil_dsl.solvers.z3_backend import Z3Backend
from fossil_dsl.syntax.parser import parse_source
from fossil_dsl.syntax.writer import spec_head

AGREEMENT_POINTS = 256  # where a torch field is compared with the formulas
AGREEMENT_TOLERANCE = 1e-6  # relative


class BuildError(FslError):
    pass


class BespokeSet:
    """A set the language has no shape for. Subclass it and give `constraints` (sympy
    relations over the state symbols, all of which hold in the set: the solvers and the
    checker use these) and `sample` (points of the set, for learning). `box` (low, high)
    bounds the set, for pictures and for sampling its neighbourhood."""

    box: tuple[Sequence[float], Sequence[float]] | None = None

    def constraints(self, x: Sequence[sympy.Symbol]) -> Sequence[sympy.Rel]:
        raise NotImplementedError

    def sample(self, count: int, generator: "torch.Generator") -> "torch.Tensor":
        raise NotImplementedError


SetLike = str | BespokeSet


def build_spec(name: str, states: Sequence, dynamics: Sequence, domain: SetLike,
               prove: str, sets: Mapping[str, SetLike] | None = None,
               inputs: Sequence = (), time: str = "continuous",
               synthesis: Mapping[str, object] | None = None,
               torch_dynamics: Callable | None = None) -> CheckedSpec:
    """A checked spec. `states` and `inputs` are names or sympy symbols; `dynamics` one
    sympy expression per state (dx/dt, or the next state if `time` is "discrete");
    `domain` and `sets` are .fsl set expressions (text) or BespokeSets; `prove` is a
    .fsl property; `synthesis` maps option names to values as a .fsl synthesis block
    would ("certificate": "tanh(5)", "max_iters": 25). `torch_dynamics(points,
    inputs)`, if given, returns the field for learning as a (batch, states) tensor; it
    must agree with `dynamics`. Raises SpecError (with diagnostics) or BuildError."""
    state_names, input_names = _names(states), _names(inputs)
    if isinstance(domain, BespokeSet) and domain.box is None:
        raise BuildError("a bespoke domain needs a `box` (low, high): the learner samples "
                         "the other sets and the domain's boundary within it")
    sets = dict(sets or {})
    bespoke = {key: value for key, value in {"domain": domain, **sets}.items()
               if isinstance(value, BespokeSet)}
    text = spec_text(name, state_names, input_names, dynamics, domain, prove, sets, time,
                     synthesis or {})
    source = Source(f"<python:{name}>", text)
    report = check_tree(parse_source(source))  # a syntax error raises SpecError
    if report.spec is None or has_errors(report.diagnostics):
        raise SpecError([d for d in report.diagnostics if d.is_error], source)
    spec = dataclasses.replace(_with_bespoke_sets(report.spec, bespoke), source=text)
    if torch_dynamics is not None:
        _check_agreement(spec, torch_dynamics)
        spec = dataclasses.replace(spec, torch_dynamics=torch_dynamics)
    return spec


def spec_text(name: str, states: Sequence[str], inputs: Sequence[str], dynamics: Sequence,
              domain: SetLike, prove: str, sets: Mapping[str, SetLike], time: str,
              synthesis: Mapping[str, object]) -> str:
    """The .fsl text of a spec built in Python (a bespoke set appears as its
    constraints)."""
    names = list(states) + list(inputs)
    if len(dynamics) != len(states):
        raise BuildError(f"{len(dynamics)} dynamics expressions for {len(states)} states")
    lines = spec_head(name, states, inputs, time,
                      [to_text(_expr(value, names)) for value in dynamics])
    lines += [f"domain {_set_text(domain, states)}"]
    lines += [f"set {key} = {_set_text(value, states)}" for key, value in sets.items()]
    lines += ["", f"prove {prove}"]
    if synthesis:
        lines += ["", "synthesis {"] + [f"    {k}: {v}" for k, v in synthesis.items()] + ["}"]
    return "\n".join(lines) + "\n"


def _names(symbols: Sequence) -> list[str]:
    return [s.name if isinstance(s, sympy.Symbol) else str(s) for s in symbols]


def _expr(value, names):
    try:
        return from_sympy(value, names)
    except SympyConversionError as exc:
        raise BuildError(str(exc)) from exc


def _set_text(value: SetLike, states: Sequence[str]) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, BespokeSet):
        constraints = _constraints(value, states)
        text = "{ " + ", ".join(str(c) for c in constraints) + " }"
        if value.box is None:
            return text
        _check_inside_box(Semialgebraic(tuple(constraints), tuple(states)), value.box, states)
        # proved equal to the constraints alone; the box lets the checker see a bound
        low, high = ("[" + ", ".join(map(_exact_text, side)) + "]" for side in value.box)
        return f"({text} & box({low}, {high}))"
    raise BuildError(f"a set is .fsl text or a BespokeSet, not {type(value).__name__}")


def _exact_text(value: float) -> str:
    """The number as the user wrote it (0.2, not the double nearest to it)."""
    return to_text(Num(Fraction(repr(float(value)))))


def _check_inside_box(region: Semialgebraic, box, states: Sequence[str]) -> None:
    """A bespoke set's constraints must lie in its box: every proof is about the
    constraints, every sample is drawn in the box."""
    context = CheckContext()
    context.states.extend(states)
    low, high = (tuple(Num(Fraction(repr(float(v)))) for v in side) for side in box)
    query = L.conjunction(region.contains_formula(states), L.negation(
        Box(low, high).contains_formula(states)))
    RelationProver(context, states, Z3Backend()).refute(
        query, f"the bespoke set {region.text()} lies in its box", None)
    if has_errors(context.diagnostics):
        raise BuildError("; ".join(d.message for d in context.diagnostics)
                         + " (its `box` must contain every point of its constraints)")


def _constraints(bespoke: BespokeSet, states: Sequence[str]) -> list[L.Compare]:
    symbols = [sympy.Symbol(s, real=True) for s in states]
    found = []
    for relation in bespoke.constraints(symbols):
        if not isinstance(relation, sympy.core.relational.Relational) or \
                relation.rel_op not in ("<", "<=", ">", ">="):
            raise BuildError(f"a bespoke set's constraint must be <, <=, > or >=: {relation}")
        found.append(L.Compare(relation.rel_op, _expr(relation.lhs, states),
                               _expr(relation.rhs, states)))
    return found


def _with_bespoke_sets(spec: CheckedSpec, bespoke: Mapping[str, BespokeSet]) -> CheckedSpec:
    """The checked spec with each bespoke set's semialgebraic stand-in replaced, wherever
    it occurs, by a set that samples itself."""
    swaps: dict[int, SetExpr] = {}
    for key, value in bespoke.items():
        stand_in = spec.domain if key == "domain" else spec.sets[key]
        stand_in = stand_in.value if isinstance(stand_in, Named) else stand_in
        constraints = stand_in.left if isinstance(stand_in, Intersection) else stand_in
        assert isinstance(constraints, Semialgebraic)
        box = None if value.box is None else \
            (tuple(map(float, value.box[0])), tuple(map(float, value.box[1])))
        swaps[id(stand_in)] = Bespoke(constraints.constraints, constraints.states, key,
                                      value.sample, box)
    if not swaps:
        return spec
    roles = {k: _swap(v, swaps) for k, v in spec.property.roles.items()}
    return dataclasses.replace(
        spec, domain=_swap(spec.domain, swaps),
        sets={k: _swap(v, swaps) for k, v in spec.sets.items()},
        property=dataclasses.replace(spec.property, roles=roles))


def _swap(node, swaps: dict[int, SetExpr]):
    if id(node) in swaps:
        return swaps[id(node)]
    if not (dataclasses.is_dataclass(node) and isinstance(node, SetExpr)):
        return node
    changes = {f.name: _swap(getattr(node, f.name), swaps) for f in dataclasses.fields(node)
               if isinstance(getattr(node, f.name), SetExpr)}
    return dataclasses.replace(node, **changes) if changes else node


def _check_agreement(spec: CheckedSpec, field: Callable) -> None:
    """The torch field must be the field the formulas state: learning on one system and
    proving another would waste the run."""
    box = spec.domain.bounding_box() or ((-1.0,) * len(spec.states), (1.0,) * len(spec.states))
    import torch  # the field is a torch function: the caller has torch loaded already
    low, high = (torch.tensor(b, dtype=torch.float64) for b in box)
    generator = torch.Generator().manual_seed(0)
    points = low + (high - low) * torch.rand(AGREEMENT_POINTS, len(spec.states),
                                             generator=generator, dtype=torch.float64)
    inputs = None
    env = state_env(spec.states, points)
    if spec.inputs:
        inputs = torch.rand(AGREEMENT_POINTS, len(spec.inputs), generator=generator,
                            dtype=torch.float64) * 2 - 1
        env.update({u: inputs[:, i] for i, u in enumerate(spec.inputs)})
    given = torch.as_tensor(field(points, inputs), dtype=torch.float64)
    exact = torch.stack([torch.as_tensor(evaluate(f, env), dtype=torch.float64)
                         .expand(AGREEMENT_POINTS) for f in spec.dynamics], 1)
    if given.shape != exact.shape:
        raise BuildError(f"torch_dynamics returned shape {tuple(given.shape)}, expected "
                         f"{tuple(exact.shape)}")
    error = ((given - exact).abs() / (1 + exact.abs())).max()
    if not error <= AGREEMENT_TOLERANCE:
        raise BuildError(f"torch_dynamics differs from the dynamics formulas (relative "
                         f"error {float(error):.3g} on random points of the domain)")
