"""M/K(/T) circles: the worked examples of 004_… and random known linkages.

References: the forward position of a known chain (ground + sum L e^{i theta}), the pole
construction of the paper (eqs. 2-9), the paper's circle-intersection formula (eqs. 10-14) and
the compatibility linkage (Appendix A) -- each a different computation from the t-plane solver.
"""

from __future__ import annotations

import numpy as np
import pytest

from mechc.linkage_synthesis import mk_circles as mk
from mechc.linkage_synthesis.circles import (
    apollonius,
    circumcircle,
    gcircle_to_circle,
    intersect_circles,
    intersect_gcircles,
)
from mechc.linkage_synthesis.examples import EXAMPLES, printed_residual

TOL = 1e-9


def forward_points(ground, links, angles):
    """Where a known chain puts its end in every position."""
    return ground + np.einsum("l,lj->j", links, np.exp(1j * angles))


def reproduces(sol: mk.ChainSolution, problem: mk.ChainProblem) -> float:
    """Max relative miss of the prescribed points and of the prescribed rotations."""
    pts = forward_points(sol.ground, sol.links, sol.angles)
    miss = np.max(np.abs(pts - problem.points)) / problem.scale
    known = ~np.isnan(problem.angles)
    rot = np.max(np.abs(np.angle(np.exp(1j * (sol.angles[known] - problem.angles[known])))))
    return max(miss, rot)


# --- worked examples -----------------------------------------------------------------------------


def test_fig1_circles_agree_with_pole_construction():
    pr = EXAMPLES["fig1"].problem
    res = mk.solve_chain(pr)
    assert res.mode == "circle"
    cM, cK = res.circles[0].circles["M"], res.circles[0].circles["K"]
    pM, pK = mk.dyad_circles_from_poles(pr, np.radians(-110))
    assert abs(cM.centre - pM.centre) < 1e-12 and abs(cM.radius - pM.radius) < 1e-12
    assert abs(cK.centre - pK.centre) < 1e-12 and abs(cK.radius - pK.radius) < 1e-12
    # the paper's observation: M circle through P13, P23; K circle through P13, P23'
    p13, p23, p23i = mk.pole(pr, 0, 2), mk.pole(pr, 1, 2), mk.image_pole(pr, 1, 2)
    assert cM.contains(p13) and cM.contains(p23)
    assert cK.contains(p13) and cK.contains(p23i)
    # and every point of the circle is a solution: pick beta3 values, solve linearly
    for b3 in (-170.0, -20.0, 60.0):
        ang = pr.angles.copy()
        ang[0, 2] = np.radians(b3)
        lin = mk.solve_chain(mk.ChainProblem(pr.points, ang, 0))
        s = lin.solutions[0]
        assert s.residual < 1e-14
        assert cM.contains(s.ground) and cK.contains(s.pivots[1])


def test_fig4_two_dyads_exact():
    ex = EXAMPLES["fig4"]
    res = mk.solve_chain(ex.problem)
    assert res.mode == "intersection" and len(res.solutions) == 2
    for s in res.solutions:
        assert s.residual < 1e-13
        assert reproduces(s, ex.problem) < 1e-12
        # the ground pivot lies on both M circles, the moving pivot on both K circles
        for pc in res.circles:
            assert pc.circles["M"].contains(s.ground)
            assert pc.circles["K"].contains(s.pivots[1])


def test_figA3_five_position_dyad():
    ex = EXAMPLES["figA3"]
    res = mk.solve_chain(ex.problem)
    assert res.mode == "search" and res.solutions
    for s in res.solutions:
        assert s.residual < 1e-12 and reproduces(s, ex.problem) < 1e-12
        # the three M circles (positions 3, 4, 5) are concurrent at the ground pivot
    s0 = res.solutions[0]
    assert all(pc.circles["M"].contains(s0.ground, 1e-9) for pc in res.circles)


@pytest.mark.parametrize("name", ["figA5", "figA6"])
def test_triad_examples_solved(name):
    ex = EXAMPLES[name]
    res = mk.solve_chain(ex.problem)
    assert res.solutions, res.message
    for s in res.solutions:
        assert s.residual < 1e-12
        assert reproduces(s, ex.problem) < 1e-12


