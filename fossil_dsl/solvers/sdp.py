"""Semidefinite programs over polynomial identities, solved by Clarabel: Gram blocks
(positive semidefinite matrices G, each standing for m(x)^T G m(x), or what an identity
makes of it), scalars, identities whose every coefficient must vanish, linear equalities
and inequalities, and a linear objective.

Clarabel is used directly rather than through a modelling layer: cvxpy and the solvers
it requires (SCS, OSQP, HiGHS) add 230 MB to the install, Clarabel alone 3 MB.
"""
from __future__ import annotations

import math
import time
from fractions import Fraction
from typing import Callable

import numpy as np

from fossil_dsl.ir import polynomials as P


# The sum over Gram blocks of (entries of the block's upper triangle)^3 that one of
# Clarabel's iterations gets through in a second, about: the dense block Hessians
# dominate. Measured on this machine (two runs beside): 1.4e9 (a 4-state quartic region
# of attraction, 0.19 s an iteration; a 3-state map's quartic reach program, 95 s for
# its first iteration) to 4.1e9 (a 5-state one, 1.1 s an iteration). Clarabel heeds its
# time limit only between iterations, and a solve takes 20 to 40 of them: a program is
# tried only where FEWEST_ITERATIONS of them fit in its time (the reach program above
# had been given 27 s and took 100 s).
CUBED_ENTRIES_PER_SECOND = 3e9
FEWEST_ITERATIONS = 10
# Clarabel's factorisations in turn: its default (faer here: multithreaded, the fastest
# by far on large programs, a 5-state quartic region of attraction in 37 s against
# qdldl's 214), then, where that stops with a numerical error, qdldl (the 3-state
# quartic of tests/test_sos_roa.py: faer's error, qdldl's solution in 0.7 s)
SOLVE_METHODS = ("auto", "qdldl")
# the second gets at most this times the first one's time: a program the first found
# hard in 20 s is not worth the rest of an attempt's budget (the next gain or degree is)
RETRY_SHARE = 2.0


