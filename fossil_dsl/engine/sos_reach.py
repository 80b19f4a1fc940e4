"""A sum-of-squares attempt for reach-type properties (reach, RWA, RSWA, RAR) of a
polynomial ODE (or a rational one f = N / Q with Q > 0 on D, where the decrease is asked
of grad V . N + γ Q, multiplied through by Q, RAR's B's decay likewise:
rational_field.py; of any other ODE through a polynomial stand-in for its field:
surrogate.py), and for every reach-type property of a map (polynomial, or through a
stand-in; the decrease is V(f(x)) - V(x), still linear in V's coefficients; the kernel's
further conditions that a step from S outside G with V <= 0 lands in S, and for RSWA
from F with V <= β in F, are left to the proof); where the system has inputs, with a
linear controller fixed beforehand to an LQR gain of its linearisation, rounded as the
verifier will see it.

V (a polynomial of degree 2 or 4, coefficients in [-100, 100], for RSWA in [-10^4, 10^4])
and the largest e with

    -V - e                >= 0  on each member of I (a union's, each)
     V - e                >= 0  on each face of D, and on D outside the interior of S
    -dV/dt + λ V - γ - e  >= 0  on D outside the interior of G

each a Positivstellensatz identity (a sum of squares plus sum-of-squares multiples of the
set's constraints; "outside a set's interior" is one piece per constraint g >= 0 of the
set, where g <= 0). With λ = 0 the last asks dV/dt <= -γ even where V > 0, which no V
meets where D outside G holds another equilibrium; then λ > 0 (V of degree up to 6):
dV/dt <= λ V - γ, the condition itself where V <= 0, still linear in V. {V <= 0} may
lie anywhere, so it need not be centred at the origin (an I on one side of G, an unsafe
set on the other: no ellipsoid round the origin fits between them). For RAR, B (degree
2, then 4) comes from the barrier program (sos_barrier.py) with G for I and the part of D outside F
for U; where V's program fails, B alone is returned, and V is learned beside it.

Nothing here is trusted: the functions are rounded and proved like any candidate.
"""
from __future__ import annotations

import itertools
import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from fossil_dsl.engine.linear import operating_point
from fossil_dsl.engine.polynomial_field import PolynomialField, celled_field, exact_field
from fossil_dsl.engine.quadratic_shapes import lqr_controllers, set_point_bias
from fossil_dsl.engine.rational_field import over_one_denominator
from fossil_dsl.engine.reach_pieces import Pieces, confining_boxes, set_point
from fossil_dsl.engine.reach_program import BOUND, ReachProgram
from fossil_dsl.engine.sos import Inexact
from fossil_dsl.engine.sos_barrier import DECAY_RATES, MAP_DECAY_RATES, BarrierProgram
from fossil_dsl.engine.surrogate import polynomial_field
from fossil_dsl.ir import expr as E
from fossil_dsl.ir import polynomials as P
from fossil_dsl.ir import traversal
from fossil_dsl.ir.spec import TimeDomain
from fossil_dsl.plan.compile import Plan, default_synthesis
from fossil_dsl.solvers.sos_refutation import MAX_VARIABLES

FORMS = ("reach while avoid", "reach", "reach-avoid-remain", "reach and stay while avoid")
HALF_DEGREES = (1, 2)  # V of degree 2, then 4
# where no V decreases on all of D outside G (another equilibrium there: the rest state
# of probe68/ar15's neuron), dV <= λ V - γ: a decrease only where V <= 0, still linear
GROWTH_RATES = (1.0, 0.2)
GROWING_HALF_DEGREES = (1, 2, 3)  # ar15: degree 6 (margin 1 at λ = 1; none of degree 4)
STAND_IN_DEGREES, MAP_STAND_IN_DEGREES = (3, 5, 7), (3, 5)
# LQR gains tried with a stand-in, at most: where it works the first or second gain did
STAND_IN_CONTROLLERS = 3  # (19 specs with inputs; probe36/r01's eight programs took 8.5 s)
MIN_MARGIN = 1e-6
# a program with D's facts for the functions, at most this size: they are tried before
# the stand-in, and an exp map's infeasible quartic ones (4 321 variables, 3-4 s each)
# cost 10 s before the stand-in's V (probe62/ah11: 0.2 -> 12.9 s); the largest that found
# a V in the repo's map reach specs had 2 887 (probe76/az24)
FACTS_MAX_VARIABLES = 3_000
# |coefficient| of V at most BOUND (reach_program.py), and for RSWA, whose decrease is asked down to a ball of a quarter of F's reach: V
# holding I far out must fall by γ there too (probe73/aw29, a sampled unstable plant: no
# V of degree 8 within 100, a quartic within 10 000 with margin 0.29); and the margin
# grows with the bound, which a V solved for a stand-in needs (probe75/ay33: margin
# 0.017 within 100, its decrease refuted for the true map; margin 1 within 10 000)
STAY_BOUND = 10_000.0


