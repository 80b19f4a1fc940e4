"""Solver-neutral boolean formulas over expressions: comparisons, and, or, not."""
from __future__ import annotations

from dataclasses import dataclass

from fossil_dsl.ir.expr import Expr, Num, to_text
from fossil_dsl.ir.traversal import free_vars as expr_free_vars, substitute as expr_substitute

class Formula:
    def __and__(self, other): return conjunction(self, other)
    def __or__(self, other): return disjunction(self, other)
    def __invert__(self): return negation(self)

    def __str__(self) -> str:
        return formula_text(self)


@dataclass(frozen=True)
class Compare(Formula):
    relation: str  # one of RELATIONS
    left: Expr
    right: Expr


@dataclass(frozen=True)
class And(Formula):
    args: tuple[Formula, ...]


@dataclass(frozen=True)
class Or(Formula):
    args: tuple[Formula, ...]


@dataclass(frozen=True)
class Not(Formula):
    arg: Formula


@dataclass(frozen=True)
class BoolConst(Formula):
    value: bool


TRUE = BoolConst(True)
FALSE = BoolConst(False)


def conjunction(*args: Formula) -> Formula:
    flat: list[Formula] = []
    for arg in args:
        if arg == FALSE:
            return FALSE
        if arg != TRUE:
            flat.extend(arg.args if isinstance(arg, And) else (arg,))
    if not flat:
        return TRUE
    return flat[0] if len(flat) == 1 else And(tuple(flat))


def disjunction(*args: Formula) -> Formula:
    flat: list[Formula] = []
    for arg in args:
        if arg == TRUE:
            return TRUE
        if arg != FALSE:
            flat.extend(arg.args if isinstance(arg, Or) else (arg,))
    if not flat:
        return FALSE
    return flat[0] if len(flat) == 1 else Or(tuple(flat))


def negation(arg: Formula) -> Formula:
    if isinstance(arg, BoolConst):
        return BoolConst(not arg.value)
    if isinstance(arg, Not):
        return arg.arg
    return Not(arg)


_STRICT = {"<=": "<", ">=": ">", "<": "<", ">": ">"}
_LOOSE = {"<": "<=", ">": ">=", "<=": "<=", ">=": ">="}
_FLIPPED = {"<=": ">", "<": ">=", ">=": "<", ">": "<="}


def negated_inward(formula: Formula) -> Formula:
    """not(formula), with the negation moved down onto the comparisons (flipped)."""
    if isinstance(formula, Compare):
        return Compare(_FLIPPED[formula.relation], formula.left, formula.right)
    if isinstance(formula, Not):
        return formula.arg
    if isinstance(formula, BoolConst):
        return BoolConst(not formula.value)
    parts = [negated_inward(arg) for arg in formula.args]
    return disjunction(*parts) if isinstance(formula, And) else conjunction(*parts)


def negations_inward(formula: Formula) -> Formula:
    """The formula with every negation moved onto its comparisons (flipped): it is then
    monotone in them, and a search meets the same comparison objects in every box."""
    if isinstance(formula, Not):
        return negations_inward(negated_inward(formula.arg))
    if isinstance(formula, (And, Or)):
        parts = [negations_inward(arg) for arg in formula.args]
        return conjunction(*parts) if isinstance(formula, And) else disjunction(*parts)
    return formula


def open_inner(formula: Formula) -> Formula:
    """An open set inside the set that `formula` describes (all comparisons strict).

    For continuous expressions, {g < h} is open, and a set of points satisfying every
    strict comparison lies in the interior; negations flip to closed supersets.
    """
    return _approximate(formula, _STRICT, _LOOSE)


def closed_outer(formula: Formula) -> Formula:
    """A closed set containing the set that `formula` describes."""
    return _approximate(formula, _LOOSE, _STRICT)


def _approximate(formula: Formula, same: dict, dual: dict) -> Formula:
    if isinstance(formula, Compare):
        return Compare(same[formula.relation], formula.left, formula.right)
    if isinstance(formula, And):
        return conjunction(*(_approximate(a, same, dual) for a in formula.args))
    if isinstance(formula, Or):
        return disjunction(*(_approximate(a, same, dual) for a in formula.args))
    if isinstance(formula, Not):
        return negation(_approximate(formula.arg, dual, same))
    return formula


