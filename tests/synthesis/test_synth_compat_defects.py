"""Compatibility linkage (Appendix A of 004_…) and the circuit/branch defect check."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.linkage_synthesis import mk_circles as mk
from mechc.linkage_synthesis.compatibility import compatibility_linkage, solve_compatibility
from mechc.linkage_synthesis.defects import FourBar, check_dyads, check_loops, loop_signs
from mechc.linkage_synthesis.examples import EXAMPLES


@pytest.mark.parametrize("beta2", [-44.775, -45.508, 30.0])
def test_table_a1_compatibility_agrees_with_circles(beta2):
    # Table A1 (loop three dyad): positions and alphas as printed; beta2 free.
    base = EXAMPLES["tableA1"].problem
    ang = base.angles.copy()
    ang[0, 1] = np.radians(beta2)
    pr = mk.ChainProblem(base.points, ang, 0)
    comp = solve_compatibility(pr, np.radians(beta2))
    circ = mk.solve_chain(pr).solutions
    assert len(comp) == len(circ) == 2
    for c in comp:
        assert c.residual < 1e-12
        assert any(np.max(np.abs(c.links - s.links)) < 1e-10 for s in circ)
    # the compatibility loop closes: D1 + D2 e^{ib2} + D3 e^{ib3} + D4 e^{ib4} = 0
    cl = compatibility_linkage(pr)
    for c in comp:
        loop = (cl.d1 + cl.d2 * np.exp(1j * c.beta2) + cl.d3 * np.exp(1j * c.beta3)
                + cl.d4 * np.exp(1j * c.beta4))
        assert abs(loop) < 1e-12 * max(abs(cl.d1), abs(cl.d2), abs(cl.d3), abs(cl.d4))


def make_case(lengths, input_deg, signs, seed=0):
    """Positions of a coupler point of a known four-bar, each position in a chosen assembly;
    returns the two dyads synthesised from them (the true ones among the solutions)."""
    g, i, c, f = lengths
    fb_true = FourBar(0j, complex(g, 0), complex(i, 0), 0j)  # moving pivots filled below
    ka0 = i * np.exp(1j * np.radians(input_deg[0]))
    # follower pivot position of the true linkage: solve with given lengths
    kas, kbs = [], []
    for th, sg in zip(np.radians(input_deg), signs):
        ka = i * np.exp(1j * th)
        d = abs(fb_true.gb - ka)
        a = (c * c - f * f + d * d) / (2 * d)
        h = np.sqrt(c * c - a * a)
        e1 = (fb_true.gb - ka) / d
        cands = [ka + a * e1 + h * 1j * e1, ka + a * e1 - h * 1j * e1]
        kb = [p for p in cands if loop_signs(ka, p, fb_true.gb) == sg][0]
        kas.append(ka)
        kbs.append(kb)
    kas, kbs = np.array(kas), np.array(kbs)
    alpha = np.angle((kbs - kas) / (kbs[0] - kas[0]))
    rng = np.random.default_rng(seed)
    z = complex(*rng.normal(size=2))
    pts = kas + z * np.exp(1j * alpha)
    beta_in = np.angle(kas / kas[0])
    beta_out = np.angle((kbs - fb_true.gb) / (kbs[0] - fb_true.gb))
    dyads = []
    for beta, W in ((beta_in, kas[0]), (beta_out, kbs[0] - fb_true.gb)):
        ang = np.vstack([np.r_[0, beta[1], np.nan, np.nan], alpha])
        res = mk.solve_chain(mk.ChainProblem(pts, ang, 0))
        sol = [s for s in res.solutions if abs(s.links[0] - W) < 1e-8]
        assert sol, res.message
        dyads.append(sol[0])
    assert ka0 == kas[0]
    return dyads


def test_defect_check_flags_branch_change():
    # non-Grashof (2 + 3 > 2.5 + 2.2): the two assemblies are branches joined at toggles
    drv, fol = make_case((3.0, 2.0, 2.5, 2.2), [60, 70, 80, 90], [1, 1, -1, -1])
    rep = check_dyads(drv, fol)
    assert rep.signs == [1, 1, -1, -1]
    assert not rep.grashof and rep.branch_defect and not rep.ok


def test_defect_check_flags_circuit_change():
    # crank-rocker (1 + 4 <= 3.5 + 3): the assemblies are separate circuits
    drv, fol = make_case((4.0, 1.0, 3.5, 3.0), [0, 40, 80, 120], [1, -1, -1, -1], seed=1)
    rep = check_dyads(drv, fol)
    assert rep.input_rotates and rep.circuit_defect and not rep.ok


def test_defect_check_passes_clean_case():
    drv, fol = make_case((4.0, 1.0, 3.5, 3.0), [0, 40, 80, 120], [1, 1, 1, 1], seed=2)
    rep = check_dyads(drv, fol)
    assert rep.ok and not rep.toggles and rep.signs == [1, 1, 1, 1]
    assert 0 < rep.min_transmission_deg <= 90


def test_defect_check_finds_toggle_on_the_way():
    # non-Grashof: the input can only rock within about +-139 deg.  All positions are in the
    # same assembly, but going from 130 to -130 deg the short way (through 180) the input meets
    # the toggle at its limit: a branch defect that the sign test alone would miss.
    drv, fol = make_case((3.0, 2.0, 2.5, 2.2), [100, 130, -130, -100], [1, 1, 1, 1], seed=3)
    rep = check_dyads(drv, fol)
    assert rep.signs == [1, 1, 1, 1]
    assert rep.branch_defect and [leg for leg, _ in rep.toggles] == [2]
    _, ang = rep.toggles[0]
    assert 130 < ang <= 180 or ang <= -130  # where the input runs out of reach


def test_six_bar_loop_check():
    rng = np.random.default_rng(5)
    n = 4
    a = rng.normal(size=n) + 1j * rng.normal(size=n)
    b = rng.normal(size=n) + 1j * rng.normal(size=n)
    c = b + (b - a) * np.exp(1j * rng.uniform(0.2, 2.9, size=n))  # all on the + side
    assert (loop_signs(a, b, c) == 1).all()
    flipped = c.copy()
    flipped[2] = b[2] + (b[2] - a[2]) * np.exp(-1j * 1.0)  # position 3 on the other side
    out = check_loops([(a, b, c), (a, b, flipped)])
    assert not out[0]["defect"]
    assert out[1]["defect"] and out[1]["signs"] == [1, 1, -1, 1]
