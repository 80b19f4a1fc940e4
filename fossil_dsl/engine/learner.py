"""The learning side of CEGIS: networks for the certificate's functions (and the
controller), their training samples, the levels chosen from data, and training. The loss
terms are in loss.py, the search for violations in violations.py.

Nothing here proves anything: the loop turns what is learned into exact formulas and
hands those to the verifier.
"""
from __future__ import annotations

import copy
import time

import torch

from fossil_dsl.engine import reach_seed, safety_seed, stable_seed
from fossil_dsl.engine.evaluate import evaluate, holds, state_env
from fossil_dsl.engine.levels import initial_samples, level_value
from fossil_dsl.engine.loss import GUARD_BAND, condition_loss, guard_mask, placeholders
from fossil_dsl.engine.networks import Network, input_divisors
from fossil_dsl.engine.sampling import box_centre, sample
from fossil_dsl.engine.violations import ViolationSearch
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.certificates.base import (Condition, Level, change_of, level_of,
                                               next_value, value_of, velocity_of)
from fossil_dsl.plan.compile import Plan

FRESH_SEARCHES = 5  # searches of fresh samples per training round, at most
EXTRA_DIGITS = 3  # decimals that rounding may add to the plan's when 3 undo the learning
CONTROL_SAMPLES = 500  # where the control loss looks, over the domain (and again near a goal)
TARGET_SURROUNDINGS = 3.0  # the box near a goal: its bounding box scaled by this
# Adam's second-moment decay. torch's 0.999 remembers the large gradients of early
# training for about 1000 steps; late in training, when a few samples still violate a
# condition by a little, its steps are then tiny and the last violations linger for the
# whole step budget (row 7: 1000 steps twice; 0.9: 260 steps in all).
ADAM_BETAS = (0.9, 0.9)


