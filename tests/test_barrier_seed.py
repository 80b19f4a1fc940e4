"""Safety from the linearisation: B = x^T P x - c seeded from the Lyapunov equation (LQR
closed loop with inputs), and the kernel's stronger guarantee ("never leaves D") only
where its further obligation is proved."""
import json
from pathlib import Path

import torch

import fossil_dsl
from fossil_dsl.engine.learner import Learner
from fossil_dsl.engine.linear import local_certificate
from fossil_dsl.kernel.obligations import file_stem
from fossil_dsl.kernel.prove import SUM_OF_SQUARES
from fossil_dsl.outputs import recheck as rechecking
from fossil_dsl.outputs.recheck import recheck
from fossil_dsl.plan.compile import compile_spec

STABLE = Path(__file__).resolve().parent.parent / "specs" / "stability_continuous.fsl"

# four weakly coupled decaying modes; the level sets of x^T P x are far from round
DECAY = """\
state a, b, c, d
dynamics continuous {
    a' = -0.2*a + 0.1*b
    b' = -0.1*a - 0.2*b
    c' = -0.5*c + 0.01*c^3
    d' = -0.3*d
}
domain ball([0, 0, 0, 0], 4)
set init = ball([0, 0, 0, 0], 1)
set unsafe = ~ball([0, 0, 0, 0], 3.6)
prove from init: always not unsafe
"""

# a double integrator with a force input and a cubic spring: unstable without control
CART = """\
state p, v, w
input f, g
dynamics continuous {
    p' = v
    v' = 0.3*p^3 + f
    w' = w + g
}
domain ball([0, 0, 0], 3)
set init = box([-0.2, -0.2, -0.2], [0.2, 0.2, 0.2])
set unsafe = ~ball([0, 0, 0], 2.5)
prove from init: always not unsafe
"""

# discrete: a rotation shrunk by 0.9
MAP = """\
state x, y
dynamics discrete {
    next(x) = 0.9*(0.6*x - 0.8*y)
    next(y) = 0.9*(0.8*x + 0.6*y)
}
domain ball([0, 0], 2)
set init = ball([0.5, 0], 0.2)
set unsafe = ~ball([0, 0], 1.5)
prove from init: always not unsafe
"""


def test_the_seeded_barrier_separates_the_sampled_sets():
    plan = compile_spec(fossil_dsl.loads(DECAY))
    learner = Learner(plan, torch.Generator().manual_seed(0))
    assert learner.seeded
    B = learner.networks["B"]
    assert (B(learner.samples["initial"]) < 0).all()
    assert (B(learner.samples["unsafe"]) > 0).all()


def test_where_the_origin_is_not_an_equilibrium_the_seed_is_centred_on_one():
    shifted = DECAY.replace("d' = -0.3*d", "d' = -0.3*d + 0.01")
    plan = compile_spec(fossil_dsl.loads(shifted))
    learner = Learner(plan, torch.Generator().manual_seed(0))
    assert learner.seeded
    equilibrium = torch.tensor([[0.0, 0.0, 0.0, 0.01 / 0.3]], dtype=torch.float64,
                               requires_grad=True)
    value = learner.networks["B"](equilibrium)
    gradient, = torch.autograd.grad(value.sum(), equilibrium)
    assert gradient.abs().max() < 1e-9  # the quadratic's centre
    assert value < learner.networks["B"](torch.zeros(1, 4, dtype=torch.float64))


# BarrierBench bb23 with the domain its script draws round the sets: I lies away from
# the origin, and an ellipsoid round the origin that holds I crosses D's lower faces; one
# round I's middle, held there by the controller's bias, need not
AWAY = """\
state x1, x2, x3
input u0, u1, u2
dynamics continuous {
    x1' = 0.5 - 0.2*x1 + u0
    x2' = 0.1*x1 - 0.15*x2 + u1
    x3' = 0.05*x2 - 0.1*x3 + u2
}
domain box([-1, -1.25, -1.05], [7, 5.75, 4.35])
set init   = box([1, 0.5, 0.3], [1.5, 1, 0.7])
set unsafe = box([4, 3, 2], [5, 4, 3])
prove from init: always not unsafe
"""


