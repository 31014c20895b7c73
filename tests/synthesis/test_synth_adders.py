"""Adders and harmonic transformers against direct simulation (independent loop closure).

The direct simulations solve the joint positions from the link-length constraints with scipy
(least squares / Brent), continued from the reference state; the module under test uses eqs.
14-15 of 002_… (projections of the bars) or closed-form circle intersections.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq, least_squares

from mechc.linkage_synthesis.adders import (
    LeverStage,
    LongBarAdder,
    bar_shortening,
    exact_adder,
    long_bar_adder,
    structural_error,
)
from mechc.linkage_synthesis.harmonic import (
    CrankLinkTransformer,
    best_offset,
    from_homogeneous,
    harmonic_homogeneous,
    homogeneous,
    max_structural_error,
)


def simulate_long_bar(ad: LongBarAdder, x1, x2):
    """x3 from the pin constraints |P_i - S_i| = L_i, unknowns (x3, phi), continued from 0."""
    y1, y2 = ad.y3 + ad.r1, ad.y3 + ad.r2
    z = np.array([0.0, 0.0])
    out = []
    for a, b in zip(x1, x2):
        def f(v, a=a, b=b):
            x3, phi = v
            p1 = np.array([x3 - ad.r1 * np.sin(phi), ad.y3 + ad.r1 * np.cos(phi)])
            p2 = np.array([x3 - ad.r2 * np.sin(phi), ad.y3 + ad.r2 * np.cos(phi)])
            return [np.hypot(*(p1 - [a - ad.l1, y1])) - ad.l1,
                    np.hypot(*(p2 - [b - ad.l2, y2])) - ad.l2]
        z = least_squares(f, z, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        out.append(z[0])
    return np.array(out)


@pytest.mark.parametrize("r1,r2,l1,l2", [(20, -30, 200, 150), (40, -10, 80, 120),
                                         (25, -25, 50, 50)])
def test_long_bar_error_matches_direct_simulation(r1, r2, l1, l2):
    ad = LongBarAdder(r1, r2, l1, l2)
    t = np.linspace(0, 1, 40)
    x1 = 15 * np.sin(3 * t)
    x2 = -10 * t + 4 * np.cos(5 * t) - 4
    st = long_bar_adder(ad, x1, x2)
    assert st.ok.all()
    x3 = simulate_long_bar(ad, x1, x2)
    w1, w2 = ad.weights
    assert np.max(np.abs((x3 - (w1 * x1 + w2 * x2)) - st.error)) < 1e-9
    assert np.max(np.abs(x3 - st.x3)) < 1e-9


def test_long_bar_error_shrinks_like_one_over_length():
    # 002_… p. after eq. 15: L (1 - cos theta) decreases with 1/L when theta ~ 1/L
    errs = []
    for L in (100.0, 200.0, 400.0, 800.0):
        ad = LongBarAdder(30, -30, L, L)
        errs.append(np.max(np.abs(long_bar_adder(ad, np.array([20.0]), np.array([-20.0])).error)))
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all(np.abs(ratios - 2.0) < 0.05)


def test_books_two_degree_figure():
    # 002_…: "If theta_1 is kept less than 0.035 radians (about 2 deg) the difference between
    # X1 and X1' will be about 0.0006 L1"
    assert abs(bar_shortening(1.0, 0.035) - 0.0006) < 2e-5


def test_exact_adder_is_the_lever_law():
    # eq. 8 against the collinear lever: P3 divides P1P2 in the ratio A2 : A1 (by eq. 14)
    rng = np.random.default_rng(0)
    a1, a2 = rng.uniform(0.5, 3, size=2)
    x1, x2 = rng.normal(size=5), rng.normal(size=5)
    p1, p2 = x1 + 1j * 0.0, x2 + 1j * (a1 + a2)
    p3 = p1 + (p2 - p1) * a1 / (a1 + a2)
    assert np.allclose(exact_adder(a2, a1, x1, x2), p3.real, atol=1e-14)


def crank_path(centre, r, start, sweep, t):
    return centre + r * np.exp(1j * (start - sweep * t))


def simulate_whiffletree(stages, pins, anchor):
    """Far ends from the two length constraints per lever, continued from the reference."""
    out = np.zeros(len(anchor), complex)
    fars = [st.far for st in stages]
    for k in range(len(anchor)):
        q = anchor[k]
        for s, (st, pin) in enumerate(zip(stages, pins)):
            def f(v, pin=pin[k], q=q, st=st):
                d = complex(*v)
                return [abs(d - pin) - st.lever, abs(d - q) - st.link]
            v = least_squares(f, [fars[s].real, fars[s].imag], xtol=1e-15, ftol=1e-15,
                              gtol=1e-15).x
            fars[s] = complex(*v)
            q = pin[k] + st.p * (fars[s] - pin[k])
        out[k] = q
    return out


@pytest.mark.parametrize("p1,p2", [(0.5, 0.5), (2.0, 0.5), (0.5, 1.5)])
def test_whiffletree_error_matches_direct_simulation(p1, p2):
    # Fig. 22 of 001_… with unit links: lever BG (pin B, anchor C via link CG, output E at p2),
    # lever AD (pin A, anchor E via link ED, output F at p1); cranks turn the input points.
    B, G = 0.0 + 0.0j, 0.0 + 1.0j
    C = G - 1.0
    E = B + p2 * (G - B)
    A = 1.2 + 0.0j
    D = A + 1.0j
    st0 = LeverStage(B, G, C, p2)
    st1 = LeverStage(A, D, E, p1)
    assert abs(st1.anchor - st0.output) < 1e-12  # link ED's length follows from E and D
    t = np.linspace(0, 1, 25)
    # input cranks of unit length turning clockwise through 0.3 / 0.3 / 0.25 rad
    pin_b = crank_path(B - 1j, 1.0, np.pi / 2, 0.3, t)
    pin_a = crank_path(A - 1j, 1.0, np.pi / 2, 0.3, t)
    anc = crank_path(C - 1j, 1.0, np.pi / 2, 0.25, t)
    r = structural_error([st0, st1], [pin_b, pin_a], anc)
    assert r.ok.all()
    f = simulate_whiffletree([st0, st1], [pin_b, pin_a], anc)
    disp = (f - f[0]).real
    assert np.max(np.abs(disp - r.displacement)) < 1e-9
    assert np.max(np.abs((disp - r.linear) - r.error)) < 1e-9
    # the weights of eq. 3.13 of 001_…: (p1 p2, p1 (1 - p2), 1 - p1) for (C, B, A)
    assert np.allclose(r.weights, [p1 * p2, p1 * (1 - p2), 1 - p1])
    assert r.max_abs > 0  # a real linkage is not exactly linear


def test_whiffletree_linear_limit():
    # with very long links and small strokes the separator is linear to second order
    st0 = LeverStage(0j, 1j, -1000 + 1j, 0.5)
    st1 = LeverStage(5 + 0j, 5 + 1j, st0.output, 0.5)
    t = np.linspace(0, 1, 5)
    r = structural_error([st0, st1], [0j + 1e-3 * t, 5 + 2e-3 * t], -1000 + 1j + 1e-3 * t)
    assert r.max_abs < 1e-6


def test_crank_link_matches_direct_simulation():
    tr = CrankLinkTransformer(radius=1.0, link=3.0, offset=0.3)
    xs = np.radians(np.linspace(-50, 70, 25))
    for x in xs:
        px, py = np.sin(x), np.cos(x)  # crank pin, zero position perpendicular to the slide
        s = brentq(lambda sx, px=px, py=py: np.hypot(sx - px, tr.offset - py) - tr.link, px,
                   px + tr.link)
        assert abs((s - tr.link) - tr.output(x)) < 1e-12
        assert abs(tr.output(x) - np.sin(x) - tr.structural_error(x)) < 1e-15


def test_crank_link_error_vanishes_with_long_link():
    x = np.radians(np.linspace(-40, 40, 81))
    w = best_offset(1.0, x[0], x[-1])
    e1 = max_structural_error(CrankLinkTransformer(1.0, 10.0, w), x[0], x[-1])
    e2 = max_structural_error(CrankLinkTransformer(1.0, 20.0, w), x[0], x[-1])
    assert 1.9 < e1 / e2 < 2.1  # L (1 - cos eps) with L sin eps fixed: ~ 1/(2L)
    # the best offset beats an offset at either end of the range of R cos x
    lo = max_structural_error(CrankLinkTransformer(1.0, 10.0, np.cos(x).min()), x[0], x[-1])
    assert e1 < lo


@pytest.mark.parametrize("x_lo,travel", [(-0.4, 0.9), (0.5, 1.5), (1.2, 2.0), (-2.0, 1.0)])
def test_harmonic_homogeneous(x_lo, travel):
    th = np.linspace(0, 1, 201)
    h = harmonic_homogeneous(th, x_lo, travel)
    s = np.sin(x_lo + th * travel)
    assert abs(h.min()) < 2e-5 and abs(h.max() - 1) < 2e-5  # 0..1 over the travel (sampled)
    # eq. 4-12 is the homogeneous form of R sin X: affine in sin
    assert np.allclose(from_homogeneous(h, s.min(), s.max()), s, atol=2e-5 * np.ptp(s))
    assert np.allclose(homogeneous(from_homogeneous(th, 2.0, 5.0), 2.0, 5.0), th)
