"""The starting box of the Arb refutation procedure (arb_backend.py): bounds that the
query's own top-level conjuncts give each variable, worked out in exact rationals and
rounded outwards: `c <= x`, `x <= c`, and axis-parallel ellipsoids
`sum a_i (x_i - c_i)^2 <= r` (balls among them), and for a disjunction the hull of its
disjuncts' boxes. A variable no conjunct bounds gets none (the search then answers
UNKNOWN)."""
from __future__ import annotations

import math
from fractions import Fraction

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P

BELOW, ABOVE = ("<", "<="), (">", ">=")


def starting_box(formula: L.Formula, names) -> list[tuple[float, float]] | None:
    """Float bounds (rounded outwards) for each variable from the query's conjuncts, a
    disjunction's being the hull of its disjuncts' (a set given as a union of a disc and
    boxes), or None where some variable gets none."""
    low, high = _box(formula, names)
    if not all(math.isfinite(low[n]) and math.isfinite(high[n]) for n in names):
        return None
    return [(low[n], high[n]) for n in names]


def _box(formula: L.Formula, names) -> tuple[dict, dict]:
    """(low, high) per variable that every point of the formula's set lies within."""
    low = {name: -math.inf for name in names}
    high = {name: math.inf for name in names}
    for atom in _conjuncts(formula):
        if isinstance(atom, L.Or):
            boxes = [_box(arg, names) for arg in atom.args]
            bounds = [(name, min(b[0][name] for b in boxes), max(b[1][name] for b in boxes))
                      for name in names]
        else:
            bounds = _bounds(atom, names)
        for name, lower, upper in bounds:
            low[name] = max(low[name], lower)
            high[name] = min(high[name], upper)
    return low, high


def _conjuncts(formula: L.Formula) -> list[L.Formula]:
    if isinstance(formula, L.And):
        return [atom for arg in formula.args for atom in _conjuncts(arg)]
    if isinstance(formula, L.Not):  # negated inwards: a comparison flips, `or` splits
        return _conjuncts(L.negated_inward(formula.arg))
    return [formula]


def _bounds(atom: L.Formula, names):
    """(variable, lower, upper) that the comparison implies: from `x <= c`, `c <= x`, an
    axis-parallel ellipsoid `sum a_i (x_i - c_i)^2 <= r`, and any ellipsoid
    `x^T A x + b^T x + k <= 0` with A positive definite (a sublevel set of a quadratic V)."""
    polynomial = _at_most_zero(atom, names)
    if polynomial is None:
        return []
    return _ellipsoid_bounds(polynomial, names) or quadratic_bounds(polynomial, names)


def _at_most_zero(atom: L.Formula, names) -> dict | None:
    """p with the comparison saying p(x) <= 0 (or < 0), if p is a polynomial in names."""
    if not isinstance(atom, L.Compare) or atom.relation not in BELOW + ABOVE:
        return None
    small, large = (atom.left, atom.right) if atom.relation in BELOW \
        else (atom.right, atom.left)
    try:
        return P.polynomial(E.add(small, E.neg(large)), names)
    except ValueError:
        return None


def ellipsoids(formula: L.Formula, names) -> list[tuple[dict, dict, Fraction]]:
    """The axis-parallel ellipsoids sum a_i (x_i - c_i)^2 <= R among the conjuncts, as
    ({name: a_i}, {name: c_i}, R), exactly."""
    found = []
    for atom in _conjuncts(formula):
        polynomial = _at_most_zero(atom, names)
        parts = None if polynomial is None else _ellipsoid_parts(polynomial, names)
        if parts is not None and parts[0] and _radius(*parts) >= 0:
            square, linear, _ = parts
            found.append(({names[i]: a for i, a in square.items()},
                          {names[i]: -linear.get(i, 0) / (2 * a) for i, a in square.items()},
                          _radius(*parts)))
    return found


def _ellipsoid_parts(polynomial: dict, names):
    """({i: a_i}, {i: b_i}, k) for p = sum (a_i x_i^2 + b_i x_i) + k with every a_i > 0
    and b_i = 0 where a_i is not given (unless p is linear); None for any other p."""
    n = len(names)
    square, linear, constant = {}, {}, Fraction(0)
    for monomial, coefficient in polynomial.items():
        degree = sum(monomial)
        if degree == 0:
            constant = Fraction(coefficient)
        elif degree == 1 or (degree == 2 and max(monomial) == 2):
            i = max(range(n), key=lambda j: monomial[j])
            (square if degree == 2 else linear)[i] = Fraction(coefficient)
        else:
            return None
    if any(a <= 0 for a in square.values()) or (square and set(linear) - set(square)):
        return None
    return square, linear, constant


def _radius(square: dict, linear: dict, constant: Fraction) -> Fraction:
    """R with p(x) <= 0 the ellipsoid sum a_i (x_i - c_i)^2 <= R."""
    return sum(linear.get(i, 0) ** 2 / (4 * a) for i, a in square.items()) - constant


