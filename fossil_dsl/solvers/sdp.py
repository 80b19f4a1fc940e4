"""Semidefinite programs over polynomial identities, solved by Clarabel: Gram blocks
(positive semidefinite matrices G, each standing for m(x)^T G m(x) times a polynomial),
scalars, one identity whose every coefficient must vanish, linear equalities and
inequalities, and a linear objective.

Clarabel is used directly rather than through a modelling layer: cvxpy and the solvers
it requires (SCS, OSQP, HiGHS) add 230 MB to the install, Clarabel alone 3 MB.
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from fossil_dsl.ir import polynomials as P


class Program:
    """Gram blocks, scalars, polynomial identities (every coefficient zero; terms go to
    the current one, `new_identity` starts the next), linear equalities and
    inequalities, a linear objective; solved by Clarabel."""

    def __init__(self, n: int):
        self.n = n
        self.count = 0  # variables
        self.blocks: list[tuple[int, list[P.Monomial]]] = []  # (first variable, basis)
        self.tag = 0  # which identity terms are added to
        self.identity: dict[tuple[int, P.Monomial], dict[int, float]] = {}
        self.constant: dict[tuple[int, P.Monomial], float] = {}
        self.equalities: list[tuple[dict[int, float], float]] = []
        self.at_most: list[tuple[dict[int, float], float]] = []  # coefficients . x <= bound

    def gram(self, basis: list[P.Monomial], times: P.Polynomial | None = None,
             in_identity: bool = True):
        """A PSD block G over the basis, adding (m^T G m) * times to the identity (unless
        not `in_identity`); returns [(variable, i, j)] for its upper triangle, column by
        column."""
        times = times or P.constant(1, self.n)
        self.blocks.append((self.count, basis))
        entries = []
        for j in range(len(basis)):
            for i in range(j + 1):
                if in_identity:
                    product = {P.times(basis[i], basis[j]): Fraction(1 if i == j else 2)}
                    self.add_term(self.count, P.multiply(product, times))
                entries.append((self.count, i, j))
                self.count += 1
        return entries

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

    def solve(self, objective: dict[int, float], seconds: float):
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
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.time_limit = max(0.1, seconds)
        solution = clarabel.DefaultSolver(sparse.csc_matrix((self.count, self.count)), q, A,
                                          np.array(right), cones, settings).solve()
        if str(solution.status) not in ("Solved", "AlmostSolved"):
            return None
        return np.array(solution.x)

    def matrix(self, x, entries, size: int) -> np.ndarray:
        G = np.zeros((size, size))
        for variable, i, j in entries:
            G[i, j] = G[j, i] = x[variable]
        return G
