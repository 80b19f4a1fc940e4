"""Subexpressions whose repetitions make up much of an expression written out as a tree.

Expressions share equal subexpressions, but an evaluator that works on trees (codac's
contractors) goes through a shared subexpression once per occurrence. A discrete
barrier's invariance condition B(f(x)) holds the next state f(x) once per neuron of B:
row 17's (a sigmoid barrier, a tanh controller in f) is a tree of 17 534 nodes, 619 of
them distinct, 14 000 of them copies of the two components of f(x). Naming such a
subexpression (an auxiliary variable defined equal to it) leaves one copy.
"""
from __future__ import annotations

from collections import Counter
from typing import Iterable

from fossil_dsl.ir.expr import Expr, children
from fossil_dsl.ir.traversal import children_first

# A subexpression is named when naming it removes at least this share of the tree: an
# auxiliary variable is one more dimension of every box and one more contractor, which a
# small saving does not repay (row 5's flow condition: its 16 repeated tanh applications
# named, the proof took twice as long; session 40).
SHARE_WORTH_NAMING = 1 / 3


def worth_naming(roots: Iterable[Expr], share: float = SHARE_WORTH_NAMING) -> list[Expr]:
    """The subexpressions to name, inner ones first: greedily the one whose naming removes
    the most tree nodes, while that is at least `share` of the tree left."""
    roots = tuple(roots)
    order = children_first(roots)
    named: list[Expr] = []
    while True:
        counts, sizes = _occurrences(roots, order, set(named))
        total = sum(sizes[r] if r not in named else 1 for r in roots) + \
            sum(sizes[n] for n in named)
        candidates = [n for n in order if n not in named and children(n) and counts[n] > 1]
        if not candidates:
            break
        best = max(candidates, key=lambda n: _saving(n, counts, sizes))
        if _saving(best, counts, sizes) < share * total:
            break
        named.append(best)
    position = {node: i for i, node in enumerate(order)}
    return sorted(named, key=position.__getitem__)


def _saving(node: Expr, counts: Counter, sizes: dict) -> int:
    # count copies of a size-node tree become count one-node names and one definition
    return (counts[node] - 1) * (sizes[node] - 1) - 1


def _occurrences(roots, order, named: set) -> tuple[Counter, dict]:
    """Per node: how often it occurs in the trees of the roots and of the named nodes'
    definitions (a named node's children occur once, in its definition), and the size of
    its own tree with named nodes inside it counted as one node."""
    sizes: dict[Expr, int] = {}
    for node in order:
        sizes[node] = 1 + sum(1 if c in named else sizes[c] for c in children(node))
    counts = Counter(roots)
    for node in reversed(order):  # parents before children
        times = 1 if node in named else counts[node]
        for child in children(node):
            counts[child] += times
    return counts, sizes
