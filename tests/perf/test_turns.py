"""A lever placed by a circle meeting keeps its pose as the arm it turned to (``Turn``): the
angle, its cosine and sine, and every point's position must be what the angle gives by libm's
trig, and a point the closed form placed is read back as placed only while that pose stands."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechc.ir.mechanism import Body, Joint, Part
from mechc.parts.base import rotate
from mechc.parts.poses import Poses, Turns
from mechc.physics.closed_form import position, solve


def _fourbar() -> tuple[Part, tuple[float, float]]:
    """Crank 10 at (0, 0) pinned at (0, 10), coupler 40, rocker 30 about (40, 0)."""
    o2, a = (40.0, 0.0), (0.0, 10.0)
    dx, dy = a[0] - o2[0], a[1] - o2[1]
    d = math.hypot(dx, dy)
    al = (30.0 ** 2 - 40.0 ** 2 + d * d) / (2 * d)
    h = math.sqrt(30.0 ** 2 - al * al)
    b = (o2[0] + al * dx / d - h * dy / d, o2[1] + al * dy / d + h * dx / d)
    crank = Body("crank", "lever", [[(0.0, 0.0), a, (1.0, 10.0)]], 0.01, pivot=(0.0, 0.0))
    rocker = Body("rocker", "lever", [[o2, b, (41.0, -3.0)]], 0.01, pivot=o2)
    return Part([crank, rocker], [Joint("c", "rod", "crank", "rocker", pa=a, pb=b,
                                        length=40.0)]), b


def _libm_point(pivot, p, th):
    """Where design point ``p`` turned by ``th`` about ``pivot`` is, by libm cos and sin."""
    rx, ry = p[0] - pivot[0], p[1] - pivot[1]
    return (pivot[0] + rx * math.cos(th) - ry * math.sin(th),
            pivot[1] + rx * math.sin(th) + ry * math.cos(th))


def test_a_placed_lever_gives_the_angle_and_points_libm_gives():
    part, b = _fourbar()
    th = np.linspace(-math.pi, math.pi, 721)
    poses = solve(part, {"crank": th}, len(th))
    rocker = part.bodies[1]
    ang = poses.theta["rocker"]
    ok = ~poses.bad["rocker"]
    assert ok.sum() > 600 and np.all(np.abs(ang[ok]) <= math.pi)
    # the angle is that of the placed pin about the pivot, less the design pin's
    px, py = position(rocker, poses, b)
    for i in np.flatnonzero(ok)[::7]:
        ref = math.atan2(py[i] - 0.0, px[i] - 40.0) - math.atan2(b[1], b[0] - 40.0)
        ref = (ref + math.pi) % (2 * math.pi) - math.pi
        assert abs(ang[i] - ref) <= 1e-13
    c, s = poses.theta.cos_sin("rocker")
    np.testing.assert_allclose(c[ok], np.cos(ang[ok]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(s[ok], np.sin(ang[ok]), rtol=0, atol=1e-14)
    # another point of the rocker (not placed by the solve): turned by the angle
    q = (41.0, -3.0)
    qx, qy = position(rocker, poses, q)
    for i in np.flatnonzero(ok)[::11]:
        rx, ry = _libm_point(rocker.pivot, q, ang[i])
        assert abs(qx[i] - rx) <= 1e-12 and abs(qy[i] - ry) <= 1e-12


def test_a_placed_point_is_read_back_only_while_its_pose_stands():
    part, b = _fourbar()
    th = np.array([0.0, 0.3, -0.4])
    poses = solve(part, {"crank": th}, 3)
    rocker = part.bodies[1]
    x, y = position(rocker, poses, b)
    placed = poses.placed[("rocker", float(b[0]), float(b[1]))]
    assert x is placed[0] and y is placed[1]  # no trig: the solve's own numbers
    # a new pose for the rocker: the old placed pin must not be returned
    poses.theta["rocker"] = np.array([0.1, 0.2, 0.3])
    x2, y2 = position(rocker, poses, b)
    for i, t in enumerate((0.1, 0.2, 0.3)):
        rx, ry = _libm_point(rocker.pivot, b, t)
        assert abs(x2[i] - rx) <= 1e-12 and abs(y2[i] - ry) <= 1e-12
    # merged into another Poses, the placed points and the turn travel together
    merged = Poses()
    fresh = solve(part, {"crank": th}, 3)
    merged.update(fresh)
    assert position(rocker, merged, b)[0] is position(rocker, fresh, b)[0]


def test_turns_reads_as_a_mapping_of_angles():
    t = Turns({"a": np.array([0.5])})
    t.set_arm("b", np.array([0.0]), np.array([2.0]), 2.0, 0.0, 0.0)  # turned by +90°
    assert set(t) == {"a", "b"} and len(t) == 2 and "b" in t and "z" not in t
    assert t["b"][0] == pytest.approx(math.pi / 2, abs=1e-15)
    c, s = t.cos_sin("b")
    assert (c[0], s[0]) == pytest.approx((0.0, 1.0), abs=1e-15)
    c, s = t.cos_sin("a")
    assert (c[0], s[0]) == pytest.approx((math.cos(0.5), math.sin(0.5)), abs=2.3e-16)
    u = Turns()
    u.update(t)
    assert u.entry("b") is t.entry("b")
    del u["a"]
    assert list(u) == ["b"]
    p = Poses(theta={"x": np.array([1.0])})
    assert isinstance(p.theta, Turns) and p.theta["x"][0] == 1.0


@pytest.mark.parametrize("arm", [(0.0, 7.5), (-4.25, 0.0), (0.0, 0.0), (3.0, -2.0)])
def test_rotate_skips_zero_arm_terms_with_the_same_values(arm):
    rng = np.random.default_rng(5)
    th = rng.uniform(-4, 4, 2000)
    c, s = np.cos(th), np.sin(th)
    centre = (1.5, -2.0)
    x, y = rotate(arm[0], arm[1], c, s, centre)
    # the general formula, term by term
    gx = arm[0] * c - arm[1] * s + centre[0]
    gy = arm[0] * s + arm[1] * c + centre[1]
    np.testing.assert_array_equal(x, gx)
    np.testing.assert_array_equal(y, gy)
