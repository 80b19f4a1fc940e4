"""The least value of x^T P x on a ball (engine/quadratic_shapes.set_floor): a lower
bound, and a close one (the seed filter refuses an ellipse whose level is above it)."""
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fossil_dsl.engine.quadratic_shapes import _ball_minimum


def sampled_minimum(P, middle, radius, count=200_000, seed=0):
    rng = np.random.default_rng(seed)
    directions = rng.normal(size=(count, len(middle)))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    points = middle + radius * directions  # the minimum is on the sphere
    return float(np.min(np.einsum("bi,ij,bj->b", points, P, points)))


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-2, 2), min_size=4, max_size=4),
       st.lists(st.floats(-3, 3), min_size=2, max_size=2), st.floats(0.05, 1.0))
def test_the_floor_is_below_and_close_to_the_least_value_on_the_sphere(entries, centre, r):
    M = np.array(entries).reshape(2, 2)
    P = M @ M.T + 0.05 * np.eye(2)
    middle = np.array(centre)
    floor = _ball_minimum(P, middle, r)
    if np.linalg.norm(middle) <= r:
        assert floor == 0.0
        return
    sampled = sampled_minimum(P, middle, r)
    assert floor <= sampled + 1e-9
    assert floor >= sampled - 1e-3 * max(1.0, sampled)


def test_a_flat_ellipse_beside_a_ball_is_not_refused_by_its_smallest_eigenvalue():
    P = np.array([[0.467, 0.117], [0.117, 0.469]])  # aw30's seed
    floor = _ball_minimum(P, np.array([1.2, 1.2]), 0.3)
    gap = np.linalg.norm([1.2, 1.2]) - 0.3
    assert floor > np.linalg.eigvalsh(P)[0] * gap ** 2 + 0.3
    assert abs(floor - sampled_minimum(P, np.array([1.2, 1.2]), 0.3)) < 1e-3
