"""The property table of the language reference, as a registry of forms, and the
matching of a spec's `prove` formula against it.

A form's pattern is written in .fsl formula syntax over the letters U (avoided set:
`not U` also matches a safe set S, meaning U = the domain minus S), G (goal) and
F (final). Formulas are normalised (double negations removed, `~` read as `not`) and
`and` is matched in any order.
"""
from __future__ import annotations

import dataclasses
import difflib
import functools
import itertools
from dataclasses import dataclass

from fossil_dsl.check.context import CheckContext
from fossil_dsl.check.sets import SetChecker
from fossil_dsl.check.state_formulas import (as_set, combined_sets, key, merge_always,
                                             set_parts)
from fossil_dsl.diagnostics import Span
from fossil_dsl.ir import sets as S
from fossil_dsl.ir.spec import Property
from fossil_dsl.syntax import ast
from fossil_dsl.syntax.parser import parse_formula

# A relation the checker proves before anything runs: (kind, role, other role).
Relation = tuple[str, str, str]


@dataclass(frozen=True)
class PropertyForm:
    name: str
    certificate: str
    pattern: str
    needs_initial: bool = True
    stable_type: bool = False  # the origin must be an equilibrium
    relations: tuple[Relation, ...] = ()
    origin_roles: tuple[str, ...] = ()  # must contain the origin when a controller is built
    max_iters: int = 25
    functions: int = 1
    # equivalent formulas; a letter of `pattern` that one lacks takes its default role
    alternatives: tuple[str, ...] = ()

    @functools.cached_property
    def normal(self) -> tuple:
        return normalise(parse_formula(self.pattern))

    @functools.cached_property
    def normals(self) -> tuple[tuple, ...]:
        return (self.normal,) + tuple(normalise(parse_formula(text))
                                      for text in self.alternatives)

    def display(self) -> str:
        return f"from I: {self.pattern}" if self.needs_initial else self.pattern


_INTERIOR = (("inside_interior", "initial", "safe"), ("inside_interior", "goal", "safe"))

FORMS: list[PropertyForm] = [
    PropertyForm("stability", "Lyapunov", "stable", needs_initial=False,
                 stable_type=True),
    PropertyForm("region of attraction", "ROA", "stable", stable_type=True,
                 relations=(("inside", "initial", "domain"),)),
    PropertyForm("safety", "barrier", "always not U",
                 relations=(("inside", "initial", "domain"), ("disjoint", "initial", "unsafe"))),
    PropertyForm("stable while avoid", "ROA + barrier", "stable and always not U",
                 stable_type=True, max_iters=100, functions=2,
                 relations=(("inside", "initial", "domain"), ("disjoint", "initial", "unsafe"))),
    # reaching G asks no equilibrium of the controller (its bias may hold the state
    # anywhere, a tank's level at its set point: probe70/at27), so G need not hold 0
    PropertyForm("reach while avoid", "reach-while-avoid", "not U until G",
                 relations=_INTERIOR),
    # `always not U and eventually X` is `not U until X` once F and U are disjoint (a
    # relation proved here); without U, S is the domain and U is empty
    PropertyForm("reach and stay while avoid", "RWA + stay level set",
                 "not U until always F",
                 alternatives=("eventually always F", "always not U and eventually always F"),
                 relations=(("inside_interior", "initial", "safe"),
                            ("disjoint", "final", "unsafe")),
                 origin_roles=("final",)),
    # `always not U and eventually G` stays out of U after G too: F is the safe set
    PropertyForm("reach-avoid-remain", "RWA + barrier", "not U until (G and always F)",
                 max_iters=100, functions=2,
                 alternatives=("eventually (G and always F)", "always not U and eventually G",
                               "always not U and eventually (G and always F)"),
                 relations=_INTERIOR + (("inside", "goal", "final"),
                                        ("disjoint", "final", "unsafe")),
                 origin_roles=("goal", "final")),
    PropertyForm("reach", "RWA with the safe set = the domain", "eventually G",
                 relations=_INTERIOR),
]


# `prove stable` with `region: largest` (chosen by the options, never matched): the
# region Ω itself is the result, so there is no initial set
LARGEST_REGION = PropertyForm("largest region of attraction", "ROA", "stable",
                              needs_initial=False, stable_type=True)


def register_form(form: PropertyForm) -> None:
    """Add a property form (for user-defined certificates), replacing one of the same
    name; later forms win ties."""
    FORMS[:] = [form] + [f for f in FORMS if f.name != form.name]


