"""Discharging one obligation with a sound procedure.

- A query whose comparisons are between numbers is decided by exact rational arithmetic.
- A query with a sum-of-squares refutation (positivstellensatz.py) that checks exactly
  (a polynomial identity and positive semidefinite Gram matrices, in rationals) is proved.
- Arithmetic queries (polynomials, division, integer powers, abs) go to Z3 on exact
  rationals, then to a sum-of-squares refutation (found by a semidefinite program, then
  checked exactly; first from 6 states on), then to the interval procedure, then to
  CVC5, each with a share of the time
  (a hard nonlinear query can stall Z3 and CVC5 for minutes where the interval
  procedure refutes it in seconds; a `first` procedure, the one that proved the
  condition during the run, goes first: only the order changes). Irrational constants
  (pi, sqrt(2)) are replaced by variables bounded by an outward-rounded enclosure, so an
  UNSAT holds for the true constant too.
- Other queries go to the interval procedure (codac contractors and bisection on
  outward-rounded arithmetic, every elementary function checked against mpmath by the
  tests) and to a sum-of-squares refutation of their polynomial form (a variable per
  function application, with facts its value satisfies: solvers/atom_facts.py), which
  goes first from ATOMS_REFUTATION_FIRST states on or where it proved the condition
  during the run. Only UNSAT is used from either; a box the interval procedure cannot
  refute is "not proved", never a proof. Where the refutation of the whole query fails
  and the query leaves out a ball round the origin, the query is proved in two pieces
  that cover every point: within a ball |x| <= R by a refutation, beyond it by the
  interval procedure (solvers/ball_split.py).

Whatever a procedure says other than UNSAT (a counterexample, delta-SAT, UNKNOWN, a
timeout) leaves the obligation unproved.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace
from enum import Enum
from fractions import Fraction
from typing import Sequence

from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.atoms import folded
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.kernel.obligations import Obligation
from fossil_dsl.solvers import ball_split
from fossil_dsl.solvers.arb_box import starting_box
from fossil_dsl.solvers.positivstellensatz import BEFORE_Z3_FROM, refutation_problem
from fossil_dsl.solvers.api import Answer, Status


class Outcome(Enum):
    PROVED = "proved"
    FAILS = "fails"  # a point where the fact is false
    NOT_PROVED = "not proved"  # undecided: UNKNOWN, timeout, or a delta-SAT box


@dataclass(frozen=True)
class Proof:
    obligation: Obligation
    outcome: Outcome
    procedure: str
    detail: str = ""
    witness: tuple[Fraction, ...] | None = None
    evidence: object = None  # the sum-of-squares refutation that proved it, if one did

    @property
    def proved(self) -> bool:
        return self.outcome is Outcome.PROVED


def is_arithmetic(formula: L.Formula) -> bool:
    return all(traversal.is_arithmetic(side) for c in L.comparisons(formula)
               for side in (c.left, c.right))


SUM_OF_SQUARES = "sum of squares (exact)"
GIVEN_REFUTATION = "the refutation handed over with the claim"  # (not one found here)
# Shares of an arithmetic obligation's time: Z3, a sum-of-squares refutation (checked
# exactly; for conjunctions of polynomial comparisons), the interval procedure, CVC5.
# Time a procedure leaves unused (it gave up early) goes to those after it, in these
# proportions. The refutation's share is 0.2: probe43/x06's rational decrease takes Z3
# over 60 s and the refutation 6 s.
SHARES = {"z3": 0.3, SUM_OF_SQUARES: 0.2, "interval": 0.3, "cvc5": 0.2}
# a query with elementary functions: the share of its time for a refutation of its
# polynomial form, tried before the interval procedure from this many states on (where
# bisection slows down: a 4-state pendulum's decrease, 118 s unproved by bisection,
# 0.02 s by the refutation), after it below
ATOMS_REFUTATION_SHARE = 0.2
ATOMS_REFUTATION_FIRST = 3
# a query within a box at most this wide goes to bisection first in any case: its
# enclosures are tight from the first box (the local lemma's bounds on third derivatives
# over |x| <= 1/100 in 5 states: 20 refutations took 5 s, bisection a tenth of that)
SMALL_BOX = 0.1
INTERVAL_FIRST_DEGREE = 7  # from this degree on, the interval procedure goes before Z3
INTERVAL_FIRST_STATES = 3  # (in up to this many states, where bisection is quick)


def discharge(obligation: Obligation, states: Sequence[str], timeout: float,
              delta: float | None = None, first: str = "", refutation=None,
              pieces=None) -> Proof:
    """`pieces`, if given, checks queries in parallel (cluster/pieces.py): the interval
    procedure then splits the query into a cover (kernel/cover.py)."""
    query = obligation.query
    exact = L.truth(folded(query, states))
    if exact is not None:
        outcome = Outcome.FAILS if exact else Outcome.PROVED
        return Proof(obligation, outcome, "exact arithmetic")
    if refutation is not None and refutation_problem(refutation, query, states) is None:
        return Proof(obligation, Outcome.PROVED, SUM_OF_SQUARES, GIVEN_REFUTATION,
                     evidence=refutation)
    if is_arithmetic(query):
        return _arithmetic(obligation, states, timeout, delta, first, pieces)
    return _transcendental(obligation, states, timeout, delta, first, pieces)


def _transcendental(obligation: Obligation, states, timeout: float, delta, first: str,
                    pieces) -> Proof:
    refutation_first = first == SUM_OF_SQUARES or (len(states) >= ATOMS_REFUTATION_FIRST
                                                   and not _small(obligation.query, states))
    share = ATOMS_REFUTATION_SHARE * timeout
    if refutation_first:
        answer = _solver(SUM_OF_SQUARES).check(obligation.query, states, max(1.0, share))
        if answer.status is Status.UNSAT:
            return Proof(obligation, Outcome.PROVED, SUM_OF_SQUARES, evidence=answer.evidence)
        split = _split_at_ball(obligation, states, timeout - share, delta, pieces) \
            if ball_split.excluded_radius(obligation.query, states) is not None else None
        if split is not None:
            return split
    proof = _interval(obligation, states, timeout - share, delta, pieces)
    if proof.proved or refutation_first:
        return proof
    answer = _solver(SUM_OF_SQUARES).check(obligation.query, states, max(1.0, share))
    if answer.status is Status.UNSAT:
        return Proof(obligation, Outcome.PROVED, SUM_OF_SQUARES, evidence=answer.evidence)
    return proof


def _small(query: L.Formula, states) -> bool:
    box = starting_box(query, list(states))
    return box is not None and max(hi - lo for lo, hi in box) <= SMALL_BOX


def _split_at_ball(obligation: Obligation, states, timeout: float, delta,
                   pieces) -> Proof | None:
    """The query refuted within a ball round the origin by a sum-of-squares refutation
    and beyond it by the interval procedure (solvers/ball_split.py: the two pieces cover
    every point); None where no ball's refutation is found (nothing else is tried)."""
    started = time.monotonic()
    beyond, found = ball_split.split_query(obligation.query, states,
                                           started + ball_split.SEARCH_SHARE * timeout)
    if found is None:
        return None
    # the piece beyond the ball stays away from the origin: nothing holds there
    piece = replace(obligation, query=beyond, closure_holds=False)
    proof = _interval(piece, states, timeout - (time.monotonic() - started), delta, pieces)
    procedure = f"{SUM_OF_SQUARES} within |x| <= {found.radius}, {proof.procedure} beyond"
    return replace(proof, obligation=obligation, procedure=procedure,
                   evidence=replace(found, procedure=proof.procedure) if proof.proved else None)


