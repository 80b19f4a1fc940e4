"""Reach-type certificates from the linearisation: V = s (x^T P x - c) (and, for RAR, the
barrier x^T P' x - d) with the LQR controller, where the origin is an equilibrium inside
the goal; the shape of P is chosen so that the sampled I and boundary of S are furthest
apart. The seed is only a starting point: the kernel judges it like any candidate."""
import torch

import fossil_dsl
from fossil_dsl.engine.learner import Learner
from fossil_dsl.plan.compile import compile_spec

# a damped double integrator: reach the goal from the left, below an obstacle that sits
# between init and goal in x0 (the lines through its faces cross the way)
RWA = """\
state x0, x1
input u0
dynamics continuous {
    x0' = x1
    x1' = u0 - 0.2*x1
}
domain box([-3, -3], [3, 3])
set init = box([-2, -0.3], [-1.5, 0.3])
set goal = ball([0, 0], 0.3)
set unsafe = box([-1, 1.5], [1, 3])
prove from init: not unsafe until goal
"""

# an oscillator with a quadratic spring: reach `final` and stay there, avoiding a box
RSWA = """\
state x0, x1
dynamics continuous {
    x0' = x1
    x1' = -x0 - 0.6*x1 + 0.1*x0^2
}
domain box([-2, -2], [2, 2])
set init   = box([1, -0.2], [1.4, 0.2])
set final  = ball([0, 0], 0.4)
set unsafe = box([-2, 1.5], [-1.2, 2])
prove from init: not unsafe until always final
"""

# a jerk-driven chain with damping: reach, avoid, remain
RAR = """\
state x0, x1, x2
input u0
dynamics continuous {
    x0' = x1
    x1' = x2
    x2' = u0 - x2
}
domain box([-2, -2, -2], [2, 2, 2])
set init = box([0.8, -0.1, -0.1], [1, 0.1, 0.1])
set goal = ball([0, 0, 0], 0.3)
set final = ball([0, 0, 0], 0.6)
set unsafe = box([-2, -2, 1.5], [-1.5, 2, 2])
prove from init: not unsafe until (goal and always final)
"""


# a stable spiral: reach the goal from the right, then remain in `final`
SPIRAL_RAR = """\
state x0, x1
dynamics continuous {
    x0' = -0.5*x0 - 2*x1
    x1' = 2*x0 - 0.5*x1
}
domain box([-2, -2], [2, 2])
set init = box([1, -0.2], [1.3, 0.2])
set goal = ball([0, 0], 0.2)
set final = ball([0, 0], 0.5)
set unsafe = box([-2, -2], [-1.7, -1.7])
prove from init: not unsafe until (goal and always final)
"""


def learner_for(text: str) -> Learner:
    return Learner(compile_spec(fossil_dsl.loads(text)), torch.Generator().manual_seed(0))


def test_the_seed_meets_every_sampled_condition():
    for text in (RWA, RSWA):
        learner = learner_for(text)
        assert learner.seeded
        V = learner.networks["V"]
        assert (V(learner.samples["initial"]) <= 0).all()
        assert (V(learner.samples["boundary"]) > 0).all()
        loss, satisfied = learner.loss()
        assert satisfied, float(loss)


def test_the_rar_seed_sets_both_functions_and_the_controller():
    learner = learner_for(RAR)
    assert learner.seeded
    B = learner.networks["B"]
    assert (B(learner.samples["barrier_initial"]) <= 0).all()
    assert (B(learner.samples["barrier_unsafe"]) > 0).all()
    gain = learner.controller.output.weight @ learner.controller.linears[0].weight
    assert gain.abs().sum() > 0  # the LQR gain, not torch's random start


def test_no_seed_where_the_goal_misses_the_origin():
    shifted = RSWA.replace("ball([0, 0], 0.4)", "ball([-0.8, 0], 0.3)")
    assert not learner_for(shifted).seeded


def test_seeded_reach_certificates_are_certified_in_the_first_iterations():
    for text in (RWA, RSWA, SPIRAL_RAR):
        result = fossil_dsl.synthesise(fossil_dsl.loads(text), seed=0, timeout=120)
        assert result.certified and result.iterations == 1, result.reason


