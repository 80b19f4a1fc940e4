"""The counterexample-guided loop: learn on samples, round to exact rationals, verify
every condition, add counterexamples (and their neighbourhoods) to the samples, repeat.

"Certified" is returned only when every condition's query was UNSAT for the exact
formulas that are returned with it.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Callable

from fossil_dsl.engine.course import AFTER_A_FAILURE, failed, stalled, undecided_again
from fossil_dsl.engine.falsify import Falsifier
from fossil_dsl.engine.given import GivenFunctions, verifier_only
from fossil_dsl.plan.certificates.base import change_of, level_of, next_value, value_of, \
    velocity_of
from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import traversal
from fossil_dsl.ir import logic as L
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir.atoms import folded
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.ir.numbers import rational
from fossil_dsl.plan.compile import Plan
from fossil_dsl.solvers import registry
from fossil_dsl.solvers.api import Answer, Backend, Status


@dataclass(frozen=True)
class Verdict:
    condition: str
    status: Status
    reason: str = ""
    counterexample: tuple | None = None
    solver: str = ""  # which solver answered (where the backend combines several)


@dataclass(frozen=True)
class IterationRecord:
    iteration: int
    loss: float
    verdicts: tuple[Verdict, ...]
    learn_seconds: float
    verify_seconds: float

    @property
    def failed(self) -> list[str]:
        return [v.condition for v in self.verdicts if v.status is not Status.UNSAT]


@dataclass
class CegisState:
    """Everything the loop carries from one iteration to the next."""

    iteration: int = 0
    learn_seconds: float = 0.0
    verify_seconds: float = 0.0
    history: list[IterationRecord] = field(default_factory=list)
    last_verified: tuple | None = None  # (candidate, queries, verdicts) of the last iteration


@dataclass(frozen=True)
class ExactCandidate:
    """What is verified: exact formulas for every function and the controller, each
    function's change along the closed loop, and the levels as rationals."""

    formulas: dict[str, E.Expr]
    changes: dict[str, E.Expr]
    controller: dict[str, E.Expr]  # input name -> k_i(x)
    levels: dict[str, Fraction]
    digits: int  # decimals kept when the weights were rounded
    next_state: dict[str, E.Expr] = field(default_factory=dict)  # discrete: state -> f(x)
    velocity: dict[str, E.Expr] = field(default_factory=dict)  # continuous: state -> f(x)

    def mapping(self) -> dict[str, E.Expr]:
        found = {next_value(s).name: f for s, f in self.next_state.items()}
        found.update({velocity_of(s).name: f for s, f in self.velocity.items()})
        found.update({value_of(n).name: f for n, f in self.formulas.items()})
        found.update({change_of(n).name: c for n, c in self.changes.items()})
        found.update({level_of(n).name: E.Num(v) for n, v in self.levels.items()})
        return found


@dataclass(frozen=True)
class CegisOutcome:
    certified: bool
    reason: str
    candidate: ExactCandidate
    queries: dict[str, L.Formula]  # condition name -> the query decided (substituted)
    verdicts: tuple[Verdict, ...]
    history: tuple[IterationRecord, ...]
    learn_seconds: float
    verify_seconds: float
    networks: dict  # name -> torch module (engine.networks.Network); none if given
    interrupted: bool = False  # stopped by Ctrl-C: what was found so far, nothing proved
    strategy: str = "learning"  # how the functions were found
    refutations: dict = field(default_factory=dict)  # obligation -> sum-of-squares evidence

    @property
    def formulas(self) -> dict[str, E.Expr]:
        return self.candidate.formulas


class Listener:
    """What the loop tells while it runs (the command line's live display, say). Override
    what you show; `progress=` of the API also takes a plain function of each record."""

    def start(self, plan: Plan) -> None:
        """Before the first iteration."""

    def phase(self, iteration: int, text: str) -> None:
        """The loop starts learning or verifying a condition (iteration 0: a step before
        the loop, such as the sum-of-squares attempt)."""

    def finished(self, record: IterationRecord) -> None:
        """An iteration has ended."""


class _RecordsOnly(Listener):
    def __init__(self, function: Callable[[IterationRecord], None]):
        self.function = function

    def finished(self, record: IterationRecord) -> None:
        self.function(record)


def as_listener(progress: Listener | Callable | None) -> Listener:
    if progress is None:
        return Listener()
    return progress if isinstance(progress, Listener) else _RecordsOnly(progress)