def _arithmetic(obligation: Obligation, states, timeout: float, delta, first: str,
                pieces) -> Proof:
    early = len(states) >= BEFORE_Z3_FROM  # the refutation before Z3
    first = "interval" if first == "taylor" else first  # (which tries Taylor forms first)
    # Z3 stalls for its whole share on polynomials of high degree (a degree-8 V shaped
    # to a basin: 18 s per condition) where the interval procedure answers in seconds
    high = bisection_first(obligation.query, states)
    order = sorted(SHARES, key=lambda name: (name != first,
                                             not (high and name == "interval"),
                                             not (early and name == SUM_OF_SQUARES)))
    reasons = []
    ends = time.monotonic() + timeout
    for index, name in enumerate(order):
        left = sum(SHARES[later] for later in order[index:])
        budget = max(1.0, SHARES[name] / left * (ends - time.monotonic()))
        if name == "interval":
            proof = _interval(obligation, states, budget, delta, pieces)
            if proof.proved:
                return proof
            reasons.append(f"interval: {proof.detail}")
            continue
        answer = _solver(name).check(obligation.query, states, budget)
        if answer.status is Status.UNSAT:
            return Proof(obligation, Outcome.PROVED, name, evidence=answer.evidence)
        if answer.status is Status.SAT and not answer.approximate:
            return Proof(obligation, Outcome.FAILS, name, "counterexample",
                         _point(answer, states))
        reasons.append(f"{name}: {_reason(answer)}")
    return Proof(obligation, Outcome.NOT_PROVED, ", ".join(order), "; ".join(reasons))