# four states, two inputs: the thin ellipsoid that holds I and its mirror image reaches
# into the corners of D, which 4-dimensional boundary samples seldom visit
PLANAR = """\
state x0, x1, x2, x3
input u0, u1
dynamics continuous {
    x0' = x2
    x1' = x3
    x2' = u0
    x3' = u1
}
domain box([-3, -3, -3, -3], [3, 3, 3, 3])
set init = box([-2, -2, -0.1, -0.1], [-1.8, -1.8, 0.1, 0.1])
set goal = ball([0, 0, 0, 0], 0.3)
set unsafe = box([0.5, -3, -3, -3], [1, -1.5, 3, 3])
prove from init: not unsafe until goal
"""


def test_the_level_stays_below_the_quadratic_on_the_boxes_exact_boundary():
    result = fossil_dsl.synthesise(fossil_dsl.loads(PLANAR), seed=0, timeout=120)
    assert result.certified and result.iterations == 1, result.reason


def test_box_floors_bound_the_quadratic_on_the_faces_and_on_the_box():
    import numpy as np
    from fossil_dsl.engine.quadratic_shapes import boundary_floor, set_floor
    from fossil_dsl.ir.sets import Box
    from fossil_dsl.ir.expr import Num
    from fractions import Fraction
    rng = np.random.default_rng(0)
    factor = rng.normal(size=(3, 3))
    P = factor @ factor.T + 0.1 * np.eye(3)
    box = Box(tuple(Num(Fraction(v)) for v in (-1, -2, -1)),
              tuple(Num(Fraction(v)) for v in (2, 1, 3)))
    centre = np.array([0.2, -0.3, 0.5])
    floor = boundary_floor(P, box, centre)
    # points on the ellipsoid (x - c)^T P (x - c) = floor lie in the box, and one of them
    # on a face: the floor is the largest level whose ellipsoid stays inside
    directions = rng.normal(size=(20000, 3))
    scale = np.sqrt(floor / np.einsum("bi,ij,bj->b", directions, P, directions))
    points = centre + directions * scale[:, None]
    low, high = np.array([-1, -2, -1]), np.array([2, 1, 3])
    assert np.all(points >= low - 1e-9) and np.all(points <= high + 1e-9)
    assert np.min(np.minimum(points - low, high - points)) < 0.02
    # the smallest value over a box away from the centre, against a dense sample of it
    away = Box(tuple(Num(Fraction(v)) for v in (1, 1, 1)), tuple(Num(Fraction(v)) for v in (2, 3, 2)))
    inside = rng.uniform([1, 1, 1], [2, 3, 2], size=(200000, 3)) - centre
    sampled = np.einsum("bi,ij,bj->b", inside, P, inside).min()
    assert set_floor(P, away, centre) <= sampled + 1e-9
    assert set_floor(P, away, centre) >= sampled - 0.05 * sampled


# an inverted pendulum map (specs/probe51/l06): I at th = 0.3..0.5, unsafe th <= -0.5, so
# every ellipsoid round the origin that holds I meets the unsafe set
PENDULUM_MAP_RWA = """\
state th, w
input u
dynamics discrete {
    next(th) = th + 0.1*w
    next(w) = w + 0.1*(sin(th) - 0.2*w + u)
}
domain box([-1, -1.5], [1, 1.5])
set init = box([0.3, -0.1], [0.5, 0.1])
set goal = ball([0, 0], 0.15)
set unsafe = { th <= -0.5 }
prove from init: not unsafe until goal
"""


def test_where_no_ellipsoid_round_the_origin_fits_it_is_moved_into_g_towards_i():
    from fossil_dsl.engine import reach_seed
    import numpy as np
    learner = learner_for(PENDULUM_MAP_RWA)
    plan, rng = learner.plan, np.random.default_rng(0)
    boundary = reach_seed._boundary_samples(plan, rng)
    assert not reach_seed._fitting(plan, learner.networks, learner.samples, boundary,
                                   np.zeros(2), np.zeros(1), rng)
    centres = reach_seed._goal_centres(plan, learner.samples["initial"])
    assert centres and all(0 < c[0] < 0.15 and c[1] == 0 for c in centres)
    assert learner.seeded
    V = learner.networks["V"]
    at = torch.tensor(np.array([[0.0, 0.0], centres[0]]), dtype=torch.float64)
    values = V(at).detach().flatten()
    assert values[1] < values[0]  # V is least at the centre, not at the origin
    result = fossil_dsl.synthesise(fossil_dsl.loads(PENDULUM_MAP_RWA), seed=0, timeout=60)
    assert result.certified and result.iterations == 1, result.reason
