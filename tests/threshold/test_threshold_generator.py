"""Every function of three inputs as a threshold generator, proven kinematically."""

from __future__ import annotations

from collections import Counter
from functools import cache

import numpy as np
import pytest

from mechc.errors import DesignError
from mechc.geometry.circles import line_angle_deg
from mechc.threshold.functions import (
    function_value,
    input_matrix,
    npn_class_ids,
    truth_table_from_fv,
)
from mechc.threshold.generator import design_generator
from mechc.threshold.weights import realise, static_hazards

STROKE = 20.0
SAMPLES = 50
MARGIN = 0.05  # of stroke (the proofs' margin, docs/mechanism.md)
X = input_matrix(3)

# Minimum thresholds per NPN class from 001 Table II (Mow and Fu): class representative FV -> k.
# Representatives written from Table II's vectors (see test_threshold_weights.TABLE_II).
_TABLE_II_K = {15: 1, 31: 1, 23: 1, 63: 1, 127: 1, 111: 2, 30: 2, 151: 2, 61: 2, 126: 2, 60: 2,
               27: 3, 105: 3}


def min_thresholds(fv: int) -> int:
    ids = npn_class_ids(3)
    if fv in (0, 255):
        return 0
    return next(k for rep, k in _TABLE_II_K.items() if ids[rep] == ids[fv])


# Functions whose every realisation has a static hazard (proved by exhaustion in
# test_threshold_weights.test_no_weights_avoid_the_48_hazards).
UNAVOIDABLE = {fv for fv in range(256)
               if static_hazards(realise(fv).weights, truth_table_from_fv(fv))}
# Every one of them gets a generator whose F moves in two dimensions (mechc.threshold.planar):
# x1 (x2 xor x3) (FV 6) with F on link AD of the 45-degree eight-bar, the multiplexer class
# (FV 27) with the free eight-bar (AD tilted, E a coupler point of BG).
MULTIPLEXER = {fv for fv in UNAVOIDABLE if npn_class_ids(3)[fv] == npn_class_ids(3)[27]}


@cache
def design(fv: int):
    return design_generator(fv, stroke_mm=STROKE)


def changes() -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """All 24 single-input changes, SAMPLES each, as one (3, 24 * SAMPLES) input array."""
    u = np.linspace(0.0, 1.0, SAMPLES)
    cols, meta = [], []
    for a in range(8):
        for j in range(3):
            b = a ^ (4 >> j)
            x = np.repeat(X[a][:, None].astype(float), SAMPLES, 1)
            x[j] = X[a][j] + (X[b][j] - X[a][j]) * u
            cols.append(x)
            meta.append((a, b, j))
    return np.concatenate(cols, 1), meta


def held_violations(fv: int) -> set[tuple[int, int]]:
    """Changes (from minterm, input) where an output that must hold leaves the margin."""
    d = design(fv)
    tt = truth_table_from_fv(fv)
    x, meta = changes()
    out = d.kinematics(x).output.reshape(len(meta), SAMPLES)
    bad = set()
    for (a, b, j), o in zip(meta, out):
        if tt[a] == tt[b] and np.abs(o - tt[a]).max() > MARGIN:
            bad.add((a, j))
    return bad


def test_unavoidable_set():
    assert len(UNAVOIDABLE) == 48
    # two NPN classes: x1 (x2 xor x3) and the 3-threshold class of |W| = (3, 2, 1)
    ids = npn_class_ids(3)
    assert len({int(ids[fv]) for fv in UNAVOIDABLE}) == 2
    assert len(MULTIPLEXER) == 24 and MULTIPLEXER < UNAVOIDABLE