def test_fig7_family_members_exact_and_printed_answer_off():
    ex = EXAMPLES["fig7"]
    res = mk.solve_chain(ex.problem)
    assert res.mode == "family" and len(res.family) > 50
    assert max(reproduces(s, ex.problem) for s in res.family) < 1e-12
    near = mk.family_member_near(ex.problem, ex.printed["solutions"][0])
    assert near.residual < 1e-12
    # the printed triad misses some position by more than 10 % of the problem size
    assert printed_residual(ex.problem, ex.printed["solutions"][0]).max() > 0.1


def test_figA4_four_position_triad_circles():
    pr = EXAMPLES["figA4"].problem
    for a3 in (0.0, 45.0, 120.0):
        ang = pr.angles.copy()
        ang[1, 2] = np.radians(a3)
        res = mk.solve_chain(mk.ChainProblem(pr.points, ang, 1))
        assert res.mode == "circle"
        circ = res.circles[0].circles
        # points of the circles: fix alpha4 too and solve linearly; they must lie on M, K, T
        for a4 in (-150.0, 10.0, 100.0):
            ang2 = ang.copy()
            ang2[1, 3] = np.radians(a4)
            s = mk.solve_chain(mk.ChainProblem(pr.points, ang2, 1)).solutions[0]
            assert s.residual < 1e-13
            for name, p in zip("MKT", s.pivots):
                assert circ[name].contains(p, 1e-9)


# --- random known linkages -------------------------------------------------------------------


def random_chain(rng, k, n):
    links = rng.normal(size=k) + 1j * rng.normal(size=k)
    angles = np.zeros((k, n))
    angles[:, 1:] = rng.uniform(-np.pi, np.pi, size=(k, n - 1))
    ground = complex(rng.normal(), rng.normal())
    return ground, links, angles


def problem_from(ground, links, angles, free_link, free_known):
    pts = forward_points(ground, links, angles)
    ang = angles.copy()
    unknown = [j for j in range(1, angles.shape[1]) if j not in free_known]
    ang[free_link, unknown] = np.nan
    return mk.ChainProblem(pts, ang, free_link)


def found_truth(res, links):
    return any(np.max(np.abs(s.links - links)) < 1e-7 for s in res.solutions)


@pytest.mark.parametrize("seed", range(5))
def test_random_dyads(seed):
    rng = np.random.default_rng(seed)
    for n, known in ((3, [1, 2]), (4, [1]), (5, [])):
        g, L, A = random_chain(rng, 2, n)
        pr = problem_from(g, L, A, 0, known)
        res = mk.solve_chain(pr)
        assert res.solutions, (n, res.message)
        for s in res.solutions:
            assert reproduces(s, pr) < TOL
        assert found_truth(res, L), (n, res.message)


@pytest.mark.parametrize("seed", range(4))
def test_random_triads(seed):
    rng = np.random.default_rng(10 + seed)
    for n, known in ((4, [1, 2, 3]), (5, [1, 2]), (6, [1])):
        g, L, A = random_chain(rng, 3, n)
        pr = problem_from(g, L, A, 1, known)
        res = mk.solve_chain(pr)
        assert res.solutions, (n, res.message)
        for s in res.solutions:
            assert reproduces(s, pr) < TOL
        assert found_truth(res, L), (n, res.message)


def test_random_triad_seven_positions():
    rng = np.random.default_rng(7)
    g, L, A = random_chain(rng, 3, 7)
    pr = problem_from(g, L, A, 1, [])
    res = mk.solve_chain(pr)
    assert res.solutions
    for s in res.solutions:
        assert reproduces(s, pr) < TOL
    assert found_truth(res, L)


# --- circle geometry -------------------------------------------------------------------------