# ---- normal form: nested tuples ------------------------------------------------------
# ("stable",) ("lit", name, negated) ("always", x) ("eventually", x) ("not", x)
# ("until", a, b) ("and", (a, b, ...)) ("or", (a, b, ...))
_DUAL = {"always": "eventually", "eventually": "always"}  # not always A = eventually not A


def normalise(node: ast.Formula, negated: bool = False) -> tuple:
    if isinstance(node, ast.FSet):
        return ("lit", node.name, negated)
    combined = as_set(node) if isinstance(node, ast.FBinary) else None
    if combined is not None:
        return ("lit", key(combined), negated)
    if isinstance(node, ast.FUnary) and node.op == "not":
        return normalise(node.operand, not negated)
    if negated and isinstance(node, ast.FUnary) and node.op in _DUAL:
        return (_DUAL[node.op], normalise(node.operand, True))
    if negated:
        return ("not", normalise(node))
    if isinstance(node, ast.FStable):
        return ("stable",)
    if isinstance(node, ast.FUnary):
        return (node.op, normalise(node.operand))
    if node.op == "until":
        return ("until", normalise(node.left), normalise(node.right))
    return (node.op, tuple(normalise(part) for part in set_parts(node)))


def match(pattern: tuple, node: tuple, binding: dict) -> dict | None:
    """Bind the pattern's letters to (set name, negated); None if it does not match."""
    if pattern[0] == "lit":
        return _match_literal(pattern, node, binding)
    if pattern[0] != node[0]:
        return None
    if pattern[0] == "stable":
        return binding
    if pattern[0] in ("always", "eventually", "not"):
        return match(pattern[1], node[1], binding)
    if pattern[0] == "until":
        left = match(pattern[1], node[1], binding)
        return None if left is None else match(pattern[2], node[2], left)
    return _match_commutative(pattern[1], node[1], binding)


def _match_literal(pattern, node, binding):
    letter, pattern_negated = pattern[1], pattern[2]
    if node[0] != "lit" or (node[2] and not pattern_negated):
        return None
    value = (node[1], node[2])
    if binding.get(letter, value) != value:
        return None
    return {**binding, letter: value}


def _match_commutative(patterns, nodes, binding):
    if len(patterns) != len(nodes):
        return None
    for order in itertools.permutations(nodes):
        result = binding
        for sub_pattern, sub_node in zip(patterns, order):
            result = match(sub_pattern, sub_node, result)
            if result is None:
                break
        if result is not None:
            return result
    return None


def shape_text(node: tuple) -> str:
    """The formula with every set written A, for comparing shapes."""
    kind = node[0]
    if kind == "lit":
        return "not A" if node[2] else "A"
    if kind == "stable":
        return "stable"
    if kind in ("always", "eventually", "not"):
        return f"{kind} {shape_text(node[1])}"
    if kind == "until":
        return f"({shape_text(node[1])} until {shape_text(node[2])})"
    return "(" + f" {kind} ".join(shape_text(n) for n in node[1]) + ")"


def nearest_form(node: tuple, has_initial: bool) -> PropertyForm:
    shape = shape_text(node).split()

    def similarity(form: PropertyForm) -> float:
        score = difflib.SequenceMatcher(None, shape, shape_text(form.normal).split()).ratio()
        return score + (0.01 if form.needs_initial == has_initial else 0)

    return max(FORMS, key=similarity)