def bisection_first(query: L.Formula, states) -> bool:
    """Whether a bisection procedure should go before Z3: a polynomial of high degree in
    few states."""
    return _degree(query, states) >= INTERVAL_FIRST_DEGREE


def _degree(query: L.Formula, states) -> int:
    """The largest degree of a polynomial side of the query's comparisons (0 if none is
    a polynomial of few states)."""
    if len(states) > INTERVAL_FIRST_STATES:
        return 0
    degrees = [0]
    for comparison in L.comparisons(query):
        for side in (comparison.left, comparison.right):
            try:
                degrees.append(P.degree(P.polynomial(side, states)))
            except (P.NotPolynomial, E.ExprError, ValueError, ZeroDivisionError):
                continue
    return max(degrees)


def _solver(name: str):
    from fossil_dsl.solvers.cvc5_backend import Cvc5Backend
    from fossil_dsl.solvers.sos_refutation import SosBackend
    from fossil_dsl.solvers.z3_backend import Z3Backend
    return {"z3": Z3Backend, "cvc5": Cvc5Backend, SUM_OF_SQUARES: SosBackend}[name]()


def _interval(obligation: Obligation, states, timeout: float, delta, pieces=None) -> Proof:
    from fossil_dsl.solvers.interval_backend import IntervalBackend
    if obligation.closure_holds:
        return Proof(obligation, Outcome.NOT_PROVED, "interval",
                     "the query's closure holds at the origin: not tried")
    split = _split(obligation, states, timeout, delta, pieces) if pieces else None
    if split is not None:
        return split
    backend = IntervalBackend(delta) if delta else IntervalBackend()
    answer = backend.check(obligation.query, states, timeout)
    if answer.status is Status.UNSAT:  # by codac, or by the Taylor forms it tries first
        return Proof(obligation, Outcome.PROVED, answer.solver or "interval")
    return Proof(obligation, Outcome.NOT_PROVED, "interval", _reason(answer),
                 _point(answer, states))


def _split(obligation: Obligation, states, timeout: float, delta, pieces) -> Proof | None:
    """The interval procedure on the pieces of a checked cover, in parallel; None where
    the query has no bounded hull to split (the one search then decides)."""
    from fossil_dsl.kernel import cover
    names = [s for s in states if s in L.free_vars(obligation.query)]
    split = cover.check_split(obligation.query, names, pieces, timeout, delta)
    if split is None:
        return None
    procedure = f"interval, split into {split.pieces} pieces"
    if split.answer.status is Status.UNSAT:
        return Proof(obligation, Outcome.PROVED, procedure)
    return Proof(obligation, Outcome.NOT_PROVED, procedure, _reason(split.answer),
                 _point(split.answer, states))


def _point(answer: Answer, states) -> tuple[Fraction, ...] | None:
    if not answer.model:
        return None
    return tuple(Fraction(answer.model.get(s, 0)) for s in states)


def _reason(answer: Answer) -> str:
    if answer.status is Status.SAT:
        return answer.reason or "a solution whose coordinates are only approximate"
    return answer.reason or answer.status.value