def test_generalised_intersection_matches_paper_formula():
    rng = np.random.default_rng(3)
    for _ in range(200):
        c1, c2 = complex(*rng.normal(size=2)), complex(*rng.normal(size=2))
        r1, r2 = rng.uniform(0.2, 2, size=2)
        ref = intersect_circles(c1, r1, c2, r2)
        # the same circles as generalised circles: |t - c|^2 - r^2 = 0 -> A=1, B=-conj(c)
        hi, lo, ok = intersect_gcircles(1.0, -np.conj(c1), abs(c1) ** 2 - r1**2,
                                        1.0, -np.conj(c2), abs(c2) ** 2 - r2**2)
        assert bool(ok) == (len(ref) > 0)
        if len(ref) == 2:
            got = sorted([complex(hi), complex(lo)], key=lambda z: (z.real, z.imag))
            want = sorted(ref, key=lambda z: (z.real, z.imag))
            assert max(abs(a - b) for a, b in zip(got, want)) < 1e-9


def test_apollonius_locus():
    rng = np.random.default_rng(4)
    a, b, c, d = rng.normal(size=4) + 1j * rng.normal(size=4)
    A, B, C = apollonius(a, b, c, d)
    circ = gcircle_to_circle(A, B, C)
    for th in np.linspace(0, 2 * np.pi, 9):
        t = circ.centre + circ.radius * np.exp(1j * th)
        assert abs(abs(a + b * t) - abs(c + d * t)) < 1e-10
    cc = circumcircle(1, 1j, -1)
    assert abs(cc.centre) < 1e-15 and abs(cc.radius - 1) < 1e-15


# --- problem statements that cannot be solved are refused with the reason ------------------------


def test_refusals():
    with pytest.raises(mk.SynthesisError, match="at least 3 positions"):
        mk.chain_problem([0, 1], {"alpha": [0, 10], "beta": [0, None]})
    with pytest.raises(mk.SynthesisError, match="only one link"):
        mk.chain_problem([0, 1, 2], {"alpha": [0, None, 3], "beta": [0, None, None]})
    tri = mk.chain_problem([0, 1, 2 + 1j, 3], {"beta": [0, 5, 9, 14], "alpha": [0, None, None,
                                                                              None],
                                               "gamma": [0, -10, -20, -30]})
    with pytest.raises(mk.SynthesisError, match="give alpha2, alpha3"):
        mk.solve_chain(tri)
    # a dyad in 4 positions without beta2 is a one-parameter family (sampled, each exact)
    pr = EXAMPLES["fig4"].problem
    ang = pr.angles.copy()
    ang[0, 1] = np.nan
    res = mk.solve_chain(mk.ChainProblem(pr.points, ang, 0))
    assert res.mode == "family" and not res.solutions and res.family
    assert max(reproduces(s, res.problem) for s in res.family) < TOL


def test_fig2_circles_for_several_beta2_share_the_poles():
    # 004_… Fig. 2: six values of beta2, 60 deg apart; every M circle passes through P13 and
    # P23, every K circle through P13 and P23'
    pr = EXAMPLES["fig1"].problem
    ang = pr.angles.copy()
    ang[0, 1] = np.nan
    pr2 = mk.ChainProblem(pr.points, ang, 0)
    res = mk.solve_chain(pr2)
    assert res.mode == "circle" and len(res.circles) == 6
    p13, p23, p23i = mk.pole(pr, 0, 2), mk.pole(pr, 1, 2), mk.image_pole(pr, 1, 2)
    for pc in res.circles:
        assert pc.circles["M"].contains(p13) and pc.circles["M"].contains(p23)
        assert pc.circles["K"].contains(p13) and pc.circles["K"].contains(p23i)


def test_more_free_choices_than_needed_are_checked():
    # Fig. 4 with beta3 also fixed: linear in positions 1-3, position 4 only checked
    pr = EXAMPLES["fig4"].problem
    exact = mk.solve_chain(pr).solutions[0]
    ang = pr.angles.copy()
    ang[0, 2] = exact.angles[0, 2]
    res = mk.solve_chain(mk.ChainProblem(pr.points, ang, 0))
    assert res.mode == "linear" and len(res.solutions) == 1
    assert np.max(np.abs(res.solutions[0].links - exact.links)) < 1e-9
    ang[0, 2] += 0.05  # a beta3 for which position 4 is out of reach
    res = mk.solve_chain(mk.ChainProblem(pr.points, ang, 0))
    assert not res.solutions and res.rejected == 1