@dataclass(frozen=True)
class ReachFinding:
    """V (and B for RAR) as exact formulas, and the controller they were found for
    (input -> exact formula; empty without inputs)."""

    formulas: dict
    controller: dict
    gain: np.ndarray | None  # -K: u = -K x + operating
    operating: np.ndarray  # the bias: the operating input, plus K c for a set point c
    degree: int  # V's (0: no V, RAR's B alone)
    margin: float
    seconds: float
    levels: dict  # name -> Fraction (RSWA's β), fixed for the proof
    barrier_degree: int = 0  # RAR's B (0: none)
    stand_in: int = 0  # the degree of the field's polynomial stand-in (0: none)
    confined: bool = False  # V > 0 outside a box round I and G (Pieces.confined)
    cells: int = 0  # cells of D with their own facts (polynomial_field.celled_field)
    abstracted: bool = False  # the functions were variables bounded by their facts

    def describe(self) -> str:
        if not self.degree:
            return (f"sum-of-squares programming (Clarabel): B of degree "
                    f"{self.barrier_degree}{self._stand_in()}, {self.seconds:.2f} s")
        control = " for an LQR gain of the linearisation" if self.controller else ""
        if not self.barrier_degree:
            barrier = ""
        elif self.barrier_degree == 2:
            barrier = " and a quadratic B"
        else:
            barrier = f" and B of degree {self.barrier_degree}"
        box = ", decreasing in a box round I and G" if self.confined else ""
        return (f"sum-of-squares programming (Clarabel): V of degree {self.degree}"
                f"{barrier}{control}{self._stand_in()}{box}, margin {self.margin:.3g}, "
                f"{self.seconds:.2f} s")

    def _stand_in(self) -> str:
        if self.cells:
            return f" (the functions' facts on each of {self.cells} cells of D)"
        return (f" (solved for a polynomial stand-in of degree {self.stand_in} for the "
                "field)") if self.stand_in else ""


def applies(plan: Plan) -> bool:
    """An ODE (polynomial, rational, or with a polynomial stand-in: surrogate.py) or a
    map, a reach-type property, the default templates, and at most a linear controller
    (the default one); a map's RAR comes later (`applies_late`)."""
    return plan.certificate.form in FORMS and default_synthesis(plan) and not applies_late(plan)


def applies_late(plan: Plan) -> bool:
    """A map's RAR: after the linearisation's quadratic V, which certified every such
    spec of the repo it applies to in a few seconds, where the programs (B's above all,
    of degree 4 for maps with stand-ins) cost up to 16 s first (probe64/am04: 4.6 ->
    16 s); the programs certify where no ellipsoid fits (probe70/at31)."""
    return (plan.certificate.form == "reach-avoid-remain" and default_synthesis(plan)
            and (plan.spec.time is TimeDomain.DISCRETE
                 or not all(map(traversal.is_arithmetic, plan.spec.dynamics))))


