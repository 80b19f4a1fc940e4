"""The counterexample-guided loop: learn on samples, round to exact rationals, verify
every condition, add counterexamples (and their neighbourhoods) to the samples, repeat.

"Certified" is returned only when every condition's query was UNSAT for the exact
formulas that are returned with it.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import torch

from fossil_dsl.certificates.base import Condition, change_of, value_of
from fossil_dsl.ir import calculus
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import logic as L
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.learn.evaluate import evaluate, holds, state_env
from fossil_dsl.learn.networks import Network
from fossil_dsl.learn.sampling import around, sample
from fossil_dsl.plan import Plan
from fossil_dsl.smt.api import Answer, Backend, Status


@dataclass(frozen=True)
class Verdict:
    condition: str
    status: Status
    reason: str = ""
    counterexample: tuple | None = None


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

    samples: dict[str, torch.Tensor]  # condition name -> training points
    iteration: int = 0
    learn_seconds: float = 0.0
    verify_seconds: float = 0.0
    history: list[IterationRecord] = field(default_factory=list)


@dataclass(frozen=True)
class CegisOutcome:
    certified: bool
    reason: str
    formulas: dict[str, E.Expr]  # function name -> exact formula (as verified)
    changes: dict[str, E.Expr]  # function name -> its derivative / one-step difference
    queries: dict[str, L.Formula]  # condition name -> the query decided (substituted)
    verdicts: tuple[Verdict, ...]
    history: tuple[IterationRecord, ...]
    learn_seconds: float
    verify_seconds: float
    networks: dict[str, Network]


Progress = Callable[[IterationRecord], None]


class Cegis:
    def __init__(self, plan: Plan, backend: Backend, progress: Progress | None = None):
        self.plan = plan
        self.backend = backend
        self.progress = progress or (lambda record: None)
        self.states = plan.states
        self.options = plan.options
        torch.manual_seed(self.options.seed)
        self.generator = torch.Generator().manual_seed(self.options.seed)
        self.networks = {f.name: Network(len(self.states), f.layers, f.zero_at_origin)
                         for f in plan.functions if f.candidate is None}
        self.deadline = time.monotonic() + self.options.timeout

    # ---- the loop ----
    def run(self) -> CegisOutcome:
        # Batches are small: a thread pool only adds waiting, and under load (another
        # process, or parallel benchmark jobs) it made steps 30x slower (60 ms, not 2 ms).
        threads = torch.get_num_threads()
        torch.set_num_threads(1)
        try:
            return self._run()
        finally:
            torch.set_num_threads(threads)

    def _run(self) -> CegisOutcome:
        state = CegisState(self.initial_samples())
        optimiser = self._optimiser()
        reason = f"gave up after {self.options.max_iters} iterations"
        for state.iteration in range(1, self.options.max_iters + 1):
            loss, learn_seconds = self.learn(state, optimiser)
            formulas, changes = self.exact_formulas()
            verdicts, queries, verify_seconds = self.verify(formulas, changes)
            state.verify_seconds += verify_seconds
            record = IterationRecord(state.iteration, loss, verdicts, learn_seconds,
                                     verify_seconds)
            state.history.append(record)
            self.progress(record)
            if all(v.status is Status.UNSAT for v in verdicts):
                return self.outcome(state, True, "every condition proved", formulas,
                                    changes, queries, verdicts)
            if not self.networks:
                return self.outcome(state, False, _failure_reason(verdicts), formulas,
                                    changes, queries, verdicts)
            self.learn_from(verdicts, state)
            if time.monotonic() > self.deadline:
                reason = f"timeout after {self.options.timeout:g} s"
                break
        return self.outcome(state, False, reason, formulas, changes, queries, verdicts)

    def outcome(self, state, certified, reason, formulas, changes, queries, verdicts):
        return CegisOutcome(certified, reason, formulas, changes, queries, tuple(verdicts),
                            tuple(state.history), state.learn_seconds, state.verify_seconds,
                            self.networks)

    # ---- learning ----
    def initial_samples(self) -> dict[str, torch.Tensor]:
        by_role = {}
        for role, count in self.plan.samples.items():
            region = self._role_set(role)
            by_role[role] = sample(region, self.states, count, self.generator,
                                   self.plan.spec.domain.bounding_box())
        return {c.name: by_role[c.samples] for c in self.plan.conditions}

    def _role_set(self, role: str):
        return self.plan.spec.domain if role == "domain" else self.plan.spec.property.role(role)

    def _optimiser(self):
        self.parameters = [p for n in self.networks.values() for p in n.parameters()]
        if not self.parameters:
            return None
        return torch.optim.Adam(self.parameters, lr=self.options.learning_rate)

    def learn(self, state: CegisState, optimiser) -> tuple[float, float]:
        started = time.monotonic()
        loss_value = 0.0
        if optimiser is not None:
            for _ in range(self.options.learn_steps):
                loss, satisfied = self.loss(state.samples)
                loss_value = float(loss.detach())
                if satisfied or time.monotonic() > self.deadline:
                    break
                optimiser.zero_grad()
                loss.backward()
                _clip_gradients(self.parameters, 10.0)
                optimiser.step()
            for network in self.networks.values():
                network.round_weights(self.options.digits)
        elapsed = time.monotonic() - started
        state.learn_seconds += elapsed
        return loss_value, elapsed

    def loss(self, samples: dict[str, torch.Tensor]) -> tuple[torch.Tensor, bool]:
        total, satisfied = torch.zeros((), dtype=torch.float64), True
        for condition in self.plan.conditions:
            points = samples[condition.name]
            if condition.exclude_origin:
                points = points[points.norm(dim=1) > 1e-6]
            if len(points) == 0:
                continue
            term, ok = self.condition_loss(condition, points)
            total = total + term
            satisfied = satisfied and ok
        return total, satisfied

    def condition_loss(self, condition: Condition, points: torch.Tensor):
        points = points.clone().requires_grad_(True)
        env = state_env(self.states, points)
        env.update(self.values(points))
        violation = _violation(condition.claim, env)
        margin = self.options.margin
        if condition.scaled_margin:
            margin = margin * (points ** 2).sum(1)
        mask = self._guard_mask(condition.guard, env, len(points))
        shortfall = torch.relu(violation + margin)[mask]
        if len(shortfall) == 0:
            return torch.zeros((), dtype=torch.float64), True
        return shortfall.mean(), bool((shortfall == 0).all())

    def _guard_mask(self, guard: L.Formula, env, batch: int) -> torch.Tensor:
        if guard == L.TRUE:
            return torch.ones(batch, dtype=torch.bool)
        scale = max((float(v.detach().abs().mean()) for k, v in env.items()
                     if k.startswith("$") and isinstance(v, torch.Tensor)), default=1.0)
        return holds(guard, {k: v.detach() for k, v in env.items()}, batch, 0.1 * scale)

    def values(self, points: torch.Tensor) -> dict[str, torch.Tensor]:
        """Each network's value and its derivative (or one-step difference) at points."""
        result = {}
        field = self.field(points)
        for name, network in self.networks.items():
            value = network(points)
            if self.plan.spec.time is TimeDomain.DISCRETE:
                change = network(torch.stack(field, 1)) - value
            else:
                grad, = torch.autograd.grad(value.sum(), points, create_graph=True)
                change = sum(grad[:, i] * f for i, f in enumerate(field))
            result[value_of(name).name] = value
            result[change_of(name).name] = change
        return result

    def field(self, points: torch.Tensor) -> list[torch.Tensor]:
        env = state_env(self.states, points)
        return [torch.as_tensor(evaluate(f, env), dtype=torch.float64).expand(len(points))
                for f in self.plan.spec.dynamics]

    # ---- verification ----
    def exact_formulas(self) -> tuple[dict[str, E.Expr], dict[str, E.Expr]]:
        formulas = {f.name: f.candidate if f.candidate is not None
                    else self.networks[f.name].formula(self.states, self.options.digits)
                    for f in self.plan.functions}
        changes = {name: self.change(formula) for name, formula in formulas.items()}
        return formulas, changes

    def change(self, formula: E.Expr) -> E.Expr:
        dynamics = self.plan.spec.dynamics
        if self.plan.spec.time is TimeDomain.DISCRETE:
            return E.add(calculus.compose(formula, self.states, dynamics), E.neg(formula))
        return calculus.lie_derivative(formula, self.states, dynamics)

    def verify(self, formulas, changes):
        started = time.monotonic()
        mapping = {value_of(n).name: f for n, f in formulas.items()}
        mapping.update({change_of(n).name: c for n, c in changes.items()})
        verdicts, queries = [], {}
        for condition in self.plan.conditions:
            query = L.substitute(condition.query(self.states), mapping)
            queries[condition.name] = query
            budget = max(1.0, min(self.options.query_timeout, self.deadline - time.monotonic()))
            answer = self.backend.check(query, self.states, budget)
            verdicts.append(_verdict(condition.name, answer, self.states))
        return tuple(verdicts), queries, time.monotonic() - started

    def learn_from(self, verdicts, state: CegisState) -> None:
        scale = _box_scale(self.plan.spec.domain.bounding_box())
        for verdict in verdicts:
            condition = next(c for c in self.plan.conditions if c.name == verdict.condition)
            if verdict.status is Status.SAT:
                point = torch.tensor([list(map(float, verdict.counterexample))],
                                     dtype=torch.float64)
                extra = around(point, condition.region, self.states,
                               self.options.counterexample_neighbours, 0.02 * scale,
                               self.generator)
            elif verdict.status is Status.UNKNOWN:  # learn something: more samples there
                extra = sample(condition.region, self.states, 100, self.generator,
                               self.plan.spec.domain.bounding_box())
            else:
                continue
            state.samples[condition.name] = torch.cat([state.samples[condition.name], extra])


