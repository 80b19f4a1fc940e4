"""A polynomial query that every point of a transcendental query extends to.

Each application f(a) of an elementary function in a query is replaced by a fresh
variable t, and polynomial facts about t = f(a) are added as conjuncts. Every fact holds
for every real argument (universal), or for every argument in a range that the query's
own top-level conjuncts imply (from `c <= x`, `x <= c` and axis-parallel ellipsoids:
arb_box.py, worked out exactly). So a point x satisfying the query gives the point
(x, f(a(x)), ...) satisfying the polynomial query: if that one is unsatisfiable (a
sum-of-squares refutation, checked exactly), so is the query.

Universal facts (t = f(a)):
- sin: sin a lies between a and a - a^3/6 (for a >= 0, a - a^3/6 <= sin a <= a by the
  alternating Taylor series; sin is odd): (t - a)(t - a + a^3/6) <= 0; and t^2 <= 1.
- cos: 1 - a^2/2 <= cos a <= 1 (the same argument; cos is even).
- tanh, atan: between 0 and a, i.e. t (t - a) <= 0; between a and a - a^3/3: g(a) = f(a)
  - a + a^3/3 has g(0) = 0 and g'(a) = a^2 - tanh(a)^2 >= 0 (tanh), a^4/(1 + a^2) >= 0
  (atan), so g >= 0 for a >= 0 (both are odd); and t^2 <= 1 (tanh), t^2 <= 2.4675 >
  (pi/2)^2 (atan).
- exp: t > 0 and t >= 1 + a (convexity: the tangent at 0).
Facts for |a| <= L, with the constants below rounded the safe way from arb's enclosures:
- sin (L <= 3), tanh, atan: f(a)/a decreases in |a| from 1, so t lies between a and k a,
  k = f(L)/L: (t - a)(t - k a) <= 0. (With these, the cubic facts are left out: they
  only raise the degree of the refutation.)
- cos (L <= 3): (1 - cos a)/a^2 decreases in |a|, so t <= 1 - c a^2, c = (1 - cos L)/L^2.
- exp, for lo <= a <= hi: below the chord, t <= E(lo) + (a - lo)(E(hi) - E(lo))/(hi - lo)
  with E an upper bound of exp (convexity).
- sin, cos, tanh, for a range at most 1/2 wide without 0 inside: within a rounded-up ε
  of their quadratic Taylor polynomial at its middle (taylor_facts.py); these replace
  the sector facts there.
Other functions (log, sqrt, tan) become a variable with no fact; abs stays (solvers
encode it). tests/test_atom_facts.py checks every fact at many points against sympy at 60 digits.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.solvers.arb_rounding import arb, lower, upper
from fossil_dsl.solvers.arb_box import (ellipsoids, quadratic_ellipsoids, sqrt_up,
                                        starting_box)
from fossil_dsl.solvers.taylor_facts import narrow, taylor_facts

ATOM_PREFIX = "@"  # not a spec identifier's first character: no clash with a state
SINE_RANGE = 3  # below pi: sin(a)/a and (1 - cos a)/a^2 still decrease


def _n(value) -> E.Num:
    return E.Num(Fraction(value))


def _cube(a: E.Expr) -> E.Expr:
    return E.power(a, _n(3))


def _between(t: E.Expr, one: E.Expr, other: E.Expr) -> L.Formula:
    """t lies between `one` and `other` (in either order): (t - one)(t - other) <= 0."""
    product = E.mul(E.add(t, E.neg(one)), E.add(t, E.neg(other)))
    return L.Compare("<=", product, _n(0))


def _at_most(smaller: E.Expr, larger: E.Expr) -> L.Formula:
    return L.Compare("<=", smaller, larger)


def _minus_cube(a: E.Expr, share: Fraction) -> E.Expr:
    return E.add(a, E.neg(E.mul(_n(share), _cube(a))))


def _sin(a: E.Expr, t: E.Expr, reach) -> list[L.Formula]:
    if narrow(reach):
        return [_square_at_most(t, 1)] + taylor_facts("sin", a, t, reach)
    width = _width(reach)
    if width is not None and width <= SINE_RANGE:
        return [_square_at_most(t, 1), _between(t, a, _scaled(_sin_ratio(width), a))]
    return [_square_at_most(t, 1), _between(t, a, _minus_cube(a, Fraction(1, 6)))]


def _cos(a: E.Expr, t: E.Expr, reach) -> list[L.Formula]:
    if narrow(reach):
        return [_at_most(t, _n(1))] + taylor_facts("cos", a, t, reach)
    facts = [_at_most(_one_minus(Fraction(1, 2), a), t), _at_most(t, _n(1))]
    width = _width(reach)
    if width is not None and width <= SINE_RANGE:
        facts.append(_at_most(t, _one_minus(lower(_cosine_ratio(width)), a)))
    return facts


def _sigmoid(func: str, square_bound: Fraction):
    """tanh and atan: the same facts, with their own ratio and bound."""
    def facts(a: E.Expr, t: E.Expr, reach) -> list[L.Formula]:
        if func == "tanh" and narrow(reach):
            return [_square_at_most(t, square_bound)] + taylor_facts(func, a, t, reach)
        width = _width(reach)
        nearer = _minus_cube(a, Fraction(1, 3)) if width is None else \
            _scaled(_ratio(func, width), a)
        return [_square_at_most(t, square_bound), _between(t, _n(0), a),
                _between(t, a, nearer)]
    return facts


def _exp(a: E.Expr, t: E.Expr, reach) -> list[L.Formula]:
    facts = [L.Compare(">", t, _n(0)), _at_most(E.add(_n(1), a), t)]
    if reach is not None and reach[0] < reach[1]:
        facts.append(_at_most(t, _chord(a, *reach)))
    return facts


# t = f(a) -> its facts, given (lo, hi) with lo <= a <= hi wherever the query holds, or
# None; a function not here becomes a variable with no fact
FACTS = {"sin": _sin, "cos": _cos, "tanh": _sigmoid("tanh", Fraction(1)),
         "atan": _sigmoid("atan", Fraction("2.4675")), "exp": _exp}


def _width(reach) -> Fraction | None:
    """max |a| over the range, or None where none is known (or it is only 0)."""
    width = None if reach is None else max(-reach[0], reach[1])
    return width if width else None


def _square_at_most(t: E.Expr, bound) -> L.Formula:
    return _at_most(E.power(t, _n(2)), _n(bound))


def _scaled(ratio, a: E.Expr) -> E.Expr:
    """k a for a rational k just below the arb ratio."""
    return E.mul(_n(lower(ratio)), a)


def _one_minus(share: Fraction, a: E.Expr) -> E.Expr:
    return E.add(_n(1), E.neg(E.mul(_n(share), E.power(a, _n(2)))))


def _chord(a: E.Expr, lo: Fraction, hi: Fraction) -> E.Expr:
    at_lo, at_hi = upper(arb(lo).exp()), upper(arb(hi).exp())
    slope = (at_hi - at_lo) / (hi - lo)
    return E.add(_n(at_lo), E.mul(_n(slope), E.add(a, _n(-lo))))


def _sin_ratio(width: Fraction):
    return arb(width).sin() / arb(width)


def _cosine_ratio(width: Fraction):
    return (1 - arb(width).cos()) / arb(width) ** 2


def _ratio(func: str, width: Fraction):
    return getattr(arb(width), func)() / arb(width)


def replaceable(node: E.Expr) -> bool:
    """A function application that becomes a variable (abs stays: solvers encode it)."""
    return isinstance(node, E.Apply) and node.func != "abs"


def has_atoms(query: L.Formula) -> bool:
    return any(replaceable(node) for c in L.comparisons(query)
               for side in (c.left, c.right) for node in E.walk(side))


def abstracted(query: L.Formula, states: Sequence[str]) -> tuple[L.Formula, tuple[str, ...]]:
    """The polynomial query (the module's text) and its variables: the states, then one
    per distinct function application, named in the order they are first met."""
    table = _Table()
    body = L.map_comparisons(query, lambda c: L.Compare(
        c.relation, _replaced(c.left, table), _replaced(c.right, table)))
    return (L.conjunction(body, *_facts(table, _Ranges(query))),
            tuple(states) + tuple(table.names.values()))


def abstracted_terms(terms: Sequence[E.Expr], region: L.Formula, states: Sequence[str]
                     ) -> tuple[list[E.Expr], list[L.Formula], tuple[str, ...]] | None:
    """The terms with a variable per function application (shared as in `abstracted`),
    the facts those variables satisfy wherever `region` holds (ranges from its
    conjuncts), and the variables: the states, then the new ones. None where a function
    has no facts (log, sqrt: a variable alone says nothing)."""
    table = _Table()
    rewritten = [_replaced(term, table) for term in terms]
    if any(func not in FACTS for func, _ in table.names):
        return None
    return rewritten, _facts(table, _Ranges(region)), tuple(states) + tuple(table.names.values())


def argument_range(query: L.Formula, argument: E.Expr) -> tuple[Fraction, Fraction] | None:
    """Exact bounds of a polynomial argument wherever the query holds (from its
    conjuncts, as for the facts), or None."""
    return _Ranges(query).of(argument)


def _facts(table: "_Table", ranges: "_Ranges") -> list[L.Formula]:
    """The facts of every application in the table that has any."""
    return [fact for (func, argument), name in table.names.items() if func in FACTS
            for fact in FACTS[func](argument, E.Var(name), ranges.of(argument))]


class _Ranges:
    """Exact bounds of polynomial arguments over the box the query's conjuncts give
    their variables: the box that bounds all of the query's variables at once (a ball in
    every state), found once, else one on the argument's variables alone."""

    def __init__(self, query: L.Formula):
        self.query = query
        self.everything = sorted(v for v in L.free_vars(query)
                                 if not v.startswith(ATOM_PREFIX))
        self.whole = starting_box(query, self.everything)
        self.ellipsoids = ellipsoids(query, self.everything)
        self.quadratic = quadratic_ellipsoids(query, self.everything)

    def of(self, argument: E.Expr) -> tuple[Fraction, Fraction] | None:
        """None for an argument with a replaced function in it, or an unbounded one."""
        names = sorted(E.free_vars(argument))
        if not names or any(name.startswith(ATOM_PREFIX) for name in names):
            return None
        box = self._box(names)
        if box is None:
            return None
        try:
            polynomial = P.polynomial(argument, names)
        except ValueError:
            return None
        low = high = Fraction(0)
        for monomial, coefficient in polynomial.items():
            lo, hi = _monomial_range(monomial, [(Fraction(a), Fraction(b)) for a, b in box])
            ends = (coefficient * lo, coefficient * hi)
            low, high = low + min(ends), high + max(ends)
        reaches = [_linear_reach(polynomial, names, *e) for e in self.ellipsoids] + \
            [_reach_on_quadratic(polynomial, names, *e) for e in self.quadratic]
        for reach in reaches:
            if reach is not None:
                low, high = max(low, reach[0]), min(high, reach[1])
        return low, high

    def _box(self, names: list[str]):
        if self.whole is not None:
            return [self.whole[self.everything.index(name)] for name in names]
        return starting_box(self.query, names)


