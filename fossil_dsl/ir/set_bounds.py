"""The box a conjunction of comparisons lies in (Semialgebraic.bounding_box): from the
comparisons that bound one state by a constant (`x0 <= 2`, `-1 <= x1`), and from those
that bound a sum of squares (`x^2 + (y - 1)^2 <= 4`, a disc written by hand: probe70/at28,
whose domain was refused as unbounded). Every bound is rounded outward; the kernel proves
again that the set lies in the box it uses."""
from __future__ import annotations

import math
from fractions import Fraction

from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.enclosure import enclose
from fossil_dsl.ir.expr import ExprError, Var, add, free_vars, neg

WIDENING = 1e-9  # relative, on each bound read from a sum of squares


def constraint_box(constraints, states):
    """(lower, upper) bounds of every state, or None where some state is unbounded."""
    lower = {s: -math.inf for s in states}
    upper = {s: math.inf for s in states}
    for constraint in constraints:
        for name, (low, high) in _bounds(constraint, states):
            lower[name], upper[name] = max(lower[name], low), min(upper[name], high)
    box = (tuple(lower[s] for s in states), tuple(upper[s] for s in states))
    return box if all(map(math.isfinite, box[0] + box[1])) else None


def _bounds(constraint: L.Compare, states):
    """(state, (low, high)) pairs the comparison implies."""
    found = []
    for var, const, below in ((constraint.left, constraint.right, True),
                              (constraint.right, constraint.left, False)):
        if isinstance(var, Var) and var.name in states and not free_vars(const):
            low, high = enclose(const)
            at_most = (constraint.relation in ("<", "<=")) == below
            found.append((var.name, (-math.inf, high) if at_most else (low, math.inf)))
    return found or _square_bounds(constraint, states)


def _square_bounds(constraint: L.Compare, states):
    """From p <= 0 with p = sum a_i x_i^2 + b_i x_i + k, every a_i > 0 and no cross
    term: sum a_i (x_i + h_i)^2 <= R, so |x_i + h_i| <= sqrt(R / a_i)."""
    if constraint.relation in ("<", "<="):
        expression = add(constraint.left, neg(constraint.right))
    else:
        expression = add(constraint.right, neg(constraint.left))
    try:
        p = P.polynomial(expression, states)
    except (ValueError, ExprError):  # not a polynomial, or too large to expand
        return []
    squares, linear, constant = {}, {}, Fraction(0)
    for monomial, c in p.items():
        used = [k for k, e in enumerate(monomial) if e]
        if not used:
            constant += c
        elif len(used) > 1 or monomial[used[0]] > 2:
            return []
        elif monomial[used[0]] == 2:
            squares[used[0]] = c
        else:
            linear[used[0]] = c
    if not squares or any(a <= 0 for a in squares.values()) or set(linear) - set(squares):
        return []
    room = sum(linear.get(k, 0) ** 2 / (4 * a) for k, a in squares.items()) - constant
    if room < 0:
        return []  # no point: left to the checker's emptiness test
    try:
        return [(states[k], _interval(-Fraction(linear.get(k, 0)) / (2 * a), room / a))
                for k, a in squares.items()]
    except OverflowError:
        return []


def _interval(centre: Fraction, square: Fraction) -> tuple[float, float]:
    """[centre - r, centre + r] with r^2 = square, widened outward."""
    reach = math.sqrt(float(square)) * (1 + WIDENING) + WIDENING
    middle = float(centre)
    return middle - reach - WIDENING * abs(middle), middle + reach + WIDENING * abs(middle)