def search(plan: Plan, deadline: float) -> ReachFinding | None:
    """The first V (and B) found, over the controllers tried and V's degrees."""
    started = time.monotonic()
    spec, states = plan.spec, plan.states
    centre = set_point(plan) if spec.inputs else None
    operating = operating_point(spec, centre) if spec.inputs else np.zeros(0)
    if operating is None:
        return None
    try:
        pieces = Pieces(plan)
    except Inexact:
        return None
    rng = np.random.default_rng(plan.options.seed)
    discrete = spec.time is TimeDomain.DISCRETE
    loops = []
    for controller, gain, field, stand_in in _closed_loops(plan, operating, rng, centre,
                                                           discrete, deadline):
        b = None if pieces.outside_final is None else \
            _barrier(len(states), field, pieces, deadline, discrete)
        if pieces.outside_final is not None and b is None:
            continue
        loops.append(_Loop(controller, gain, field, stand_in, b))
        found = _functions(len(states), field, b, _shapes(pieces, not controller),
                           pieces, deadline, discrete, partial=not controller)
        if found is not None:
            return _finding(plan, found, loops[-1], centre, operating, started)
    # then, for the first closed loop, {V <= 0} in a box round I and G: after every
    # loop's own programs (probe59/ac15's second gain: found 10 s later behind them)
    confining = [(0.0, half, pieces.confined(box), BOUND) for box in confining_boxes(plan)
                 for half in HALF_DEGREES]
    if loops and confining and pieces.stay is None:
        first = loops[0]
        found = _functions(len(states), first.field, first.barrier, confining, pieces,
                           deadline, discrete)
        if found is not None:
            return _finding(plan, found, loops[0], centre, operating, started)
    return None


def _closed_loops(plan: Plan, operating, rng, centre, discrete: bool, deadline: float):
    """(controller, gain, the closed loop in polynomial form, its stand-in's degree) for
    each LQR gain in turn (one without inputs), each of its forms (_fields); an inexact
    or abstracted form for the first STAND_IN_CONTROLLERS gains only."""
    for index, (controller, gain) in enumerate(lqr_controllers(plan, operating, rng, centre)):
        closed = [traversal.substitute(f, controller) for f in plan.spec.dynamics]
        for field, stand_in in _fields(closed, plan, discrete):
            if time.monotonic() > deadline or \
                    (stand_in or field.facts) and index >= STAND_IN_CONTROLLERS:
                return
            yield controller, gain, field, stand_in


def _fields(closed, plan: Plan, discrete: bool):
    """(the closed loop in polynomial form, its stand-in's degree): polynomial, else for
    a map with functions (not RAR, whose B program has no facts for maps) with a variable
    per application bounded by its facts on D (exact), then over a denominator or as a
    stand-in, then the exact form with the facts on each cell of a grid on D (probe77/
    ba11's tanh network: no stand-in within 1 % on D, no V with D's facts)."""
    n = len(plan.states)
    field = _polynomial(closed, plan.states)
    if field is not None:
        yield PolynomialField(n, field, P.constant(1, n), []), 0
        return
    exact = discrete and plan.certificate.form != "reach-avoid-remain"
    if exact and (whole := exact_field(plan, closed)) and whole.facts \
            and not P.degree(whole.denominator):
        yield whole, 0
    found = _over_denominator(closed, plan, discrete)
    if found is not None:
        yield PolynomialField(n, found[0], found[1], []), found[2]
    if exact and (celled := celled_field(plan, closed)) and not P.degree(celled.denominator):
        yield celled, 0


class _Loop(NamedTuple):
    """A closed loop tried: the controller, its field in polynomial form, RAR's B."""
    controller: dict
    gain: np.ndarray | None
    field: PolynomialField
    stand_in: int
    barrier: P.Polynomial | None


def _finding(plan: Plan, found, loop: _Loop, centre, operating, started: float) -> ReachFinding:
    formulas, levels, degree, margin, confined = found
    return ReachFinding({name: P.to_expr(p, plan.states) for name, p in formulas.items()},
                        loop.controller, loop.gain,
                        set_point_bias(operating, loop.gain, centre), degree, margin,
                        time.monotonic() - started, levels,
                        P.degree(formulas["B"]) if "B" in formulas else 0, loop.stand_in,
                        confined, len(loop.field.cells), bool(loop.field.facts))


def _over_denominator(closed, plan: Plan, discrete: bool):
    """(N, Q, the stand-in's degree) for a system that is not polynomial: an ODE's
    rational field over one denominator Q > 0 (the programs, RAR's barrier program too,
    are multiplied through by Q), else a polynomial stand-in over Q = 1, of lower degree
    for a map (V(p(x)) multiplies the degrees); or None."""
    if discrete:
        return _stand_in(closed, plan, MAP_STAND_IN_DEGREES)
    if all(traversal.is_arithmetic(f) for f in closed):
        found = over_one_denominator(closed, plan.states, plan.spec.domain.bounding_box(),
                                     plan.options.seed)
        if found is not None:
            return (*found, 0)
    return _stand_in(closed, plan, STAND_IN_DEGREES)