def _linear_reach(polynomial, names, scales: dict, centre: dict, radius: Fraction):
    """The range of a linear polynomial over the ellipsoid sum a_i (x_i - c_i)^2 <= R
    (its variables among the x_i): d + sum b_i c_i -+ sqrt(R sum b_i^2 / a_i), the
    square root rounded up; None for another polynomial. On a ball a linear argument
    such as x1 - x2 reaches sqrt(2) r, not the 2 r of the ball's box (a 5-state ring
    of sines: the facts from the box left the decrease unrefuted beyond |x| = 0.4)."""
    if any(sum(m) > 1 for m in polynomial) or not set(names) <= set(scales):
        return None
    zero = (0,) * len(names)
    slopes = {names[m.index(1)]: b for m, b in polynomial.items() if m != zero}
    middle = polynomial.get(zero, Fraction(0)) + sum(b * centre[v] for v, b in slopes.items())
    width = Fraction(sqrt_up(radius * sum(b * b / scales[v] for v, b in slopes.items())))
    return middle - width, middle + width


def _reach_on_quadratic(polynomial, names, used, inverse, centre, radius: Fraction):
    """The range of a linear polynomial over (x - c)^T A (x - c) <= R (its variables among
    the ellipsoid's): d + b^T c -+ sqrt(R b^T A^-1 b), the root rounded up; None for
    another polynomial. A controller's tanh(-K x) on a quadratic V's sublevel set reaches
    sqrt(R K A^-1 K^T), where the box of the set's per-variable bounds gave sum |K_i|
    times each reach (probe58/ab04: 0.8 against 2.1, and tanh's sector below 0.5)."""
    if any(sum(m) > 1 for m in polynomial) or not set(names) <= set(used):
        return None
    zero = (0,) * len(names)
    row = {v: i for i, v in enumerate(used)}
    slopes = [Fraction(0)] * len(used)
    for monomial, coefficient in polynomial.items():
        if monomial != zero:
            slopes[row[names[monomial.index(1)]]] = Fraction(coefficient)
    n = len(used)
    middle = polynomial.get(zero, Fraction(0)) + sum(b * c for b, c in zip(slopes, centre))
    spread = sum(slopes[i] * inverse[i][j] * slopes[j] for i in range(n) for j in range(n))
    width = Fraction(sqrt_up(radius * spread))
    return middle - width, middle + width


def _monomial_range(monomial, box) -> tuple[Fraction, Fraction]:
    low = high = Fraction(1)
    for power, (lo, hi) in zip(monomial, box):
        for _ in range(power):
            ends = (low * lo, low * hi, high * lo, high * hi)
            low, high = min(ends), max(ends)
    return low, high


class _Table:
    def __init__(self):
        self.names: dict[tuple[str, E.Expr], str] = {}

    def variable(self, func: str, argument: E.Expr) -> E.Var:
        key = (func, argument)
        if key not in self.names:
            self.names[key] = f"{ATOM_PREFIX}{func}{len(self.names)}"
        return E.Var(self.names[key])


def _replaced(expr: E.Expr, table: _Table) -> E.Expr:
    """Innermost applications first, so an argument is itself polynomial."""
    if isinstance(expr, (E.Num, E.Var, E.Pi)):
        return expr
    if replaceable(expr):
        return table.variable(expr.func, _replaced(expr.arg, table))
    return traversal.rebuild(expr, tuple(_replaced(c, table) for c in E.children(expr)))