class Cegis:
    def __init__(self, plan: Plan, backend: Backend | None,
                 progress: Listener | Callable | None = None, deadline: float | None = None):
        self.plan = plan
        self.backend = backend
        self.listener = as_listener(progress)
        self.states = plan.states
        self.options = plan.options
        self.learner = GivenFunctions(plan) if verifier_only(plan) else self._learner()
        # runs that learn look for counterexamples numerically where the verifier is slow
        self.falsifier = None if isinstance(self.learner, GivenFunctions) else \
            Falsifier(self.states, plan.spec.domain.bounding_box(), self.options.seed,
                      registry.BACKENDS[plan.verifier].delta_decision)
        self.deadline = deadline or time.monotonic() + self.options.timeout

    def _learner(self):
        import torch  # only runs that learn import it
        from fossil_dsl.engine.learner import Learner
        torch.manual_seed(self.options.seed)
        return Learner(self.plan, torch.Generator().manual_seed(self.options.seed))

    @property
    def networks(self) -> dict:
        found = dict(self.learner.networks)
        if self.learner.controller is not None:
            found["k"] = self.learner.controller
        return found

    # ---- the loop ----
    def run(self) -> CegisOutcome:
        if isinstance(self.learner, GivenFunctions):
            return self._run()
        import torch
        # Batches are small: a thread pool only adds waiting, and under load (another
        # process, or parallel benchmark jobs) it made steps 30x slower (60 ms, not 2 ms).
        threads = torch.get_num_threads()
        torch.set_num_threads(1)
        try:
            return self._learn_only() if self.options.learn_only else self._run()
        finally:
            torch.set_num_threads(threads)

    def _run(self) -> CegisOutcome:
        state = CegisState()
        self.listener.start(self.plan)
        try:
            return self._iterate(state)
        except KeyboardInterrupt:  # Ctrl-C: what was found so far, nothing proved
            return self._interrupted(state)

    def _iterate(self, state: CegisState) -> CegisOutcome:
        reason = f"gave up after {self.options.max_iters} iterations"
        restarted = 0  # iterations before the last restart of the learner
        for state.iteration in range(1, self.options.max_iters + 1):
            self.listener.phase(state.iteration, "learning")
            loss, learn_seconds = self.learn(state)
            candidate = self.exact_candidate()
            if undecided_again(state.last_verified, candidate):
                self.learner.restart()
                restarted = len(state.history)
                loss, more = self.learn(state)
                learn_seconds, candidate = learn_seconds + more, self.exact_candidate()
            verdicts, queries, verify_seconds = self.verify(candidate, state.iteration)
            state.verify_seconds += verify_seconds
            state.last_verified = (candidate, queries, verdicts)
            record = IterationRecord(state.iteration, loss, verdicts, learn_seconds,
                                     verify_seconds)
            state.history.append(record)
            self.listener.finished(record)
            if all(v.status is Status.UNSAT for v in verdicts):
                return self.outcome(state, True, "every condition proved", candidate,
                                    queries, verdicts)
            if not self.learner.trainable:
                return self.outcome(state, False, failure_reason(verdicts), candidate,
                                    queries, verdicts)
            self.learn_from(verdicts)
            if stalled(state.history[restarted:]):  # stuck where it cannot meet them
                self.learner.restart()
                restarted = len(state.history)
            if time.monotonic() > self.deadline:
                reason = f"timeout after {self.options.timeout:g} s"
                break
        return self.outcome(state, False, reason, candidate, queries, verdicts)

    def _learn_only(self) -> CegisOutcome:
        state = CegisState(iteration=1)
        loss, learn_seconds = self.learn(state)
        import torch
        held_out = torch.Generator().manual_seed(self.options.seed + 1)
        rates = self.learner.violation_rates(held_out)
        verdicts = tuple(Verdict(name, Status.UNKNOWN, "not verified (learn-only): "
                                 f"{fails} of {total} fresh samples violate it")
                         for name, (fails, total) in rates.items())
        state.history.append(IterationRecord(1, loss, verdicts, learn_seconds, 0.0))
        return self.outcome(state, False, "learn-only: trained without verifying; nothing "
                            "was proved", self.exact_candidate(), {}, verdicts)

    def _interrupted(self, state: CegisState) -> CegisOutcome:
        """The last candidate verified, with its verdicts (or the networks as they are,
        if none was verified yet)."""
        candidate, queries, verdicts = state.last_verified or (self.exact_candidate(), {}, ())
        outcome = self.outcome(state, False, f"interrupted (Ctrl-C) in iteration "
                               f"{state.iteration}", candidate, queries, verdicts)
        return replace(outcome, interrupted=True)

    def outcome(self, state, certified, reason, candidate, queries, verdicts):
        return CegisOutcome(certified, reason, candidate, queries, tuple(verdicts),
                            tuple(state.history), state.learn_seconds, state.verify_seconds,
                            self.networks)

    def learn(self, state: CegisState) -> tuple[float, float]:
        started = time.monotonic()
        loss = 0.0
        if self.learner.trainable:
            loss = self.learner.train(self.options.learn_steps, self.deadline)
        elapsed = time.monotonic() - started
        state.learn_seconds += elapsed
        return loss, elapsed

    # ---- verification ----
    def exact_candidate(self) -> ExactCandidate:
        digits = self.learner.digits
        learner = self.learner
        formulas = {f.name: f.candidate if f.candidate is not None
                    else P.compact(learner.networks[f.name].formula(self.states, digits),
                                   self.states)
                    for f in self.plan.functions}
        controller = {}
        if learner.controller is not None:
            controller = dict(zip(self.plan.controller.inputs,
                                  learner.controller.formulas(self.states, digits)))
        closed_loop = tuple(traversal.substitute(f, controller) for f in self.plan.spec.dynamics)
        changes = {name: self.change(formula, closed_loop) for name, formula in formulas.items()}
        levels = {name: Fraction(learner.fixed_levels[name]) if name in learner.fixed_levels
                  else rational(value, digits) for name, value in learner.levels().items()}
        discrete = self.plan.spec.time is TimeDomain.DISCRETE
        next_state = dict(zip(self.states, closed_loop)) if discrete else {}
        velocity = {} if discrete else dict(zip(self.states, closed_loop))
        return ExactCandidate(formulas, changes, controller, levels, digits, next_state,
                              velocity)

    def change(self, formula: E.Expr, dynamics) -> E.Expr:
        discrete = self.plan.spec.time is TimeDomain.DISCRETE
        return calculus.change(formula, self.states, dynamics, discrete)

    def verify(self, candidate: ExactCandidate, iteration: int = 0):
        started = time.monotonic()
        mapping = candidate.mapping()
        verdicts, queries = [], {}
        total = len(self.plan.conditions)
        for number, condition in enumerate(self.plan.conditions, 1):
            self.listener.phase(iteration, f"verifying {condition.name} ({number}/{total})")
            query = L.substitute(self.plan.query(condition), mapping)
            queries[condition.name] = query
            budget = max(1.0, min(self.options.query_timeout, self.deadline - time.monotonic(),
                                  AFTER_A_FAILURE if failed(verdicts) else math.inf))
            answer = _decided(query, self.states) or self._checked(condition.name, query, budget)
            verdicts.append(_verdict(condition.name, answer, self.states, self.backend.name))
        return tuple(verdicts), queries, time.monotonic() - started

    def _checked(self, name: str, query: L.Formula, budget: float) -> Answer:
        def check(seconds: float) -> Answer:
            return self.backend.check(query, self.states, seconds)
        if self.falsifier is None:
            return check(budget)
        return self.falsifier.checked(name, query, budget, check)

    def learn_from(self, verdicts) -> None:
        for verdict in verdicts:
            # an undecided query may come with a lead: a point where it was not refuted
            if verdict.status is not Status.UNSAT and verdict.counterexample is not None:
                self.learner.add_counterexample(verdict.condition, verdict.counterexample)
            elif verdict.status is Status.UNKNOWN:  # learn something: more samples there
                self.learner.add_region_samples(verdict.condition)


def _decided(query: L.Formula, states) -> Answer | None:
    """UNSAT where comparisons whose sides differ by a number make the query false (a
    conserved B's dB/dt > 0 is 0 > 0, which a delta-decision procedure reads as
    satisfiable within its tolerance)."""
    return Answer(Status.UNSAT, solver="exact arithmetic") \
        if L.truth(folded(query, states)) is False else None


def _verdict(name: str, answer: Answer, states, backend: str) -> Verdict:
    """`backend` names the solver where the answer does not (a single procedure's): the
    kernel asks first the procedure that proved a condition in the loop (row12's
    polynomial barrier: 19 s in Z3's and CVC5's shares before the interval procedure)."""
    point = tuple(answer.model.get(s, 0) for s in states) if answer.model else None
    return Verdict(name, answer.status, answer.reason, point, answer.solver or backend)


def failure_reason(verdicts) -> str:
    failed = [v for v in verdicts if v.status is not Status.UNSAT]
    words = [f"{v.condition}: {'counterexample' if v.status is Status.SAT else v.reason or 'unknown'}"
             for v in failed]
    verb = "fails" if any(v.status is Status.SAT for v in failed) else "is not proved"
    return f"the given function {verb}: " + "; ".join(words)