# ---- from a `prove` statement to a Property ----------------------------------------
class PropertyChecker:
    def __init__(self, context: CheckContext, sets: SetChecker):
        self.context = context
        self.sets = sets

    def check(self, decl: ast.ProveDecl) -> tuple[Property, PropertyForm] | None:
        formula = merge_always(decl.formula)
        node = normalise(formula)
        has_initial = decl.initial is not None
        found = self._find(node, has_initial, decl)
        if found is None:
            return None
        form, binding = found
        roles, implied = self._roles(decl, formula, form, binding)
        if roles is None:
            return None
        text = _source_text(decl)
        # relations of a filled-in F (the safe set) or U (empty) follow from the others
        relations = tuple(r for r in form.relations if not implied & set(r[1:]))
        return Property(form.name, form.certificate, roles, text), \
            dataclasses.replace(form, relations=relations)

    def _find(self, node, has_initial, decl):
        for form, binding in _matches(node):
            if form.needs_initial == has_initial:
                return form, binding
        for form, _ in _matches(node):
            self._initial_mismatch(form, decl)
            return None
        self._unsupported(node, has_initial, decl)
        return None

    def _initial_mismatch(self, form: PropertyForm, decl: ast.ProveDecl) -> None:
        if form.needs_initial:
            self.context.error(f"`{form.pattern}` ({form.name}) needs an initial set: "
                               f"write `prove from I: {form.pattern}`", decl.formula.span)
        else:
            self.context.error(f"`{form.pattern}` ({form.name}) takes no initial set",
                               decl.span)

    def _unsupported(self, node, has_initial, decl):
        nearest = nearest_form(node, has_initial)
        supported = "; ".join(f"`{f.display()}` ({f.name})" for f in FORMS)
        self.context.error(
            f"unsupported property: no certificate proves this formula; the nearest "
            f"supported form is `{nearest.display()}` ({nearest.name})", decl.formula.span,
            f"supported forms: {supported}")

    def _roles(self, decl, formula, form, binding) -> tuple[dict[str, S.SetExpr] | None,
                                                            set[str]]:
        spans = _literal_spans(formula)
        combined = combined_sets(formula)
        roles: dict[str, S.SetExpr | None] = {"domain": self.sets.domain}
        if decl.initial is not None:
            roles["initial"] = self.sets.convert(decl.initial)
        for letter, (name, negated) in binding.items():
            written = combined.get(name) or ast.SetRef(name, spans[name])
            value = self.sets.convert(written)
            roles.update(_letter_roles(letter, value, negated, self.sets.domain))
        implied = _default_roles(roles, form, binding)
        if any(value is None for value in roles.values()):
            return None, implied
        return roles, implied


def _matches(node: tuple):
    """(form, binding) of every form one of whose formulas the normal form matches."""
    for form in FORMS:
        for normal in form.normals:
            binding = match(normal, node, {})
            if binding is not None:
                yield form, binding
                break


def _default_roles(roles: dict, form: PropertyForm, binding: dict) -> set[str]:
    """Fill in the roles of letters the written formula left out, and return the filled
    in roles that are implied: without U the safe set is the domain and U is empty;
    without F (`always not U and eventually G`) F is the safe set."""
    letters, implied = _letters(form.normal), set()
    domain = roles["domain"]
    if "unsafe" not in roles and "safe" not in roles and ("U" in letters or "goal" in roles):
        roles["safe"] = domain
        if "U" in letters and domain is not None:
            roles["unsafe"] = S.Complement(domain, domain)
            implied.add("unsafe")
    if "F" in letters and "F" not in binding:
        roles["final"] = roles.get("safe")
        implied.add("final")
    return implied


def _letters(node: tuple) -> set[str]:
    if node[0] == "lit":
        return {node[1]}
    parts = node[1] if node[0] in ("and", "or") else node[1:]
    return set().union(*(_letters(part) for part in parts if isinstance(part, tuple)))


def _letter_roles(letter, value, negated, domain) -> dict:
    if letter == "G":
        return {"goal": value}
    if letter == "F":
        return {"final": value}
    if value is None or domain is None:
        return {"unsafe": None}
    if negated:
        return {"unsafe": value, "safe": S.Complement(value, domain)}
    return {"safe": S.Intersection(value, domain), "unsafe": S.Complement(value, domain)}


def formula_set_names(formula: ast.Formula) -> set[str]:
    return set(_literal_spans(formula))


def _literal_spans(formula: ast.Formula) -> dict[str, Span]:
    spans: dict[str, Span] = {}
    stack = [formula]
    while stack:
        node = stack.pop()
        if isinstance(node, ast.FSet):
            spans.setdefault(node.name, node.span)
        elif isinstance(node, ast.FUnary):
            stack.append(node.operand)
        elif isinstance(node, ast.FBinary):
            stack.extend((node.left, node.right))
    return spans


def _source_text(decl: ast.ProveDecl) -> str:
    return "prove " + _formula_text(decl.formula) if decl.initial is None else \
        f"prove from {_set_text(decl.initial)}: {_formula_text(decl.formula)}"


def _formula_text(node: ast.Formula) -> str:
    if isinstance(node, ast.FSet):
        return node.name
    if isinstance(node, ast.FStable):
        return "stable"
    if isinstance(node, ast.FUnary):
        return f"{node.op} {_formula_text(node.operand)}"
    return f"({_formula_text(node.left)} {node.op} {_formula_text(node.right)})"


def _set_text(node: ast.SetExpr) -> str:
    return node.name if isinstance(node, ast.SetRef) else "(a set expression)"