def _clip_gradients(parameters, limit: float) -> None:
    """Scale gradients down to norm `limit` (torch's clip_grad_norm_ costs ~1.6 ms a call)."""
    norm = float(sum(p.grad.pow(2).sum() for p in parameters if p.grad is not None)) ** 0.5
    if norm > limit:
        for p in parameters:
            if p.grad is not None:
                p.grad.mul_(limit / norm)


def _violation(claim: L.Formula, env) -> torch.Tensor:
    """How far the claim is from holding (positive: violated)."""
    if not isinstance(claim, L.Compare):
        raise TypeError(f"a claim must be one comparison, not {claim}")
    difference = evaluate(claim.left, env) - evaluate(claim.right, env)
    return difference if claim.relation in ("<", "<=") else -difference


def _verdict(name: str, answer: Answer, states) -> Verdict:
    point = tuple(answer.model.get(s, 0) for s in states) if answer.model else None
    return Verdict(name, answer.status, answer.reason, point)


def _failure_reason(verdicts) -> str:
    failed = [v for v in verdicts if v.status is not Status.UNSAT]
    words = [f"{v.condition}: {'counterexample' if v.status is Status.SAT else v.reason or 'unknown'}"
             for v in failed]
    return "the given function fails: " + "; ".join(words)


def _box_scale(box) -> float:
    if box is None:
        return 1.0
    return max(high - low for low, high in zip(*box))