class Program:
    """Gram blocks, scalars, polynomial identities (every coefficient zero; terms go to
    the current one, `new_identity` starts the next), linear equalities and
    inequalities, a linear objective; solved by Clarabel."""

    def __init__(self, n: int, searches: bool = False):
        self.n = n
        self.searches = searches  # for a certificate (see _retried_after)
        self.count = 0  # variables
        self.blocks: list[tuple[int, list[P.Monomial]]] = []  # (first variable, basis)
        self.tag = 0  # which identity terms are added to
        self.identity: dict[tuple[int, P.Monomial], dict[int, float]] = {}
        self.constant: dict[tuple[int, P.Monomial], float] = {}
        self.equalities: list[tuple[dict[int, float], float]] = []
        self.at_most: list[tuple[dict[int, float], float]] = []  # coefficients . x <= bound

    def gram(self, basis: list[P.Monomial], of: Callable[[P.Polynomial], P.Polynomial] = None,
             times: P.Polynomial | None = None, sign: int = 1):
        """A PSD block G over the basis, adding of(m^T G m) to the identity (`of` is linear:
        m^T G m itself by default, a derivative, nothing), or sign * m^T G m * times (a
        multiplier's product with a constraint, in floats: each entry's term is a shifted
        copy of `times`, which a product of Fractions built 20 times slower);
        returns [(variable, i, j)] for its upper triangle, column by column."""
        self.blocks.append((self.count, basis))
        rows = None if times is None else [(m, sign * float(c)) for m, c in times.items() if c]
        entries = []
        for j in range(len(basis)):
            for i in range(j + 1):
                monomial, weight = P.times(basis[i], basis[j]), 1 if i == j else 2
                if rows is None:
                    product = {monomial: Fraction(weight)}
                    self.add_term(self.count, of(product) if of else product)
                else:
                    self._add_shifted(self.count, monomial, weight, rows)
                entries.append((self.count, i, j))
                self.count += 1
        return entries

    def _add_shifted(self, variable: int, monomial: P.Monomial, weight: int, rows) -> None:
        """variable * weight * monomial * (the polynomial of `rows`) into the identity."""
        for m, c in rows:
            row = self.identity.setdefault((self.tag, P.times(monomial, m)), {})
            row[variable] = row.get(variable, 0.0) + weight * c

    def minus_certificate(self, half: int, constraints: list[P.Polynomial], low: int) -> None:
        """Subtracts s + sum_i sigma_i g_i from the identity (so that what it holds is
        >= 0 wherever every g_i >= 0): s over the monomials of degree low..half, sigma_i
        over low..room, where room keeps sigma_i g_i within degree 2 half."""
        self.gram(P.monomials(self.n, low, half), lambda p: P.scale(p, -1))
        for g in constraints:
            room = (2 * half - P.degree(g)) // 2
            if room >= low:
                self.gram(P.monomials(self.n, low, room), times=g, sign=-1)

    def require_nonnegative(self, terms, constraints: list[P.Polynomial],
                            margin: tuple[int, P.Polynomial], constant=None) -> None:
        """sum of variable * polynomial terms (+ constant) - margin variable * its
        polynomial = s + sum_i sigma_i g_i, as one identity: the left side is then >= 0
        wherever every g_i >= 0."""
        for variable, polynomial in terms:
            self.add_term(variable, polynomial)
        if constant:
            self.add_constant(constant)
        self.add_term(margin[0], P.scale(margin[1], -1))
        top = max([2, P.degree(constant or {}), P.degree(margin[1])]
                  + [P.degree(p) for _, p in terms] + [P.degree(g) for g in constraints])
        self.minus_certificate((top + 1) // 2, constraints, low=0)
        self.new_identity()

    def unknown_polynomial(self, basis: list[P.Monomial], bound: float) -> list[int]:
        """A scalar per monomial of the basis, each in [-bound, bound]: the coefficients
        of a polynomial the program looks for."""
        coefficients = [self.scalar() for _ in basis]
        for variable in coefficients:
            self.at_most += [({variable: 1.0}, bound), ({variable: -1.0}, bound)]
        return coefficients

    def scalar(self) -> int:
        self.count += 1
        return self.count - 1

    def new_identity(self) -> None:
        self.tag += 1

    def add_term(self, variable: int, polynomial: P.Polynomial) -> None:
        for monomial, coefficient in polynomial.items():
            row = self.identity.setdefault((self.tag, monomial), {})
            row[variable] = row.get(variable, 0.0) + float(coefficient)

    def add_constant(self, polynomial: P.Polynomial) -> None:
        for monomial, coefficient in polynomial.items():
            key = (self.tag, monomial)
            self.constant[key] = self.constant.get(key, 0.0) + float(coefficient)

    def too_costly(self, seconds: float) -> bool:
        """Whether the program would take much longer than `seconds` (Clarabel heeds its
        time limit only between iterations, and its setup not at all)."""
        cubed = sum(math.comb(len(basis) + 1, 2) ** 3 for _, basis in self.blocks)
        return FEWEST_ITERATIONS * cubed > seconds * CUBED_ENTRIES_PER_SECOND

    def solve(self, objective: dict[int, float], seconds: float):
        """The solution, or None: infeasible, unsolved in time, or too costly to try."""
        if self.too_costly(seconds):
            return None
        import clarabel
        from scipy import sparse
        rows, cols, values, right = [], [], [], []

        def row(coefficients: dict[int, float], value: float) -> None:
            for variable, coefficient in coefficients.items():
                rows.append(len(right)), cols.append(variable), values.append(coefficient)
            right.append(value)
        for key in sorted(set(self.identity) | set(self.constant)):
            row(self.identity.get(key, {}), -self.constant.get(key, 0.0))
        for coefficients, value in self.equalities:
            row(coefficients, value)
        cones = [clarabel.ZeroConeT(len(right))]
        for coefficients, bound in self.at_most:
            row(coefficients, bound)
        if self.at_most:
            cones.append(clarabel.NonnegativeConeT(len(self.at_most)))
        for first, basis in self.blocks:
            k = first
            for j in range(len(basis)):
                for i in range(j + 1):
                    row({k: -1.0 if i == j else -math.sqrt(2)}, 0.0)
                    k += 1
            cones.append(clarabel.PSDTriangleConeT(len(basis)))
        A = sparse.csc_matrix((values, (rows, cols)), shape=(len(right), self.count))
        q = np.zeros(self.count)
        for variable, weight in objective.items():
            q[variable] = weight
        limit = seconds
        for method in SOLVE_METHODS:
            settings = clarabel.DefaultSettings()
            settings.verbose = False
            settings.direct_solve_method = method
            settings.time_limit = max(0.1, limit)
            started = time.monotonic()
            solution = clarabel.DefaultSolver(sparse.csc_matrix((self.count, self.count)), q,
                                              A, np.array(right), cones, settings).solve()
            status = str(solution.status)
            if status not in self._retried_after():
                break
            spent = time.monotonic() - started
            # a stall is no sign of a hard program (ae03: faer stalled in 4 s, qdldl needs
            # 9 s, 14 s with a run beside it)
            limit = seconds - spent if status == "InsufficientProgress" else \
                min(seconds - spent, RETRY_SHARE * spent)
        if status not in ("Solved", "AlmostSolved"):
            return None
        return np.array(solution.x)

    def _retried_after(self) -> tuple[str, ...]:
        """The first method's statuses after which the next is tried: a program that
        searches for a certificate (a few per run) is retried where the first stalled too
        (probe60/ae03, a 4-state quartic region of attraction: faer's insufficient
        progress, qdldl's solution with margin 0.55); refutations, tried on many queries
        that have none, are not."""
        return ("NumericalError", "InsufficientProgress") if self.searches else \
            ("NumericalError",)

    def matrix(self, x, entries, size: int) -> np.ndarray:
        G = np.zeros((size, size))
        for variable, i, j in entries:
            G[i, j] = G[j, i] = x[variable]
        return G
