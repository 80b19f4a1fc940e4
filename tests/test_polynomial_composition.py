"""P.compose (p(f(x)), exact) against sympy's substitution, on random polynomials and
maps: the images of monomials are kept between calls (the programs compose every basis
monomial with the same map), so a second call with another map must not reuse them."""
from fractions import Fraction

import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.ir import polynomials as P

N = 2
SYMBOLS = sympy.symbols("x0 x1")
coefficients = st.fractions(min_value=-3, max_value=3, max_denominator=4)
monomial = st.tuples(*[st.integers(0, 2)] * N)
polynomial = st.dictionaries(monomial, coefficients.filter(bool), max_size=4)


def as_sympy(p) -> sympy.Expr:
    return sum((sympy.Rational(c.numerator, c.denominator)
                * sympy.Mul(*[s ** k for s, k in zip(SYMBOLS, m)]) for m, c in p.items()),
               sympy.Integer(0))


@settings(max_examples=60, deadline=None)
@given(polynomial, st.lists(st.tuples(polynomial, polynomial), min_size=1, max_size=3))
def test_composition_matches_substitution_map_after_map(p, maps):
    for field in maps:
        composed = P.compose(p, list(field))
        expected = as_sympy(p).subs(dict(zip(SYMBOLS, map(as_sympy, field))),
                                    simultaneous=True)
        assert sympy.expand(as_sympy(composed) - expected) == 0
        assert all(isinstance(c, Fraction) and c for c in composed.values())


def test_a_composed_polynomial_is_not_aliased_to_the_kept_images():
    field = [{(1, 0): Fraction(1, 2)}, {(0, 1): Fraction(1), (2, 0): Fraction(1)}]
    first = P.compose({(0, 1): Fraction(1)}, field)
    first[(0, 1)] = Fraction(7)
    again = P.compose({(0, 1): Fraction(1)}, field)
    assert again == {(0, 1): Fraction(1), (2, 0): Fraction(1)}