@pytest.mark.parametrize("fv", range(256))
def test_generator_proof(fv):
    tt = truth_table_from_fv(fv)
    d = design(fv)
    assert d.realisation.truth_table() == tt
    assert d.realisation.k == min_thresholds(fv)
    assert d.ok, [str(c) for c in d.checks if not c.passed]
    rest = d.kinematics(X.T.astype(float)).output
    assert np.abs(rest - np.array(tt)).max() <= MARGIN
    x, meta = changes()
    ks = d.kinematics(x)
    out = ks.output.reshape(len(meta), SAMPLES)
    for (a, b, _j), o in zip(meta, out):
        assert abs(o[0] - tt[a]) <= MARGIN and abs(o[-1] - tt[b]) <= MARGIN
        if tt[a] == tt[b]:
            assert np.abs(o - tt[a]).max() <= MARGIN, (a, b)
    if d.kind == "generator":
        # transmission angles recomputed from the joint positions along every change
        jt = ks.joints
        mu = [line_angle_deg(jt["E"] - jt["D"], jt["A"] - jt["D"]),
              line_angle_deg(jt["F"] - jt["J"], np.asarray(d.pivots["K"]) - jt["J"])]
        if "G" in jt:
            mu.append(line_angle_deg(jt["C"] - jt["G"], jt["B"] - jt["G"]))
        assert min(m.min() for m in mu) >= 45.0 - 1e-6
        pa = d.follower.pressure_angle(ks.cam_angle, d.program, d.loop.orientation)
        assert pa.max() <= 30.0


def test_planar_generators_are_exactly_the_cured_class():
    cured = {fv for fv in range(256) if design(fv).planar is not None}
    assert cured == UNAVOIDABLE
    assert 6 in cured and 27 in cured  # x1 (x2 xor x3) and the multiplexer, 001 §3.7.1
    free = {fv for fv in cured if design(fv).planar.free is not None}
    assert free == MULTIPLEXER
    for fv in cured:
        d = design(fv)
        # the params still mean the minimum threshold realisation (with its hazards) ...
        assert d.realisation.truth_table() == truth_table_from_fv(fv)
        assert static_hazards(d.realisation.weights, truth_table_from_fv(fv))
        # ... while the mechanism's F really moves in two dimensions: its 8 rest positions
        # are not collinear (smallest singular value of the centred points)
        rest = d.kinematics(X.T.astype(float)).joints["F"]
        assert np.linalg.svd(rest - rest.mean(0), compute_uv=False)[1] > 0.1 * d.scale


def _segments_meet(p, q, r, s) -> bool:
    """Closed segments pq and rs meet (collinear overlaps included)."""
    def cross(a, b):
        return a[0] * b[1] - a[1] * b[0]
    d1, d2, w = q - p, s - r, r - p
    den = cross(d1, d2)
    if abs(den) > 1e-12:
        t, u = cross(w, d2) / den, cross(w, d1) / den
        return -1e-9 <= t <= 1 + 1e-9 and -1e-9 <= u <= 1 + 1e-9
    if abs(cross(w, d1)) > 1e-9:
        return False  # parallel, on different lines
    ax = d1 if abs(d1[0]) + abs(d1[1]) > 0 else d2
    proj = [float(np.dot(v, ax)) for v in (p, q, r, s)]
    return max(min(proj[:2]), min(proj[2:])) <= min(max(proj[:2]), max(proj[2:])) + 1e-9


def test_multiplexer_needs_three_directions_of_F():
    # Why FV 27's class is not cured (docs/threshold.md §2): its held paths 010-000-001-101
    # (output 0) and 011-111-110-100 (output 1) must map to disjoint curves. For F an affine
    # map of the inputs, random maps with two parallel input directions never separate them,
    # while general maps often do (brute force, independent of the mechanism).
    zero = [np.array(v, float) for v in ((0, 1, 0), (0, 0, 0), (0, 0, 1), (1, 0, 1))]
    one = [np.array(v, float) for v in ((0, 1, 1), (1, 1, 1), (1, 1, 0), (1, 0, 0))]
    assert truth_table_from_fv(27) == tuple(int(m in (3, 4, 6, 7)) for m in range(8))
    rng = np.random.default_rng(1)

    def disjoint(M):
        a, b = [M @ p for p in zero], [M @ p for p in one]
        return not any(_segments_meet(a[i], a[i + 1], b[j], b[j + 1])
                       for i in range(3) for j in range(3))

    general = sum(disjoint(rng.normal(size=(2, 3))) for _ in range(400))
    parallel = 0
    for k in range(600):
        M = rng.normal(size=(2, 3))
        i, j = [c for c in range(3) if c != k % 3]
        M[:, j] = M[:, i] * rng.normal()
        parallel += disjoint(M)
    assert general > 100 and parallel == 0