def _ellipsoid_bounds(polynomial: dict, names):
    """For p(x) <= 0 with p = sum (a_i x_i^2 + b_i x_i) + k, every a_i >= 0 (no products
    of two variables): |x_i + b_i / 2a_i| <= sqrt(R / a_i), R = sum b_i^2 / 4a_i - k,
    where a_i > 0; x_i <= -k / b_i (or >=) where p is linear in x_i alone."""
    parts = _ellipsoid_parts(polynomial, names)
    if parts is None:
        return []
    square, linear, constant = parts
    if not square:
        if len(linear) != 1:
            return []
        (i, b), = linear.items()
        edge = -constant / b
        return [(names[i], -math.inf, _up(edge))] if b > 0 else [(names[i], _down(edge), math.inf)]
    radius = _radius(square, linear, constant)
    if radius < 0:
        return []
    found = []
    for i, a in square.items():
        centre = -Fraction(linear.get(i, 0)) / (2 * a)
        reach = Fraction(sqrt_up(radius / a))
        found.append((names[i], _down(centre - reach), _up(centre + reach)))
    return found


def quadratic_bounds(polynomial: dict, names):
    """For p(x) = x^T A x + b^T x + k <= 0 over the variables p has, A positive definite:
    the bounds of each x_i on the ellipsoid (quadratic_ellipsoid); [] for any other p."""
    found = quadratic_ellipsoid(polynomial, names)
    if found is None:
        return []
    used, inverse, centre, radius = found
    bounds = []
    for row, v in enumerate(used):
        reach = Fraction(sqrt_up(radius * inverse[row][row]))
        bounds.append((v, _down(centre[row] - reach), _up(centre[row] + reach)))
    return bounds


def quadratic_ellipsoid(polynomial: dict, names):
    """For p(x) = x^T A x + b^T x + k over the variables p has, A positive definite
    (shown exactly, by the pivots of its LDL^T factorisation): (those variables' names,
    A^-1, c = -A^-1 b / 2, R = b^T A^-1 b / 4 - k), so that p <= 0 is (x - c)^T A (x - c)
    <= R, on which a linear b^T x reaches b^T c -+ sqrt(R b^T A^-1 b); None for any other
    p (or R < 0), all exact."""
    if any(sum(m) > 2 for m in polynomial):
        return None
    used = sorted({i for m in polynomial for i, k in enumerate(m) if k})
    where = {v: row for row, v in enumerate(used)}
    A = [[Fraction(0)] * len(used) for _ in used]
    b, k = [Fraction(0)] * len(used), Fraction(0)
    for monomial, coefficient in polynomial.items():
        present = [i for i, e in enumerate(monomial) for _ in range(e)]
        c = Fraction(coefficient)
        if not present:
            k = c
        elif len(present) == 1:
            b[where[present[0]]] = c
        elif present[0] == present[1]:
            A[where[present[0]]][where[present[0]]] = c
        else:
            i, j = where[present[0]], where[present[1]]
            A[i][j] = A[j][i] = c / 2
    inverse = _positive_definite_inverse(A) if used else None
    if inverse is None:
        return None
    n = len(used)
    centre = [-sum(inverse[i][j] * b[j] for j in range(n)) / 2 for i in range(n)]
    radius = sum(b[i] * inverse[i][j] * b[j] for i in range(n) for j in range(n)) / 4 - k
    return None if radius < 0 else ([names[v] for v in used], inverse, centre, radius)


def quadratic_ellipsoids(formula: L.Formula, names) -> list[tuple]:
    """quadratic_ellipsoid() of every conjunct p(x) <= 0 with a positive definite
    quadratic p (a sublevel set {V <= β} of a quadratic V, cross terms and all)."""
    found = []
    for atom in _conjuncts(formula):
        polynomial = _at_most_zero(atom, names)
        ellipsoid = None if polynomial is None else quadratic_ellipsoid(polynomial, names)
        if ellipsoid is not None:
            found.append(ellipsoid)
    return found


def _positive_definite_inverse(A: list[list[Fraction]]) -> list[list[Fraction]] | None:
    """A^-1 by Gauss-Jordan elimination without pivoting, in exact rationals, or None
    unless every pivot is positive (for a symmetric A: positive definite)."""
    n = len(A)
    work = [row[:] + [Fraction(int(i == j)) for j in range(n)] for i, row in enumerate(A)]
    for col in range(n):
        pivot = work[col][col]
        if pivot <= 0:
            return None
        for row in range(col + 1, n):
            factor = work[row][col] / pivot
            if factor:
                work[row] = [a - factor * p for a, p in zip(work[row], work[col])]
    for col in reversed(range(n)):
        work[col] = [a / work[col][col] for a in work[col]]
        for row in range(col):
            factor = work[row][col]
            if factor:
                work[row] = [a - factor * p for a, p in zip(work[row], work[col])]
    return [row[n:] for row in work]


def sqrt_up(value: Fraction) -> float:
    root = math.sqrt(_up(value))
    while Fraction(root) ** 2 < value:
        root = math.nextafter(root, math.inf)
    return root


def _up(value: Fraction) -> float:
    near = float(value)
    return near if Fraction(near) >= value else math.nextafter(near, math.inf)


def _down(value: Fraction) -> float:
    near = float(value)
    return near if Fraction(near) <= value else math.nextafter(near, -math.inf)
