"""The 3-bar gate: closed form, numerical solution, and an independent kinematic check.

The independent reference is a least-squares loop closure (scipy) continued step by step from
the FF state -- the branch the mechanism really moves along -- sharing no formula with
mechc.linkage_synthesis.three_bar_gate.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.optimize import least_squares

from mechc.linkage_synthesis import three_bar_gate as tb


def loop_closure(d: tb.ThreeBarDesign, path_a, path_b):
    """Joint M and output x along a path of input positions, by continuation from FF."""
    sep, di, do = d.sep, d.input_link, d.output_link
    m0 = np.sqrt(di**2 - sep**2)
    z = np.array([m0, 0.0, m0 + d.output_side * do])
    out = []
    for a, b in zip(path_a, path_b):
        def f(v, a=a, b=b):
            mx, my, ox = v
            return [np.hypot(mx - a, my - sep) - di, np.hypot(mx - b, my + sep) - di,
                    np.hypot(mx - ox, my) - do]
        z = least_squares(f, z, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        out.append(z.copy())
    return np.array(out)


def angles(d, a, b, mx, my, ox):
    """Transmission angles (inputs at M, output link vs normal of its slide) from positions."""
    u = np.array([a - mx, d.sep - my])
    v = np.array([b - mx, -d.sep - my])
    psi = np.degrees(np.arccos(np.dot(u, v) / (np.linalg.norm(u) * np.linalg.norm(v))))
    phi = np.degrees(np.arctan2(abs(my), abs(ox - mx)))
    return min(psi, 180 - psi), 90 - phi


def independent_check(d: tb.ThreeBarDesign, steps: int = 60):
    """(outputs per state, min transmission angle over the single-input motions)."""
    s = d.stroke
    t = np.linspace(0, 1, steps)
    ff_ft = loop_closure(d, 0 * t, s * t)
    ff_tf = loop_closure(d, s * t, 0 * t)
    ft_tt = loop_closure(d, s * t, s + 0 * t)
    outs = {"FF": ff_ft[0, 2], "FT": ff_ft[-1, 2], "TF": ff_tf[-1, 2], "TT": ft_tt[-1, 2]}
    mus = []
    for path, (pa, pb) in ((ff_ft, (0 * t, s * t)), (ff_tf, (s * t, 0 * t)),
                           (ft_tt, (s * t, s + 0 * t))):
        for (mx, my, ox), a, b in zip(path, pa, pb):
            mus.extend(angles(d, a, b, mx, my, ox))
    return outs, min(mus)


def test_blog_example_is_the_toggle_root():
    # 000_…: sep 50, str 20 (stroke 40), x_o 70 -> d_i = sqrt(2900), d_o = 50 "via Wolfram Alpha".
    sep, s, xo = 50.0, 40.0, 70.0
    di = np.sqrt(2900.0)
    # the blog's final equation (as printed) is satisfied by sqrt(2900):
    q = di**2 / (sep**2 + (s / 2) ** 2) - 1
    lhs = (xo - np.sqrt(di**2 - sep**2)) ** 2
    rhs = (xo - s / 2 + np.sqrt(q)) ** 2 + (s / 2) ** 2 * q
    assert abs(lhs - rhs) < 1e-9
    # ... but in FT the two input links are then exactly in line: |A B'| = 2 d_i (a toggle)
    assert abs(np.hypot(s, 2 * sep) - 2 * di) < 1e-12
    tog = tb.toggle_design(sep, s, xo)
    assert abs(tog.input_link - di) < 1e-12 and abs(tog.output_link - 50.0) < 1e-12
    rep = tb.evaluate(tog)
    assert not rep.healthy
    assert rep.state_angles["FT"]["inputs"] < 1e-6  # transmission angle 0 in the stable state


def test_blog_branch_error():
    # The blog's x_m' = str - sqrt(d_i^2/(sep^2+str^2) - 1) is neither branch of the true
    # circle intersection for a non-toggle d_i: it drops a factor sep and takes the left branch.
    sep, s = 50.0, 40.0
    d = tb.solve_closed_form(sep, s, 70.0)[0]
    st = tb.kinematics(d, 0.0, s)
    q = d.input_link**2 / (sep**2 + (s / 2) ** 2) - 1
    blog_xm = s / 2 - np.sqrt(q)
    true_right = st.m.real
    b = np.hypot(sep, s / 2)
    h = np.sqrt(d.input_link**2 - b**2)
    true_left = s / 2 - sep * h / b
    assert abs(blog_xm - true_right) > 1.0 and abs(blog_xm - true_left) > 1.0
    assert abs(true_right - (s / 2 + sep * h / b)) < 1e-12


@pytest.mark.parametrize("seed", range(6))
def test_closed_form_matches_numeric_and_loop_closure(seed):
    rng = np.random.default_rng(seed)
    sep, s = rng.uniform(10, 80), rng.uniform(10, 60)
    xo = rng.uniform(1.2, 6.0) * (sep + s)
    closed = tb.solve_closed_form(sep, s, xo)
    numeric = tb.solve_numeric(sep, s, xo)
    assert closed, (sep, s, xo)
    d = closed[0]
    assert any(abs(n.input_link - d.input_link) < 1e-8 * s for n in numeric)
    outs, _ = independent_check(d, steps=40)
    assert abs(outs["FT"] - outs["FF"]) < 1e-9 * s
    assert abs(outs["TF"] - outs["FF"]) < 1e-9 * s
    assert abs(outs["FF"] - xo) < 1e-9 * s
    assert abs(outs["TT"] - outs["FF"] - s) < 1e-9 * s


def test_output_position_formula_against_sympy():
    import sympy as sp  # a runtime dependency: never skipped
    m, s, sep = sp.symbols("m s sep", positive=True)
    b = sp.sqrt(sep**2 + s**2 / 4)
    h = sp.sqrt(m**2 - s**2 / 4)
    px, py = s / 2 + sep * h / b, s * h / (2 * b)  # M in FT (right branch)
    x = sp.symbols("x")
    xo = sp.solve(sp.Eq((x - px) ** 2 + py**2, (x - m) ** 2), x)[0]
    for vals in ({m: 51.0, s: 40.0, sep: 50.0}, {m: 13.0, s: 7.0, sep: 3.0}):
        ref = float(xo.subs(vals))
        got = float(tb.output_position_for(float(vals[sep]), float(vals[s]), float(vals[m])))
        assert abs(ref - got) < 1e-9 * abs(ref)


def test_kinematics_vectorised_and_discriminants():
    d = tb.solve_closed_form(50, 40, 150)[0]
    a = np.linspace(0, 40, 7)[:, None]
    b = np.linspace(0, 40, 5)[None, :]
    st = tb.kinematics(d, a, b)
    assert st.output.shape == (7, 5) and st.valid.all()
    # translating both inputs translates the output
    assert np.allclose(st.output[-1, -1] - st.output[0, 0], 40.0, atol=1e-12)
    # far apart inputs cannot be bridged: negative discriminant, invalid
    far = tb.kinematics(d, 0.0, 4 * d.input_link)
    assert far.disc_inputs < 0 and not far.valid and np.isnan(far.output)
    # exactly at the stretch limit: discriminant 0, finite position, flagged
    lim = np.sqrt(4 * d.input_link**2 - 4 * d.sep**2)
    tog = tb.kinematics(d, 0.0, lim)
    assert not tog.valid and np.isfinite(tog.output) and tog.mu_inputs < 1e-5


def test_required_command(cli):
    code, out, err = cli("synth", "three-bar", "--sep", "50", "--stroke", "40", "--output", "70",
                         "--json")
    ans = json.loads(out)
    for key in ("healthy", "input_link", "output_link", "output_position",
                "min_transmission_angle_deg", "reason", "alternatives"):
        assert key in ans
    s = 40.0
    if ans["healthy"]:
        assert code == 0
        designs = [ans]
    else:
        assert code == 1 and ans["reason"]
        assert ans["alternatives"], "no healthy alternatives offered"
        designs = ans["alternatives"]
    for alt in designs:
        assert alt["healthy"] is True
        d = tb.ThreeBarDesign(alt["sep"], alt["stroke"], alt["input_link"], alt["output_link"],
                              alt["output_position"], alt["output_side"])
        outs, mu = independent_check(d)
        assert abs(outs["FT"] - outs["FF"]) <= 1e-3 * d.stroke
        assert abs(outs["TF"] - outs["FF"]) <= 1e-3 * d.stroke
        assert mu >= 45.0 - 1e-6
        assert alt["min_transmission_angle_deg"] >= 45.0
    # whatever is reported as the design for the request is checked too
    if not ans["healthy"] and ans["input_link"] is not None:
        d = tb.ThreeBarDesign(50.0, s, ans["input_link"], ans["output_link"], 70.0,
                              ans["output_side"])
        _, mu = independent_check(d)
        assert mu < 45.0  # it really is unhealthy


@pytest.mark.parametrize("seed", range(8))
def test_never_healthy_below_limits(seed):
    rng = np.random.default_rng(100 + seed)
    sep, s = rng.uniform(5, 100), rng.uniform(5, 80)
    xo = rng.uniform(0.3, 8.0) * (sep + s)
    ans = tb.synthesise(sep, s, xo, alternatives=False)
    for _d, rep, note in ans.candidates:
        if "toggle" in note:
            assert not rep.healthy
    if ans.healthy:
        outs, mu = independent_check(ans.design, steps=40)
        assert mu >= 45.0 - 1e-6
        assert abs(outs["FT"] - outs["FF"]) <= 1e-3 * s


def test_best_design_without_output():
    ans = tb.synthesise(50, 40, None, alternatives=False)
    assert ans.healthy
    outs, mu = independent_check(ans.design)
    assert mu >= 45.0 and abs(outs["FT"] - outs["FF"]) < 1e-9 * 40


def test_healthy_range_edges():
    rng = tb.healthy_range(50, 40)
    assert rng
    for iv in rng:
        for m in iv["m"]:
            x = float(tb.output_position_for(50, 40, m))
            rep = tb.evaluate(tb._design(50, 40, m, x))
            assert rep.healthy


@pytest.mark.parametrize("sep, s, xo", [(200.0, 5.0, 300.0), (1.0, 100.0, 50.0)])
def test_alternatives_when_the_ratio_itself_is_hopeless(sep, s, xo):
    # sep/stroke of 40 and of 0.01 lie far outside the range where any healthy gate exists, so
    # nothing keeping the output or the ratio can be offered: the answer must still suggest
    # healthy designs (another separation or stroke, output free), each independently checked.
    ans = tb.synthesise(sep, s, xo)
    assert not ans.healthy and ans.reason
    assert ans.alternatives, "no healthy alternatives offered"
    kept = {("sep", round(a["sep"], 9)) for a in ans.alternatives if a["sep"] == sep}
    kept |= {("stroke", round(a["stroke"], 9)) for a in ans.alternatives if a["stroke"] == s}
    assert kept == {("sep", sep), ("stroke", s)}  # one keeps the separation, one the stroke
    for alt in ans.alternatives:
        assert alt["healthy"] is True
        d = tb.ThreeBarDesign(alt["sep"], alt["stroke"], alt["input_link"], alt["output_link"],
                              alt["output_position"], alt["output_side"])
        outs, mu = independent_check(d, steps=40)
        assert abs(outs["FT"] - outs["FF"]) <= 1e-3 * d.stroke
        assert abs(outs["TF"] - outs["FF"]) <= 1e-3 * d.stroke
        assert mu >= 45.0 - 1e-6


def test_numeric_solution_skips_sign_changes_across_unassemblable_gaps():
    # Here the gate residual changes sign across m = output (the output link shrinks to zero and
    # O changes side of M), with no assembly in between: brentq used to meet a NaN there and the
    # whole command died with an internal error. The only true root is the closed-form one.
    sep, s, xo = 56.217010679509336, 1.9595755629753917, 315.1392329029357
    num = tb.solve_numeric(sep, s, xo)
    closed = tb.solve_closed_form(sep, s, xo)
    assert len(num) == len(closed) == 1
    assert abs(num[0].input_link - closed[0].input_link) < 1e-9 * s
    outs, _ = independent_check(num[0], steps=40)
    assert abs(outs["FT"] - outs["FF"]) <= 1e-9 * xo
    ans = tb.synthesise(sep, s, xo, alternatives=False)
    assert not ans.healthy and ans.reason  # transmission 21 deg, link ratio 0.05
