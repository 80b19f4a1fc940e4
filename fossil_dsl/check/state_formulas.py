"""Sets combined inside a `prove` formula: `always not (rock or pit)`.

A part of a formula built from set names with `not`, `and` and `or` alone says where the
state is at one instant, so it is a set: `rock or pit` is `rock | pit`, `not hot` is
`~hot`, `safe and not hot` is `safe & ~hot`. The property table's letters (U, G, F) then
bind to that set as they bind to a single name.

`always A and always B` says what `always (A and B)` says, and `not eventually A` what
`always not A` says: `merge_always` joins them, so that `always not rock and always not
pit` is safety with the unsafe set `rock | pit`.
"""
from __future__ import annotations

from fossil_dsl.syntax import ast

_SET_OPERATOR = {"and": "&", "or": "|"}


def as_set(node: ast.Formula) -> ast.SetExpr | None:
    """The set a formula of set names, `not`, `and` and `or` denotes; None otherwise."""
    if isinstance(node, ast.FSet):
        return ast.SetRef(node.name, node.span)
    if isinstance(node, ast.FUnary) and node.op == "not":
        operand = as_set(node.operand)
        return None if operand is None else ast.SetComplement(operand, node.span)
    if isinstance(node, ast.FBinary) and node.op in _SET_OPERATOR:
        left, right = as_set(node.left), as_set(node.right)
        if left is None or right is None:
            return None
        return ast.SetBinary(_SET_OPERATOR[node.op], left, right, node.span)
    return None


def merge_always(node: ast.Formula) -> ast.Formula:
    """The formula with the `always` of set formulas in each chain of `and` joined into
    one `always`."""
    if isinstance(node, ast.FUnary):
        return ast.FUnary(node.op, merge_always(node.operand), node.span)
    if not isinstance(node, ast.FBinary):
        return node
    if node.op != "and":
        return ast.FBinary(node.op, merge_always(node.left), merge_always(node.right),
                           node.span)
    items = [merge_always(item) for item in flatten(node, "and")]
    invariants = [_invariant(item) for item in items]
    joined = [inv for inv in invariants if inv is not None]
    if len(joined) < 2:
        return combine(items, "and")
    rest = [item for item, inv in zip(items, invariants) if inv is None]
    always = ast.FUnary("always", combine(joined, "and"), joined[0].span)
    return combine(rest + [always], "and")


def _invariant(node: ast.Formula) -> ast.Formula | None:
    """A for `always A` and `not A` for `not eventually A`, where A is a set formula."""
    if not isinstance(node, ast.FUnary):
        return None
    if node.op == "always" and as_set(node.operand) is not None:
        return node.operand
    inner = node.operand
    if node.op == "not" and isinstance(inner, ast.FUnary) and inner.op == "eventually" \
            and as_set(inner.operand) is not None:
        return ast.FUnary("not", inner.operand, node.span)
    return None


def combine(nodes: list[ast.Formula], op: str) -> ast.Formula:
    """The formulas joined by `op` (`and`/`or`), left to right."""
    joined = nodes[0]
    for node in nodes[1:]:
        joined = ast.FBinary(op, joined, node, joined.span)
    return joined


def key(node: ast.SetExpr) -> str:
    """A name for a combined set, the same wherever the same combination is written."""
    if isinstance(node, ast.SetRef):
        return node.name
    if isinstance(node, ast.SetComplement):
        return f"~{key(node.operand)}"
    return f"({key(node.left)} {node.op} {key(node.right)})"


def combined_sets(formula: ast.Formula) -> dict[str, ast.SetExpr]:
    """Every combination of sets written in the formula, by its key."""
    found: dict[str, ast.SetExpr] = {}
    stack = [formula]
    while stack:
        node = stack.pop()
        combined = as_set(node) if isinstance(node, ast.FBinary) else None
        if combined is not None:
            found[key(combined)] = combined
        elif isinstance(node, ast.FUnary):
            stack.append(node.operand)
        elif isinstance(node, ast.FBinary):
            stack.extend(set_parts(node))
    return found


def set_parts(node: ast.FBinary) -> list[ast.Formula]:
    """The operands, with the set-only operands of a chain of `and` (`or`) joined."""
    if node.op == "until":
        return [node.left, node.right]
    items = list(flatten(node, node.op))
    sets = [item for item in items if as_set(item) is not None]
    rest = [item for item in items if as_set(item) is None]
    return rest + ([combine(sets, node.op)] if len(sets) > 1 else sets)


def flatten(node: ast.Formula, op: str):
    if isinstance(node, ast.FBinary) and node.op == op:
        yield from flatten(node.left, op)
        yield from flatten(node.right, op)
    else:
        yield node