def test_a_seed_round_the_middle_of_i_keeps_its_zero_level_inside_the_domain():
    plan = compile_spec(fossil_dsl.loads(AWAY))
    learner = Learner(plan, torch.Generator().manual_seed(0))
    assert learner.seeded
    boundary = torch.tensor([[-1, 0.75, 0.5], [1.25, -1.25, 0.5], [1.25, 0.75, -1.05],
                             [-1, -1.25, -1.05]], dtype=torch.float64)
    assert (learner.networks["B"](boundary) > 0).all()
    middle = torch.tensor([[1.25, 0.75, 0.5]], dtype=torch.float64)
    # the controller holds the middle of I as an equilibrium of the closed loop
    assert torch.allclose(torch.stack(learner.field(middle)), torch.zeros(3, 1,
                          dtype=torch.float64), atol=1e-9)
    result = fossil_dsl.synthesise(plan.spec, seed=0, timeout=60)
    assert result.certified, result.reason
    assert result.kernel.strengthened == "never leaves D"


def test_seeded_barriers_are_certified_at_once_and_never_leave_the_domain(tmp_path):
    for name, text in (("decay", DECAY), ("cart", CART), ("map", MAP)):
        result = fossil_dsl.synthesise(fossil_dsl.loads(text), seed=0, timeout=120)
        assert result.certified and result.iterations == 1, (name, result.reason)
        assert result.kernel.strengthened == "never leaves D", name
        assert "never leave D" in result.guarantee()
        assert "while they remain in D" not in result.guarantee()
        folder = tmp_path / name
        result.save(folder)
        data = json.loads((folder / "result.json").read_text())
        assert data["kernel"]["strengthening"] == "never leaves D"
        checks = recheck(folder, timeout=30)
        names = {c.condition for c in checks}
        assert names & {"strong-boundary", "strong-image"}, names
        assert all(c.reproved for c in checks), [c for c in checks if not c.reproved]


LEAVES = """\
state x, y
dynamics continuous {
    x' = 1
    y' = -y
}
domain box([-1, -1], [1, 1])
set init = box([-0.5, -0.1], [-0.4, 0.1])
set unsafe = box([2, -1], [3, 1])
prove from init: always not unsafe
synthesis {
    candidate: -1
}
"""


def test_a_barrier_that_holds_only_inside_the_domain_keeps_its_qualifier():
    # every trajectory leaves D to the right and then enters U: only "while they
    # remain in D" is true, and B = -1 proves exactly that
    discrete = LEAVES.replace("continuous", "discrete").replace(
        "x' = 1", "next(x) = x + 1").replace("y' = -y", "next(y) = y/2")
    for text in (LEAVES, discrete):
        result = fossil_dsl.synthesise(fossil_dsl.loads(text), seed=0)
        assert result.certified, result.reason
        assert result.kernel.strengthened is None
        assert "while they remain in D" in result.guarantee()
        assert "the conditions are checked only inside the domain D" in result.assumptions()


def test_the_cart_seed_uses_the_riccati_gain():
    spec = fossil_dsl.loads(CART)
    P, K = local_certificate(spec, controlled=True)
    assert K.shape == (2, 3)


# the origin is an equilibrium only for u = (-0.5, 0): the controller's bias must hold it
OFFSET_MAP = """\
state x, y
input u, v
dynamics discrete {
    next(x) = 0.5 - x^2 + y + u
    next(y) = 0.2*x + v
}
domain ball([0, 0], 2)
set init = box([-0.1, -0.1], [0.1, 0.1])
set unsafe = ~ball([0, 0], 1.8)
prove from init: always not unsafe
"""


def test_the_controller_holds_the_input_that_makes_the_origin_an_equilibrium():
    plan = compile_spec(fossil_dsl.loads(OFFSET_MAP))
    learner = Learner(plan, torch.Generator().manual_seed(0))
    assert learner.seeded
    at_origin = learner.controller(torch.zeros(1, 2, dtype=torch.float64))
    assert torch.allclose(at_origin, torch.tensor([[-0.5, 0.0]], dtype=torch.float64))
    result = fossil_dsl.synthesise(plan.spec, seed=0, timeout=60)
    assert result.certified, result.reason