def test_points_on_link_ad_move_alike_for_cranks_b_and_c():
    # the first-order fact behind the test above: any point of link AD moves, for cranks B and
    # C, along the same direction (AD's rotation about A), whatever its proportions and offset
    from mechc.threshold.planar import planar_layout

    lay = planar_layout(0.7, 1.45, 0.3)
    rng = np.random.default_rng(2)
    for _ in range(5):
        t = rng.uniform(0.1, 0.9, 3)
        eps = 1e-6

        def f(tt):
            return lay.solve({c: lay.tip(c, tt[i], False) for i, c in enumerate("ABC")})["F"]

        dB = (f(t + [0, eps, 0]) - f(t)) / eps
        dC = (f(t + [0, 0, eps]) - f(t)) / eps
        dA = (f(t + [eps, 0, 0]) - f(t)) / eps
        sin_bc = abs(dB[0] * dC[1] - dB[1] * dC[0]) / np.hypot(*dB) / np.hypot(*dC)
        sin_ab = abs(dA[0] * dB[1] - dA[1] * dB[0]) / np.hypot(*dA) / np.hypot(*dB)
        assert sin_bc < 1e-4 and sin_ab > 1e-2


def _f_polyline(fv: int, path: list[int]) -> np.ndarray:
    """F along a path of single-input changes (minterms), SAMPLES per change."""
    d = design(fv)
    u = np.linspace(0.0, 1.0, SAMPLES)[:-1]  # each change's end is the next one's start
    cols = [X[a][:, None] + (X[b] - X[a])[:, None] * u for a, b in zip(path, path[1:])]
    cols.append(X[path[-1]][:, None])
    return d.kinematics(np.concatenate(cols, 1).astype(float)).joints["F"]


@pytest.mark.parametrize("fv", [27, 92])  # 92: permuted, X' centres, complement
def test_free_eight_bar_keeps_the_held_paths_apart_in_the_plane(fv):
    # Necessary for any cam: F's images of the output-0 path 010-000-001-101 and the output-1
    # path 011-111-110-100 (FV 27's labels, mapped through the wiring) must not meet. Checked
    # on F itself, segment by segment, independently of loop FJK and the cam.
    d = design(fv)
    tt = truth_table_from_fv(fv)
    zero = [m for m in range(8) if tt[m] == 0]
    one = [m for m in range(8) if tt[m] == 1]

    def path(ms):  # the held edges of one output value form a path (brute force)
        adj = {m: [n for n in ms if bin(m ^ n).count("1") == 1] for m in ms}
        start = next(m for m in ms if len(adj[m]) == 1)
        out = [start]
        while len(out) < len(ms):
            out.append(next(n for n in adj[out[-1]] if n not in out))
        return out

    a, b = _f_polyline(fv, path(zero)), _f_polyline(fv, path(one))
    assert not any(_segments_meet(a[i], a[i + 1], b[j], b[j + 1])
                   for i in range(len(a) - 1) for j in range(len(b) - 1))
    gap = np.hypot(*(a[:, None, :] - b[None, :, :]).T).min() / d.scale
    assert gap > 0.05  # units of l: well apart, not a near miss
    assert d.planar.free is not None and d.threshold_gaps_deg[0] > 25.0


