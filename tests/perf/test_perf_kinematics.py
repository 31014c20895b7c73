"""The fast lever-from-rod closed form (issue 7) against independent references.

The references are computed in 40-digit arithmetic by a different algorithm: the rocker angle
ψ from ``Dx cos ψ + Dy sin ψ = (r² + d² - L²) / (2r)`` (D = rod end - rocker pivot), the root on
the design pose's side; assembly from the triangle inequality |r - L| <= d <= r + L; the
transmission angle from the law of cosines. Angles are fed in as the same float64 values.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from mechc.ir.mechanism import Body, Joint, Part
from mechc.physics.closed_form import cos_sin, position, solve

mpmath.mp.dps = 40


def test_cos_sin_matches_libm_to_one_ulp():
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.uniform(-4, 4, 20000), rng.uniform(-1e4, 1e4, 20000),
                        [0.0, math.pi, -math.pi, math.pi / 2, -math.pi / 2, 3 * math.pi,
                         1e-300, -1e-300, 2 * math.pi]])
    c, s = cos_sin(x)
    assert np.max(np.abs(c - np.array([math.cos(v) for v in x]))) <= 2.3e-16
    assert np.max(np.abs(s - np.array([math.sin(v) for v in x]))) <= 2.3e-16
    assert np.isnan(cos_sin(np.array([np.nan]))[0]).all()


def _meet(a, b, ra, rb, s):
    d = math.dist(a, b)
    al = (ra * ra - rb * rb + d * d) / (2 * d)
    h = math.sqrt(ra * ra - al * al)
    ex, ey = (b[0] - a[0]) / d, (b[1] - a[1]) / d
    return (a[0] + al * ex - s * h * ey, a[1] + al * ey + s * h * ex)


def _random_fourbar(rng, flip: bool):
    """A random four-bar at an assembled design pose, branch and joint order random."""
    while True:
        g, cr, co, ro = rng.uniform(5, 80, 4)
        o1 = tuple(rng.uniform(-50, 50, 2))
        ang = rng.uniform(0, 2 * math.pi)
        o2 = (o1[0] + g * math.cos(ang), o1[1] + g * math.sin(ang))
        a0 = rng.uniform(0, 2 * math.pi)
        a = (o1[0] + cr * math.cos(a0), o1[1] + cr * math.sin(a0))
        if abs(ro - co) + 1e-3 < math.dist(a, o2) < ro + co - 1e-3:
            break
    b = _meet(o2, a, ro, co, rng.choice([-1.0, 1.0]))
    crank = Body("crank", "lever", [[o1, a, (o1[0] + 1, o1[1])]], 0.01, pivot=o1)
    rocker = Body("rocker", "lever", [[o2, b, (o2[0] + 1, o2[1])]], 0.01, pivot=o2)
    j = (Joint("rod", "rod", "rocker", "crank", pa=b, pb=a, length=co) if flip
         else Joint("rod", "rod", "crank", "rocker", pa=a, pb=b, length=co))
    # crank angles: random, and at set offsets from each toggle (d = r + L or |r - L|)
    th, off = list(rng.uniform(-math.pi, math.pi, 30)), [math.inf] * 30
    phi_g = math.atan2(o2[1] - o1[1], o2[0] - o1[0])
    for dt in (ro + co, abs(ro - co)):
        c = (cr * cr + g * g - dt * dt) / (2 * cr * g)
        if abs(c) <= 1:
            for sg in (1, -1):
                for e in (1e-10, -1e-10, 1e-7, -1e-7, 1e-4, -1e-4, 0.3, -0.3):
                    th.append(phi_g + sg * math.acos(c) + e - a0)
                    off.append(abs(e))
    return Part([crank, rocker], [j]), (o1, o2, a, b, co), np.array(th), np.array(off)


def _reference(geom, t):
    """Rocker pin (x, y), transmission (deg) and assembles? for crank turn t, in 40 digits."""
    o1, o2, a, b, L = geom
    mp = mpmath.mpf
    c, s = mpmath.cos(mp(float(t))), mpmath.sin(mp(float(t)))
    ax, ay = mp(a[0]) - o1[0], mp(a[1]) - o1[1]
    cx, cy = o1[0] + ax * c - ay * s, o1[1] + ax * s + ay * c
    dx, dy = cx - o2[0], cy - o2[1]
    d = mpmath.sqrt(dx * dx + dy * dy)
    r = mpmath.sqrt((mp(b[0]) - o2[0]) ** 2 + (mp(b[1]) - o2[1]) ** 2)
    if not abs(r - L) <= d <= r + L:
        return None, None, False
    k = (r * r + d * d - mp(L) ** 2) / (2 * r)
    side = np.sign((a[0] - o2[0]) * (b[1] - o2[1]) - (a[1] - o2[1]) * (b[0] - o2[0]))
    for sg in (1, -1):
        psi = mpmath.atan2(dy, dx) + sg * mpmath.acos(k / d)
        px, py = o2[0] + r * mpmath.cos(psi), o2[1] + r * mpmath.sin(psi)
        if np.sign(float(dx * (py - o2[1]) - dy * (px - o2[0]))) == side:
            break
    cos_g = abs((d * d - r * r - mp(L) ** 2) / (2 * r * L))  # arm against rod, law of cosines
    return (px, py), float(mpmath.degrees(mpmath.acos(min(cos_g, mp(1))))), True


@pytest.mark.parametrize("seed", range(6))
def test_lever_from_rod_against_40_digit_reference(seed):
    rng = np.random.default_rng(100 + seed)
    for k in range(5):
        part, geom, th, off = _random_fourbar(rng, flip=bool(k % 2))
        poses = solve(part, {"crank": th}, len(th))
        x, y = position(part.bodies[1], poses, geom[3])
        bad = poses.bad["rocker"]
        gam = poses.transmission["rod"]
        scale = max(abs(v) for p in geom[:4] for v in p) + geom[4]
        for i, t in enumerate(th):
            pin, g_ref, assembles = _reference(geom, t)
            assert bad[i] == (not assembles), (seed, k, off[i])
            if not assembles:
                assert np.isnan(poses.theta["rocker"][i])
                assert gam[i] == 0.0  # past the toggle: no transmission, never NaN-hidden
                continue
            s_g = max(math.sin(math.radians(g_ref)), 1e-12)
            # rounding conditioned by the toggle: the pin moves as 1/sin γ of its inputs' error
            err = max(abs(float(x[i] - pin[0])), abs(float(y[i] - pin[1])))
            assert err <= 1e-11 + 2e-14 * scale / s_g, (seed, k, off[i], err)
            assert abs(gam[i] - g_ref) <= 1e-9 + 1e-13 / s_g, (seed, k, off[i], gam[i], g_ref)
        np.testing.assert_array_equal(poses.singular_margin["rod"], gam)


def test_closure_check_still_flags_a_redundant_rod():
    """A second rod between the same pins, a little longer: the closure check (now in squared
    form, reusing the placed pins) must flag it beyond 1e-6 mm and only there."""
    rng = np.random.default_rng(9)
    part, geom, th, _ = _random_fourbar(rng, flip=False)
    th = th[np.isfinite(th)][:20]
    base = solve(part, {"crank": th}, len(th))
    ok = ~base.bad["rocker"]
    assert ok.sum() >= 10
    for extra, flagged in ((5e-7, False), (-5e-7, False), (2e-6, True), (-2e-6, True)):
        j = part.joints[0]
        twin = Joint("twin", "rod", j.a, j.b, pa=j.pa, pb=j.pb, length=j.length + extra)
        poses = solve(Part(part.bodies, [j, twin]), {"crank": th}, len(th))
        assert (poses.bad["rocker"][ok] == flagged).all(), extra
        assert (poses.bad["crank"][ok] == flagged).all(), extra