# Z3 proves the cart's conditions in the run (no refutation is exported)
def test_a_result_saved_over_another_leaves_nothing_of_it(tmp_path):
    first = fossil_dsl.synthesise(fossil_dsl.load(STABLE), seed=0)  # proved by refutations
    first.save(tmp_path)
    assert list((tmp_path / "obligations").glob("*.sos.json"))
    second = fossil_dsl.synthesise(fossil_dsl.loads(CART), seed=0, timeout=60)
    assert second.certified
    second.save(tmp_path)
    left = {p.name.removesuffix(".sos.json")
            for p in (tmp_path / "obligations").glob("*.sos.json")}
    assert left == {file_stem(name) for name in second.refutations}
    assert not (tmp_path / "obligations" / "condition-decrease.smt2").exists()
    assert all(c.reproved for c in recheck(tmp_path, timeout=30))


def test_without_cvc5_polynomial_obligations_are_rechecked_by_a_refutation(tmp_path,
                                                                          monkeypatch):
    # the user's controller keeps the learned route, whose conditions Z3 proves in the
    # run (with the default one, the closed loop's barrier program's B is proved by
    # refutations, and those are rechecked from their own files)
    learned = CART + "synthesis { controller: linear(2) }\n"
    result = fossil_dsl.synthesise(fossil_dsl.loads(learned), seed=0, timeout=60)
    assert result.certified
    result.save(tmp_path)
    installed = rechecking.registry.is_installed
    monkeypatch.setattr(rechecking.registry, "is_installed",
                        lambda name: name != "cvc5" and installed(name))
    checks = recheck(tmp_path, timeout=30)
    assert all(c.reproved for c in checks), checks
    by_refutation = [c for c in checks if c.proved_by == "z3" and c.solver == SUM_OF_SQUARES]
    assert any(c.condition.startswith("condition-") for c in by_refutation), checks


def test_ceilings_bound_the_quadratic_on_boxes_and_balls_from_above():
    """A box's ceiling is its largest value (at a corner: a sample of the box never
    exceeds it, and a corner attains it); a ball's is an upper bound, tight along P's
    widest direction."""
    import numpy as np
    from fractions import Fraction
    from fossil_dsl.engine.quadratic_shapes import set_ceiling
    from fossil_dsl.ir.expr import Num
    from fossil_dsl.ir.sets import Ball, Box
    rng = np.random.default_rng(1)
    factor = rng.normal(size=(4, 4))
    P = factor @ factor.T + 0.1 * np.eye(4)
    centre = np.array([0.1, -0.2, 0.0, 0.3])
    low, high = np.array([-1, 0, -2, 0.5]), np.array([0.5, 1, -1, 1.5])
    box = Box(tuple(Num(Fraction(v)) for v in low), tuple(Num(Fraction(v)) for v in high))
    points = rng.uniform(low, high, size=(100000, 4)) - centre
    sampled = np.einsum("bi,ij,bj->b", points, P, points).max()
    ceiling = set_ceiling(P, box, centre)
    assert sampled <= ceiling + 1e-9 and sampled < ceiling  # samples miss the corner
    corners = np.array(np.meshgrid(*zip(low, high))).reshape(4, -1).T - centre
    assert np.isclose(np.einsum("bi,ij,bj->b", corners, P, corners).max(), ceiling)
    ball = Ball(tuple(Num(Fraction(v)) for v in (0.5, 0, 0, -0.5)), Num(Fraction(1, 2)))
    directions = rng.normal(size=(100000, 4))
    directions /= np.linalg.norm(directions, axis=1)[:, None]
    on_sphere = np.array([0.5, 0, 0, -0.5]) + 0.5 * directions - centre
    assert np.einsum("bi,ij,bj->b", on_sphere, P, on_sphere).max() <= \
        set_ceiling(P, ball, centre) + 1e-9