def test_free_eight_bar_moves_e_in_two_directions():
    # The reason the free eight-bar succeeds where F on link AD cannot: E, a coupler point of
    # BG, moves in clearly different directions for cranks B and C (finite differences), and
    # the direction of AD responds to crank A's position (DE turns as A moves).
    d = design(27)
    t = np.full((3, 1), 0.5)
    eps = 1e-6
    e0 = d.kinematics(t).joints["E"][0]
    dirs = []
    for k in (1, 2):
        tk = t.copy()
        tk[k] += eps
        dirs.append((d.kinematics(tk).joints["E"][0] - e0) / eps)
    (ax, ay), (bx, by) = dirs
    sin_bc = abs(ax * by - ay * bx) / np.hypot(ax, ay) / np.hypot(bx, by)
    assert sin_bc > 0.9  # more than 64 deg apart
    de = [d.kinematics(np.array([[ta], [0.5], [0.5]])).joints for ta in (0.0, 1.0)]
    ang = [np.degrees(np.arctan2(*(j["E"][0] - j["D"][0])[::-1])) for j in de]
    assert abs(ang[1] - ang[0]) > 30.0  # the 45-degree layout's DE turns by about 2 alpha


@pytest.mark.parametrize("fv", [157, 27])
def test_joint_distances_are_the_link_lengths_in_mm(fv):
    d = design(fv)
    rng = np.random.default_rng(3)
    jt = d.kinematics(rng.random((3, 100))).joints
    L = d.links
    pairs = [("A", "D", "AD"), ("D", "E", "DE"), ("B", "G", "BG"), ("C", "G", "CG"),
             ("F", "J", "FJ")]
    if d.planar is None:
        pairs.append(("A", "F", "AF"))
    for p, q, key in pairs:
        assert np.allclose(np.hypot(*(jt[p] - jt[q]).T), L[key])
    for body in (("A", "D", "F"), ("B", "G", "E")):  # rigid bodies keep their shapes
        for p, q in ((0, 2), (1, 2)):
            dist = np.hypot(*(jt[body[p]] - jt[body[q]]).T)
            assert np.ptp(dist) < 1e-9 * max(1.0, dist.max())
    assert np.allclose(np.hypot(*(jt["J"] - np.asarray(d.pivots["K"])).T), L["JK"])
    z = d.pivots["Z'" if d.follower.primed else "Z"]
    assert np.allclose(np.hypot(*(jt["H"] - np.asarray(z)).T), L["ZH"])


def test_chapter_iii_examples():
    # §3.8.1 FV 157: separator of Fig. 33(d), |W| = (2,2,1), two thresholds.
    d = design(157)
    assert sorted(map(abs, d.realisation.weights)) == [1, 2, 2] and d.realisation.k == 2
    # §3.8.2 full adder: sum FV 105 on the (1,1,1) separator with three thresholds; the carry
    # (majority, FV 23) on the same separator with one.
    s, c = design(105), design(23)
    assert sorted(map(abs, s.realisation.weights)) == [1, 1, 1] and s.realisation.k == 3
    assert sorted(map(abs, c.realisation.weights)) == [1, 1, 1] and c.realisation.k == 1
    assert function_value(tuple(int(v) for v in X.sum(1) >= 2)) == 23
    # the sum's F positions are shared by the carry: same loop and separator
    assert s.separator == c.separator


def test_literals_and_constants():
    assert design(0).kind == "constant" and design(255).kind == "constant"
    kinds = Counter(design(fv).kind for fv in range(256))
    assert kinds["literal"] == 6  # x_i and their complements
    d = design(240)  # not x1
    assert d.literal == (0, True)
    assert d.kinematics(np.array([[0.0, 1.0], [0, 0], [1, 1]])).output.tolist() == [1.0, 0.0]


def test_failed_check_is_an_error_with_its_number():
    with pytest.raises(DesignError, match=r"cam pressure angle = \d"):
        design_generator(105, pressure_limit_deg=10.0)
    d = design_generator(105, pressure_limit_deg=10.0, strict=False)
    assert not d.check("cam pressure angle").passed
