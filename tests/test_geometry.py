"""The geometry kernel's circle meeting: branches, misses, and the complex and scalar forms every
toolkit calls it in."""

import math

import numpy as np
import pytest

from mechc.geometry.circles import (
    LoopClosureError,
    branch_of,
    circle_intersection,
    circle_meeting,
    quarter_turn,
)


def _random_dyads(n: int, seed: int = 4):
    rng = np.random.default_rng(seed)
    c1 = rng.normal(size=(n, 2)) * 10
    c2 = rng.normal(size=(n, 2)) * 10
    d = np.hypot(*(c2 - c1).T)
    r1 = rng.uniform(0.3, 1.0, n) * d + 0.5
    r2 = np.abs(d - r1) + rng.uniform(0.05, 0.95, n) * (d + r1 - np.abs(d - r1))  # they cross
    return c1, r1, c2, r2


def test_meeting_lies_on_both_circles_on_the_chosen_branch():
    c1, r1, c2, r2 = _random_dyads(500)
    for branch in (1, -1):
        p = circle_intersection(c1, r1, c2, r2, branch)
        assert np.allclose(np.hypot(*(p - c1).T), r1, atol=1e-9)
        assert np.allclose(np.hypot(*(p - c2).T), r2, atol=1e-9)
        assert (branch_of(c1, c2, p) == branch).all()


def test_scalar_points_and_array_radii_broadcast():
    p = circle_intersection(np.array([0.0, 0.0]), 5.0, np.array([8.0, 0.0]), 5.0, 1)
    assert p == pytest.approx([4.0, 3.0])
    assert circle_intersection((0.0, 0.0), 5.0, (8.0, 0.0), 5.0, -1) == pytest.approx([4.0, -3.0])
    p, h2 = circle_meeting(np.zeros((3, 1, 2)), np.array([[5.0], [4.0], [6.0]]),
                           np.array([[[8.0, 0.0]]]), 5.0, -1)
    assert p.shape == (3, 1, 2) and h2.shape == (3, 1)
    assert p[0, 0] == pytest.approx([4.0, -3.0])


def test_complex_points_agree_with_xy_points():
    c1, r1, c2, r2 = _random_dyads(200, seed=9)
    z1, z2 = c1 @ [1, 1j], c2 @ [1, 1j]
    for branch in (1, -1):
        xy = circle_intersection(c1, r1, c2, r2, branch)
        z = circle_intersection(z1, r1, z2, r2, branch)
        assert np.iscomplexobj(z) and z.shape == (200,)
        assert np.array_equal(z, xy @ [1, 1j])
    one = circle_intersection(0j, 5.0, 8 + 0j, 5.0, 1)
    assert one == pytest.approx(4 + 3j)


def test_a_miss_raises_naming_the_loop_or_gives_nan_or_clamps():
    c1 = np.array([[0.0, 0.0], [0.0, 0.0]])
    c2 = np.array([[1.0, 0.0], [10.0, 0.0]])  # the second pair is 10 apart with radii 2 and 3
    with pytest.raises(LoopClosureError, match=r"loop ABC: circles do not meet at 1 position"):
        circle_intersection(c1, 2.0, c2, 3.0 - np.array([1.5, 0.0]), 1, "loop ABC")
    p, h2 = circle_meeting(c1, 2.0, c2, np.array([1.5, 3.0]), 1, miss="nan")
    assert np.isfinite(p[0]).all() and np.isnan(p[1]).all()
    assert h2[0] > 0 > h2[1]
    p, h2 = circle_meeting(c1, 2.0, c2, np.array([1.5, 3.0]), 1, miss="clamp")
    assert p[1] == pytest.approx([(100 + 4 - 9) / 20, 0.0])  # foot on the line of centres
    assert h2[1] < 0
    with pytest.raises(ValueError, match="miss must be"):
        circle_meeting(c1, 2.0, c2, 3.0, 1, miss="ignore")


def test_coincident_centres_never_meet():
    with np.errstate(invalid="ignore"), pytest.raises(LoopClosureError, match="coincident"):
        circle_intersection(np.array([1.0, 1.0]), 1.0, np.array([1.0, 1.0]), 1.0, 1)
    assert np.isnan(circle_intersection(1 + 1j, 1.0, 1 + 1j, 1.0, 1, miss="nan"))


def test_branch_of_is_an_int_for_one_point_and_an_array_for_many():
    assert branch_of((0, 0), (1, 0), (0.3, 2)) == 1
    assert isinstance(branch_of((0, 0), (1, 0), (0.3, -2)), int)
    got = branch_of(np.zeros(2), np.array([[1.0, 0.0], [0.0, 1.0]]), np.array([[0, -1], [-1, 0]]))
    assert got.tolist() == [-1, 1]


def test_quarter_turn_is_the_left_normal():
    v = np.array([[1.0, 0.0], [math.sqrt(0.5), math.sqrt(0.5)]])
    assert quarter_turn(v).tolist() == [[-0.0, 1.0], [-math.sqrt(0.5), math.sqrt(0.5)]]
