"""The reach programs of sos_reach.py: V's conditions (see its text) as Positivstellensatz
identities on the pieces of reach_pieces.py, for a field in polynomial form
(polynomial_field.py): N / Q with Q > 0 on D, and for a system with sin, tanh, exp, ... a
variable per function application, bounded by the facts it satisfies on D. V is over the
states only; its decrease is then asked for every value the facts allow, so a V found
decreases for the true system (for a map, V(f(x)) with tanh's value t in place of
tanh(a) is a polynomial in x and t), not only for a fitted stand-in. A field with cells
(polynomial_field.celled_field) has the decrease asked on each cell, with its facts.
"""
from __future__ import annotations

from fractions import Fraction

from fossil_dsl.engine.polynomial_field import PolynomialField, padded, widened
from fossil_dsl.engine.reach_pieces import Pieces
from fossil_dsl.engine.sos import rounded
from fossil_dsl.ir import polynomials as P
from fossil_dsl.plan.certificates.rwa import GAMMA
from fossil_dsl.solvers.gram_rounding import decimal
from fossil_dsl.solvers.sdp import Program

DECIMALS = 6  # kept of V's coefficients
# |coefficient| of V at most this: γ is absolute, so V must be free to be steep (a
# quadratic that holds I far out and decreases by γ at G's edge needs entries above 1)
BOUND = 100.0


class ReachProgram(Program):
    def __init__(self, states: int, field: PolynomialField, pieces: Pieces, half: int,
                 discrete: bool, rate: float = 0.0, bound: float = BOUND):
        n = field.variables
        super().__init__(n, searches=True)
        self.states = states
        self.basis = [widened(m, n) for m in P.monomials(states, 0, 2 * half)]
        self.coefficients = self.unknown_polynomial(self.basis, bound)
        self.margin = self.scalar()
        self.at_most.append(({self.margin: 1.0}, 1.0))
        terms = [{m: Fraction(1)} for m in self.basis]
        negated = [(v, P.scale(t, -1)) for v, t in zip(self.coefficients, terms)]
        for piece in pieces.initial:
            self.require(negated, piece)
        for piece in pieces.boundary:
            self.require(list(zip(self.coefficients, terms)), piece)
        # grad V . N <= -γ Q, that is dV/dt <= -γ (for a map V(f(x)) - V(x) <= -γ); with
        # a rate λ, grad V . N <= (λ V - γ) Q: the same where V <= 0
        growth = Fraction(rate).limit_denominator(1000)
        denominator = padded([field.denominator], n)[0]
        decrease = [(v, P.add(P.scale(P.change(t, field.numerators, discrete), -1),
                              P.scale(P.multiply(t, denominator), growth)))
                    for v, t in zip(self.coefficients, terms)]
        stay = pieces.stay
        for piece in pieces.outside_goal if stay is None else stay.decrease:
            for region in field.regions(piece):
                self.require(decrease, piece + region, P.scale(denominator, -GAMMA))
        self.beta = None
        if stay is not None:  # V - β > 0 on F outside the outer ball, < 0 on the inner
            self.beta = self.scalar()
            self.at_most += [({self.beta: 1.0}, bound), ({self.beta: -1.0}, bound)]
            one = P.constant(1, n)
            above = list(zip(self.coefficients, terms)) + [(self.beta, P.scale(one, -1))]
            for piece in stay.above:
                self.require(above, piece)
            self.require(negated + [(self.beta, one)], stay.inner)
            if discrete:  # and V(f(x)) < β there: a step from the inner ball stays below β
                image = [(v, P.scale(P.compose(t, field.numerators), -1))
                         for v, t in zip(self.coefficients, terms)]
                for region in field.regions(stay.inner):
                    self.require(image + [(self.beta, one)], stay.inner + region)

    def levels(self, x) -> dict:
        """β (RSWA) as a short decimal, else nothing."""
        return {} if self.beta is None else {"beta": decimal(x[self.beta], DECIMALS)}

    def require(self, terms, constraints, constant=None) -> None:
        """sum of terms (+ constant) - e >= 0 on the piece (given over the states, or over
        all the variables where it holds the facts)."""
        self.require_nonnegative(terms, padded(constraints, self.n),
                                 (self.margin, P.constant(1, self.n)), constant)

    def exact_v(self, x) -> P.Polynomial:
        """V over the states."""
        return {m[:self.states]: c for m, c in
                rounded(x, self.basis, self.coefficients, DECIMALS).items()}