def _stand_in(closed, plan: Plan, degrees):
    field = polynomial_field(closed, plan.states, plan.spec.domain, degrees,
                             plan.options.seed)
    if field is None:
        return None
    return field, P.constant(1, len(plan.states)), max(P.degree(p) for p in field)


def same_polynomial(first: E.Expr, second: E.Expr, states) -> bool:
    found = _polynomial([first, second], states)
    return found is not None and found[0] == found[1]


def _polynomial(expressions, variables):
    try:
        return [P.polynomial(f, variables) for f in expressions]
    except P.NotPolynomial:
        return None


def _functions(n: int, field: PolynomialField, b, shapes, pieces: Pieces, deadline: float,
               discrete: bool, partial: bool = False):
    """({"V": V, "B": b for RAR}, levels, V's degree, margin, whether confined) or None;
    the field is N / Q (Q > 0 on D), or the map N. Where
    `partial` (no controller), RAR's B alone when no V is found (degree 0): V's program
    asks for a decrease on all of D outside G, which a basin smaller than D rules out;
    and V's programs with a growth rate are tried too."""
    for rate, half, asked, bound in shapes:
        if time.monotonic() > deadline:
            return None
        program = ReachProgram(n, field, asked, half, discrete, rate, bound)
        if program.count > (FACTS_MAX_VARIABLES if field.facts and not field.cells
                            else MAX_VARIABLES):
            continue
        x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
        if x is not None and x[program.margin] > MIN_MARGIN:
            found = {"V": program.exact_v(x)}
            if b is not None:
                found["B"] = b
            return (found, program.levels(x), 2 * half, float(x[program.margin]),
                    asked is not pieces)
    return ({"B": b}, {}, 0, 0.0, False) if partial and b is not None else None


def _shapes(pieces: Pieces, growing: bool) -> list[tuple[float, int, Pieces, float]]:
    """(λ, half-degree, pieces, V's coefficient bound) of V's programs in turn: decrease
    on all of D outside G, then (`growing`; not for RSWA, whose decrease pieces are its
    own) only where V <= 0; for RSWA, the first ones with STAY_BOUND. With a
    controller (an LQR gain: one equilibrium in D) the growing ones served no spec of
    session 70's reach bench and cost up to 30 s of programs and failed proofs
    (probe65/an14: certified in 45 s -> timeout)."""
    if pieces.stay is not None:
        return [(0.0, half, pieces, STAY_BOUND) for half in HALF_DEGREES]
    shapes = [(0.0, half, pieces, BOUND) for half in HALF_DEGREES]
    if growing:
        shapes += [(rate, half, pieces, BOUND) for half in GROWING_HALF_DEGREES
                   for rate in GROWTH_RATES]
    return shapes


def _barrier(n: int, field: PolynomialField, pieces: Pieces, deadline: float,
             discrete: bool):
    """B <= 0 on G, B > 0 on D outside F, dB/dt <= -mu B (for a map B(f(x)) - B(x)
    <= -mu B; for a field N / Q, grad B . N <= -mu B Q) on D, of degree 2, then 4 (a
    hardening spring's x^3 outgrows every quadratic's decay on D: probe54/o07); else the
    decay on F only, where B > 0 on D outside F puts {B <= 0} (probe61/af13: states at
    D's corner leave D, and no B decays on all of it), after D: the kernel's queries know
    D, not F, and B's step conditions for probe71/au24 took 10 s of interval proof
    instead of 0.3 s of refutations; or None."""
    rates = MAP_DECAY_RATES if discrete else DECAY_RATES
    for region, half, mu in itertools.product((pieces.domain, pieces.final), HALF_DEGREES,
                                              rates):
        if time.monotonic() > deadline:
            return None
        program = BarrierProgram(n, field.numerators, [pieces.goal], pieces.outside_final,
                                 region, half, mu, field.denominator, discrete=discrete)
        x = program.solve({program.margin: -1.0}, deadline - time.monotonic())
        if x is not None and x[program.margin] > MIN_MARGIN:
            return program.exact_b(x)
    return None