def truth(formula: Formula) -> bool | None:
    """The exact truth value of a formula where its comparisons between numbers decide
    it (a conjunction with a false one is false, whatever the others; a numerical
    procedure would read `0 > 0` as true within its tolerance), else None."""
    if isinstance(formula, BoolConst):
        return formula.value
    if isinstance(formula, Compare):
        if not (isinstance(formula.left, Num) and isinstance(formula.right, Num)):
            return None
        a, b = formula.left.value, formula.right.value
        return {"<=": a <= b, "<": a < b, ">=": a >= b, ">": a > b}[formula.relation]
    values = [truth(a) for a in children(formula)]
    if isinstance(formula, Not):
        return None if values[0] is None else not values[0]
    deciding = isinstance(formula, Or)  # the value that decides: True for Or, False for And
    if deciding in values:
        return deciding
    return None if None in values else not deciding


def children(formula: Formula) -> tuple[Formula, ...]:
    if isinstance(formula, (And, Or)):
        return formula.args
    if isinstance(formula, Not):
        return (formula.arg,)
    return ()


def comparisons(formula: Formula):
    stack = [formula]
    while stack:
        node = stack.pop()
        if isinstance(node, Compare):
            yield node
        stack.extend(children(node))


def free_vars(formula: Formula) -> frozenset[str]:
    names: set[str] = set()
    for comparison in comparisons(formula):
        names |= expr_free_vars(comparison.left) | expr_free_vars(comparison.right)
    return frozenset(names)


def map_comparisons(formula: Formula, change) -> Formula:
    """The formula with each comparison c replaced by change(c), its and/or/not kept."""
    if isinstance(formula, Compare):
        return change(formula)
    if isinstance(formula, And):
        return conjunction(*(map_comparisons(a, change) for a in formula.args))
    if isinstance(formula, Or):
        return disjunction(*(map_comparisons(a, change) for a in formula.args))
    if isinstance(formula, Not):
        return negation(map_comparisons(formula.arg, change))
    return formula


def substitute(formula: Formula, mapping) -> Formula:
    return map_comparisons(formula, lambda c: Compare(
        c.relation, expr_substitute(c.left, mapping), expr_substitute(c.right, mapping)))


def boundary_outer(formula: Formula) -> Formula:
    """A closed set containing the boundary of the set A that `formula` describes.

    Three closed sets contain the boundary, and so does their intersection: the closure
    of A and the closure of its complement (∂A is their intersection; for continuous
    expressions `closed_outer` gives a closed superset of each), and the points where
    some comparison is at equality (elsewhere every comparison keeps its truth value
    nearby, so the point is not on the boundary). Exact for boxes, balls and ellipsoids,
    and for a domain minus such a set: the second set is what keeps the lines through a
    box's faces, outside the box, off the boundary of D \\ U.
    """
    atoms = {(c.left, c.right): c for c in comparisons(formula)}
    on_some_atom = disjunction(*(conjunction(Compare("<=", left, right),
                                             Compare(">=", left, right))
                                 for left, right in atoms))
    return conjunction(closed_outer(formula), closed_outer(negation(formula)), on_some_atom)


# ---- text ---------------------------------------------------------------------
def formula_text(formula: Formula) -> str:
    if isinstance(formula, Compare):
        return f"{to_text(formula.left)} {formula.relation} {to_text(formula.right)}"
    if isinstance(formula, And):
        return " and ".join(_formula_wrapped(a) for a in formula.args)
    if isinstance(formula, Or):
        return " or ".join(_formula_wrapped(a) for a in formula.args)
    if isinstance(formula, Not):
        return "not " + _formula_wrapped(formula.arg)
    if isinstance(formula, BoolConst):
        return "true" if formula.value else "false"
    raise TypeError(f"not a formula: {formula!r}")


def _formula_wrapped(formula: Formula) -> str:
    text = formula_text(formula)
    return f"({text})" if isinstance(formula, (And, Or)) else text