class Learner(ViolationSearch):
    def __init__(self, plan: Plan, generator: torch.Generator):
        self.plan = plan
        self.states = plan.states
        self.generator = generator
        self.box = plan.spec.domain.bounding_box()
        self.samples = initial_samples(plan, generator)
        centre = box_centre(self.box)
        divisors = input_divisors(self.field_scales(torch.cat(list(self.samples.values()))))
        self.networks = {f.name: Network(len(self.states), f.layers, f.zero_at_origin,
                                         centre=centre, input_divisor=divisors)
                         for f in plan.functions if f.candidate is None}
        self.candidates = {f.name: f.candidate for f in plan.functions
                           if f.candidate is not None}
        self.controller = None
        if plan.controller is not None:
            c = plan.controller
            self.controller = Network(len(self.states), c.layers, c.zero_at_origin,
                                      outputs=len(c.inputs), centre=centre)
        self.conditions = {c.name: c for c in plan.conditions}
        self.digits = plan.options.digits  # of the last rounding
        self.fixed_levels = {}  # name -> value a found candidate was made for
        # each condition's placeholders, collected once (walking its formulas each
        # training step cost a tenth of the step)
        self._placeholders = {c.name: placeholders(c) for c in plan.conditions}
        needed = set().union(*self._placeholders.values())
        self.changes_needed = frozenset(n for n in needed if n.startswith("$d"))
        self.next_needed = any(next_value(s).name in needed for s in self.states)
        self.velocity_needed = any(velocity_of(s).name in needed for s in self.states)
        self.control_target, self.control_samples = self.controller_samples() \
            if self.controller is not None else (None, None)
        # the linearisation's quadratic V or B (and LQR controller) as the starting point
        self.seeded = self.seed_from(stable_seed.candidates(plan, self.networks, self.controller,
                                                       self.samples), least_loss=False) \
            or self.seed_from(safety_seed.candidates(plan, self.networks, self.controller,
                                                     self.samples)) \
            or self.seed_from(reach_seed.candidates(plan, self.networks, self.controller,
                                                    self.samples))
        self.parameters = [p for m in self.modules() for p in m.parameters()]
        # made on the first step: creating one imports torch._dynamo (1.8 s), which a
        # found candidate proved with a controller never needs (probe48/c03)
        self.optimiser = None

    def seed_from(self, candidates, least_loss: bool = True) -> bool:
        """Of (preferred, set_seed) pairs, best first: the first preferred seed that meets
        every condition on the samples (with the closed loop's true field), else the first
        other seed that does, else the one of least loss (or the first, where the loss
        says little: for a discrete SWA chain the least-loss LQR gain was never
        certified, the identity weights' in 6 s). Whether it seeded."""
        best = satisfying = None
        for preferred, set_seed in candidates:
            set_seed()
            loss, satisfied = self.loss()
            if satisfied and preferred:
                return True
            if satisfied and satisfying is None:
                satisfying = set_seed
            if best is None or (least_loss and float(loss.detach()) < best[0]):
                best = (float(loss.detach()), set_seed)
        chosen = satisfying or (best[1] if best is not None else None)
        if chosen is not None:
            chosen()
        return chosen is not None

    def restart(self) -> None:
        """New initial weights for every network, and a new optimiser; the samples (with
        every counterexample so far) are kept."""
        for module in self.modules():
            module.reset()
        self.optimiser = None
        self.digits = self.plan.options.digits

    def new_optimiser(self) -> torch.optim.Adam:
        return torch.optim.Adam(self.parameters, lr=self.plan.options.learning_rate,
                                betas=ADAM_BETAS)

    def modules(self) -> list[Network]:
        return list(self.networks.values()) + ([self.controller] if self.controller else [])

    @property
    def trainable(self) -> bool:
        return bool(self.parameters)

    # ---- values ----
    def field(self, points: torch.Tensor, open_loop: bool = False) -> list[torch.Tensor]:
        """The closed-loop vector field (or next state) at the points; open loop: with
        every input 0."""
        env = state_env(self.states, points)
        inputs = None
        if self.plan.controller is not None:
            inputs = torch.zeros(len(points), len(self.plan.controller.inputs),
                                 dtype=torch.float64) if open_loop else self.controller(points)
            inputs = inputs.unsqueeze(1) if inputs.dim() == 1 else inputs
            env.update({u: inputs[:, i] for i, u in enumerate(self.plan.controller.inputs)})
        if self.plan.spec.torch_dynamics is not None:
            values = self.plan.spec.torch_dynamics(points, inputs)
            return list(torch.as_tensor(values, dtype=torch.float64).unbind(1))
        return [torch.as_tensor(evaluate(f, env), dtype=torch.float64).expand(len(points))
                for f in self.plan.spec.dynamics]

    def field_scales(self, points: torch.Tensor) -> list[float]:
        """The root mean square of each open-loop field component over the points (the
        training samples: the sizes the loss sees)."""
        with torch.no_grad():
            return [float(f.pow(2).mean().sqrt()) for f in self.field(points, open_loop=True)]

    def function(self, name: str, points: torch.Tensor) -> torch.Tensor:
        if name in self.networks:
            return self.networks[name](points)
        value = evaluate(self.candidates[name], state_env(self.states, points))
        return torch.as_tensor(value, dtype=torch.float64).expand(len(points))

    def values(self, points: torch.Tensor, names) -> dict[str, torch.Tensor]:
        """Each named function's value and change (derivative along the flow, or
        one-step difference) at the points, which must require gradients."""
        result, field = {}, None
        if self.next_needed or self.velocity_needed:  # f(x), for claims such as f(x) ∈ S
            field = self.field(points)
            placeholder = next_value if self.next_needed else velocity_of
            result.update({placeholder(s).name: f for s, f in zip(self.states, field)})
        for name in names:
            value = self.function(name, points)
            result[value_of(name).name] = value
            if change_of(name).name not in self.changes_needed:
                continue
            field = field if field is not None else self.field(points)
            if self.plan.spec.time is TimeDomain.DISCRETE:
                change = self.function(name, torch.stack(field, 1)) - value
            else:
                grad, = torch.autograd.grad(value.sum(), points, create_graph=True)
                change = sum(grad[:, i] * f for i, f in enumerate(field))
            result[change_of(name).name] = change
        return result

    def environment(self, condition: Condition, points: torch.Tensor, levels) -> dict:
        env = state_env(self.states, points)
        env.update(self.values(points, self._names_needed([condition])))
        env.update({level_of(k).name: v for k, v in levels.items()})
        return env

    @property
    def _function_names(self):
        return [f.name for f in self.plan.functions]

    # ---- levels ----
    def levels(self) -> dict[str, float]:
        return {level.name: float(torch.as_tensor(self.level(level)).detach())
                for level in self.plan.levels}

    def level(self, level: Level):
        """The level's value now. A level just under the smallest value on `above`
        is a tensor that keeps its gradient: a loss that pushes V below it then also
        pushes that smallest value up, instead of dragging V and the level down
        together for ever."""
        if level.name in self.fixed_levels:
            return torch.tensor(float(self.fixed_levels[level.name]), dtype=torch.float64)
        if level.above is None:  # just over the largest value `below`, with its gradient
            below = self.function(level.function, self.samples[level.below])
            return level_value(None, below, self.plan.options.margin)
        above = self.function(level.function, self.samples[level.above])
        below = None
        if level.below is not None:
            with torch.no_grad():
                below = self.function(level.function, self.samples[level.below])
        return level_value(above, below, self.plan.options.margin)

    # ---- loss ----
    def loss(self) -> tuple[torch.Tensor, bool]:
        """One term per condition. Every condition's samples go through the networks
        in one batch: a pass per condition cost seven times the time on small batches."""
        levels = {level.name: self.level(level) for level in self.plan.levels}
        batches = [(condition, points) for condition, points in self._condition_samples()
                   if len(points)]
        total, satisfied = torch.zeros((), dtype=torch.float64), True
        if batches:
            points = torch.cat([p for _, p in batches]).clone().requires_grad_(True)
            shared = state_env(self.states, points)
            shared.update(self.values(points, self._names_needed(c for c, _ in batches)))
            start = 0
            for condition, part in batches:
                piece = slice(start, start + len(part))
                start += len(part)
                env = {k: v[piece] for k, v in shared.items()}
                env.update({level_of(k).name: v for k, v in levels.items()})
                term, ok = condition_loss(condition, points[piece], env,
                                          self.plan.options.margin)
                total = total + condition.weight * term
                satisfied = satisfied and ok
        if self.controller is not None:
            total = total + self.plan.options.control_weight * self.control_loss()
        return total, satisfied

    def _condition_samples(self):
        for condition in self.plan.conditions:
            points = self.samples[condition.name]
            if condition.exclude_origin:
                points = points[points.norm(dim=1) > 1e-6]
            yield condition, points

    def _names_needed(self, conditions) -> list[str]:
        needed = frozenset().union(*(self._placeholders[c.name] for c in conditions))
        return [f for f in self._function_names
                if value_of(f).name in needed or change_of(f).name in needed]

    def controller_samples(self) -> tuple[torch.Tensor, torch.Tensor]:
        """The point the controller steers to (the centre of the plan's target set, else
        the origin) and where its loss looks: the domain, and as many points again near
        the target, where a closed-loop equilibrium just outside a small goal set would
        otherwise hide between samples (row 9: the verifier found one there each
        iteration, and each fix moved it along the curve of equilibria)."""
        everywhere = sample(self.plan.spec.domain, self.states, CONTROL_SAMPLES,
                            self.generator, self.box)
        target = self.plan.controller.target
        box = target.bounding_box() if target is not None else None
        if box_centre(box) is None:
            return torch.zeros(len(self.states), dtype=torch.float64), everywhere
        low, high = (torch.tensor(side, dtype=torch.float64) for side in box)
        centre, reach = (low + high) / 2, TARGET_SURROUNDINGS * (high - low) / 2
        low, high = centre - reach, centre + reach
        if self.box is not None:
            low = torch.maximum(low, torch.tensor(self.box[0], dtype=torch.float64))
            high = torch.minimum(high, torch.tensor(self.box[1], dtype=torch.float64))
        near = low + (high - low) * torch.rand(CONTROL_SAMPLES, len(self.states),
                                               generator=self.generator, dtype=torch.float64)
        return centre, torch.cat([everywhere, near])

    def control_loss(self) -> torch.Tensor:
        """Rewards a closed-loop field (a map's step f(x) - x) pointing towards the
        target. With the next state itself, a map was rewarded for jumping across the
        target: probe60/ae06's learned gain grew to 6e4."""
        offsets = self.control_samples - self.control_target
        keep = offsets.norm(dim=1) > 1e-6
        points = self.control_samples[keep]
        field = torch.stack(self.field(points), 1)
        if self.plan.spec.time is TimeDomain.DISCRETE:
            field = field - points
        return torch.nn.functional.cosine_similarity(offsets[keep], field, dim=1,
                                                     eps=1e-9).mean()

    def train(self, steps: int, deadline: float) -> float:
        loss_value, searches = 0.0, 0
        for _ in range(steps):
            loss, satisfied = self.loss()
            loss_value = float(loss.detach())
            if time.monotonic() > deadline:
                break
            if satisfied:
                if searches == FRESH_SEARCHES or not self.add_fresh_violators():
                    break
                searches += 1
                continue
            if self.optimiser is None:
                self.optimiser = self.new_optimiser()
            self.optimiser.zero_grad()
            loss.backward()
            _clip_gradients(self.parameters, 10.0)
            self.optimiser.step()
        self.round_networks(satisfied_before=self.loss()[1])
        return loss_value

    def round_networks(self, satisfied_before: bool) -> None:
        """Round the weights to the fewest decimals (from the plan's `digits`, up to
        EXTRA_DIGITS more) that keep every condition met on the samples, if training met
        them: near the origin, rounding to 3 decimals can undo what was learned, and
        the loop would then verify the same failing candidate again and again."""
        saved = [copy.deepcopy(module.state_dict()) for module in self.modules()]
        base = self.plan.options.digits
        for self.digits in range(base, base + EXTRA_DIGITS + 1):
            for module in self.modules():
                module.round_weights(self.digits)
            if not satisfied_before or self.loss()[1]:
                return
            if self.digits < base + EXTRA_DIGITS:
                for module, state in zip(self.modules(), saved):
                    module.load_state_dict(state)

    # ---- learn-only ----
    def violation_rates(self, generator: torch.Generator) -> dict[str, tuple[int, int]]:
        """For each condition: how many fresh samples (not trained on) violate it, of how
        many where its guard holds (as `loss.is_met` judges: exactly, or, for a guard
        such as B(x) = 0 that holds exactly on no sample, within the band trained on)."""
        levels = self.levels()
        rates = {}
        for condition in self.plan.conditions:
            points = sample(condition.region, self.states, self.plan.samples[condition.name],
                            generator, self.box)
            if condition.exclude_origin:
                points = points[points.norm(dim=1) > 1e-9]
            env = self.detached_environment(condition, points, levels)
            considered = guard_mask(condition.guard, env, len(points), 0.0)
            if not considered.any():
                considered = guard_mask(condition.guard, env, len(points), GUARD_BAND)
            fails = ~holds(condition.claim, env, len(points)) & considered
            rates[condition.name] = (int(fails.sum()), int(considered.sum()))
        return rates


def _clip_gradients(parameters, limit: float) -> None:
    """Scale gradients down to norm `limit` (torch's clip_grad_norm_ costs ~1.6 ms a call)."""
    norm = float(sum(p.grad.pow(2).sum() for p in parameters if p.grad is not None)) ** 0.5
    if norm > limit:
        for p in parameters:
            if p.grad is not None:
                p.grad.mul_(limit / norm)
