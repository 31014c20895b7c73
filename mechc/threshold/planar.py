"""Generators whose output point F moves in two dimensions: the cure for static hazards that no
threshold realisation avoids (docs/threshold.md §2).

In a threshold generator F moves along one "sum" direction, so when an input of weight 2 or 3
changes, the cam sweeps through the level of the other output value. Here the eight-bar is
proportioned far from the linear approximation (E beyond G, F off the line AD), so F's rest
positions and paths spread over the plane. The cam angle -- the direction of KJ, a nonlinear
function of F's position whose level sets are circles of radius FJ -- is then chosen so that
every output that must hold keeps its cam angles inside ranges of its own value; the follower
program puts one rise or return between adjacent ranges of different values.

*Held sets*: each rest state, and each single-input change with equal outputs at its ends (the
path of F taken about both fixed centres X and X', so one design serves every wiring). The
*separation* is the smallest cam-angle distance between a held set of output 0 and one of
output 1; it is what the rises and returns have to fit in, like a threshold gap.

The design is a search per NPN class: over the wirings of the inputs to the cranks (which input
on which crank, which cranks turn about X') up to output complement, the assembly branch of J,
and the continuous p1 (AF/AD), p2 (BE/BG), F's offset from AD, K, FJ, JK: Sobol screening, then
Nelder-Mead on the best few. The separator's first-order motion explains which classes it can
serve: a point on link AD moves as crank pin A plus a rotation of AD, so cranks B and C move F
along the same direction (to first order). For x1(x2 xor x3) that is enough; for the multiplexer
class (FV 27) it is not, and the *free eight-bar* (:func:`free_layout`: AD tilted, E a coupler
point of BG, searched by :mod:`mechc.threshold.freebar`) serves it (docs/threshold.md §2).
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize
from scipy.stats import qmc

from mechc.geometry.circles import branch_of, circle_meeting, line_angle_deg, polar, quarter_turn
from mechc.threshold.functions import input_matrix, npn_canonical, truth_table_from_fv
from mechc.threshold.linkage import MAX_LINK, MAX_TURN_DEG, MIN_LINK, ThresholdLoop
from mechc.threshold.separator import Proportions, SeparatorLayout, input_stroke, layout
from mechc.threshold.weights import realise, static_hazards

P1_MAX = 4.0 / 3.0  # F at most l/3 beyond D, as for threshold generators
P2_RANGE = (0.2, 1.5)  # E at most l/2 beyond G
OFFSET_MAX = 1.2  # |F off AD| / AD
SCREEN_P2 = (1.5,)  # shorter E extensions break the 45 deg limit at D or G
SCREEN_CANDIDATES = 16384
SCREEN_SAMPLES = 12
N_POLISH = 6
SEARCH_MARGIN_DEG = 1.0  # loop FJK's transmission kept this far above mu_min in the search
TRANSMISSION_TOL = 1e-6  # deg, as in mechc.threshold.generator


def planar_layout(p1: float, p2: float, offset: float, mu_min_deg: float = 45.0
                  ) -> SeparatorLayout:
    """The eight-bar of :func:`mechc.threshold.separator.layout` with free proportions: AF/AD =
    p1, BE/BG = p2, F ``offset`` x AD to the left of A -> D. The weight pattern is nominal."""
    pr = Proportions((1, 1, 1), (1 - p1, p1 * (1 - p2), p1 * p2), p1, p2)
    return layout((1, 1, 1), mu_min_deg, proportions=pr, f_offset=offset)


#: Parameters of the free eight-bar (units of l, angles in rad, every input at t = 0): AD's
#: angle from the vertical (clockwise), |AD|, direction of D -> E, |DE|, direction of B -> G
#: (|BG| = l), E's coordinates on link BG (along B -> G, and to its left), |CG|, direction of
#: C -> G, F's coordinates on link AD (along A -> D, and to its left).
FREE_NAMES = ("beta", "AD", "gamma", "DE", "BG_dir", "BE", "E_left", "CG", "CG_dir", "AF",
              "F_left")


def free_layout(x: tuple[float, ...], mu_min_deg: float = 45.0) -> SeparatorLayout:
    """The eight-bar with every proportion free (:data:`FREE_NAMES`): same links, joints and
    cranks as :func:`~mechc.threshold.separator.layout`, but AD tilted and E a coupler point of
    BG, so that the three cranks move D's direction, E and F in genuinely different ways."""
    beta, ad, gam, de, bg_dir, be, e_left, cg, cg_dir, af, f_left = (float(v) for v in x)
    s_i, _alpha = input_stroke(mu_min_deg)
    delta = float(np.arcsin(s_i / 2))
    a0 = np.array([-np.sin(delta), np.cos(delta)])  # pin A at t = 0, X_A at the origin
    d0 = a0 + polar(np.pi / 2 - beta, ad)
    e0 = d0 + polar(gam, de)
    ub = polar(bg_dir)
    b0 = e0 - be * ub - e_left * np.array([-ub[1], ub[0]])
    g0 = b0 + ub
    c0 = g0 - polar(cg_dir, cg)
    lift = 2 * np.cos(delta)
    centres = {}
    for c, pin0 in (("A", a0), ("B", b0), ("C", c0)):
        xc = pin0 - a0
        centres[c] = ((float(xc[0]), float(xc[1])), (float(xc[0]), float(xc[1] + lift)))
    lengths = {"crank": 1.0, "AD": ad, "DE": de, "AF": af, "BG": 1.0, "CG": cg, "BE": be}
    p1 = af / ad
    pr = Proportions((1, 1, 1), (1 - p1, p1 * (1 - be), p1 * be), p1, be)
    tilts = {"DE": float((gam - np.pi + np.pi) % (2 * np.pi) - np.pi), "CG": float(cg_dir)}
    branches = {"D": branch_of(a0, e0, d0), "G": branch_of(b0, c0, g0)}
    return SeparatorLayout(pr, s_i, delta, lengths, centres, tilts, branches, f_left / ad,
                           e_left)


@dataclass
class MoveSamples:
    """Pins A and D (F is a point of the rigid link AD) at the 8 tip configurations (first 8
    rows, minterm order of t) and along every single-crank move about X and X'."""

    A: np.ndarray  # (P, 2)
    D: np.ndarray  # (P, 2)
    F: np.ndarray  # (P, 2) with the layout's own p1 and offset
    edges: list[tuple[int, int, int, np.ndarray]]  # (config t=0, config t=1, crank, rows)
    min_transmission: float  # separator (at D and G), degrees


def move_samples(lay: SeparatorLayout, samples: int) -> MoveSamples:
    configs = input_matrix(3)
    joints = [lay.solve({c: lay.tip(c, configs[:, i], False) for i, c in enumerate(lay.cranks)})]
    t = np.linspace(0.0, 1.0, samples)
    edges, n = [], 8
    for i in range(3):
        for a in range(8):
            if configs[a, i]:
                continue
            rows = []
            for primed in (False, True):
                tips = {c: (lay.tip(c, t, primed) if q == i else
                            np.broadcast_to(lay.tip(c, configs[a, q], primed), (samples, 2)))
                        for q, c in enumerate(lay.cranks)}
                joints.append(lay.solve(tips))
                rows.append(np.arange(n, n + samples))
                n += samples
            edges.append((a, a | (4 >> i), i, np.concatenate(rows)))
    A = np.concatenate([j["A"] for j in joints])
    D = np.concatenate([j["D"] for j in joints])
    F = np.concatenate([j["F"] for j in joints])
    mu = min(float(lay.transmission(j).min()) for j in joints)
    return MoveSamples(A, D, F, edges, mu)


def held_sets(h: tuple[int, ...], ms: MoveSamples) -> list[tuple[int, np.ndarray]]:
    """(output value, sample rows) of every rest state and every change whose output holds."""
    sets = [(int(h[m]), np.array([m])) for m in range(8)]
    sets += [(int(h[a]), rows) for a, b, _i, rows in ms.edges if h[a] == h[b]]
    return sets


def _f_points(ms: MoveSamples, p1: np.ndarray, q: np.ndarray) -> np.ndarray:
    """F for candidates (C,) of p1 and offset q: (C, P, 2)."""
    v = ms.D[None] - ms.A[None]
    perp = quarter_turn(v)
    return ms.A[None] + p1[:, None, None] * v + q[:, None, None] * perp


def cam_angles(F: np.ndarray, K: np.ndarray, fj: np.ndarray, jk: np.ndarray, branch: int
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(phi deg about the circular mean, transmission at J deg, closes) for candidates: F (C, P,
    2), K (C, 2), fj and jk (C,). J on the branch of geometry.circle_intersection(F, ., K, .)."""
    K = K[:, None, :]
    J, h2 = circle_meeting(K, jk[:, None], F, fj[:, None], -branch, miss="clamp")
    closes = np.all(h2 > 0, axis=1)
    w = J - K
    ang = np.arctan2(w[..., 1], w[..., 0])
    ref = np.arctan2(np.sin(ang).mean(1), np.cos(ang).mean(1))
    phi = np.degrees((ang - ref[:, None] + np.pi) % (2 * np.pi) - np.pi)
    return phi, line_angle_deg(F - J, K - J).min(1), closes


def separation(phi: np.ndarray, sets: list[tuple[int, np.ndarray]]) -> np.ndarray:
    """Smallest cam-angle distance between held sets of different output values (negative if
    any overlap), for phi (C, P)."""
    lo = {0: [], 1: []}
    hi = {0: [], 1: []}
    for v, rows in sets:
        lo[v].append(phi[:, rows].min(1))
        hi[v].append(phi[:, rows].max(1))
    l0, h0, l1, h1 = (np.stack(s, 1) for s in (lo[0], hi[0], lo[1], hi[1]))
    gap = np.maximum(l1[:, None, :] - h0[:, :, None], l0[:, :, None] - h1[:, None, :])
    return gap.min((1, 2))


def runs(phi: np.ndarray, sets: list[tuple[int, np.ndarray]]) -> list[tuple[float, float, int]]:
    """Held cam-angle ranges merged into alternating runs (lo, hi, value), ascending. Raises
    ValueError if sets of different values overlap."""
    iv = sorted((float(phi[rows].min()), float(phi[rows].max()), v) for v, rows in sets)
    out = [list(iv[0])]
    for lo, hi, v in iv[1:]:
        if v == out[-1][2]:
            out[-1][1] = max(out[-1][1], hi)
        elif lo > out[-1][1]:
            out.append([lo, hi, v])
        else:
            raise ValueError(f"held cam angles of outputs 0 and 1 overlap at {lo:.3f} deg")
    return [(a, b, int(v)) for a, b, v in out]


@dataclass(frozen=True)
class PlanarGenerator:
    """A separator and loop FJK for the wiring function ``h`` (truth table over the crank tip
    values t_A t_B t_C, minterm order); every NPN relative is reached by rewiring."""

    h: tuple[int, ...]
    p1: float
    p2: float
    offset: float
    loop: ThresholdLoop
    separation_deg: float  # on the fine samples
    min_transmission: float  # separator and loop, fine samples (deg)
    free: tuple[float, ...] | None = None  # free eight-bar parameters (FREE_NAMES), if any

    def layout(self, mu_min_deg: float) -> SeparatorLayout:
        if self.free is not None:
            return free_layout(self.free, mu_min_deg)
        return planar_layout(self.p1, self.p2, self.offset, mu_min_deg)


def wirings(tt: tuple[int, ...]) -> dict[tuple[int, ...], tuple[tuple[int, ...], tuple[int, ...]]]:
    """Wiring functions of ``tt`` up to complement: h -> (crank of each input, inputs turned
    about X'). Input j on crank perm[j] reads x_j = t_perm[j] XOR neg[j]."""
    X = input_matrix(3)
    out = {}
    for perm in itertools.permutations(range(3)):
        for neg in itertools.product((0, 1), repeat=3):
            h = tuple(int(tt[int((X[m][list(perm)] ^ np.array(neg)) @ [4, 2, 1])])
                      for m in range(8))
            if h not in out and tuple(1 - v for v in h) not in out:
                out[h] = (perm, neg)
    return out


def wiring_for(tt: tuple[int, ...], h: tuple[int, ...]
               ) -> tuple[tuple[int, ...], tuple[int, ...], bool]:
    """(crank of each input, X' flags per input, output complemented) making ``tt`` read as the
    designed ``h``; ValueError if ``tt`` is not an NPN relative of ``h``."""
    X = input_matrix(3)
    for perm in itertools.permutations(range(3)):
        for neg in itertools.product((0, 1), repeat=3):
            g = tuple(int(tt[int((X[m][list(perm)] ^ np.array(neg)) @ [4, 2, 1])])
                      for m in range(8))
            if g == h:
                return perm, neg, False
            if g == tuple(1 - v for v in h):
                return perm, neg, True
    raise ValueError(f"{tt} is not an NPN relative of {h}")


def _score(x: np.ndarray, h: tuple[int, ...], branch: int, mu: float) -> float:
    p1, q, kx, ky, fj, jk, p2 = x
    if not (0 < p1 <= P1_MAX and abs(q) <= OFFSET_MAX and P2_RANGE[0] <= p2 <= P2_RANGE[1]
            and MIN_LINK <= fj <= MAX_LINK and MIN_LINK <= jk <= MAX_LINK):
        return 1e3
    ms = move_samples(planar_layout(p1, p2, q, mu - SEARCH_MARGIN_DEG), SCREEN_SAMPLES)
    with np.errstate(all="ignore"):
        phi, trans, closes = cam_angles(_f_points(ms, np.array([p1]), np.array([q])),
                                        np.array([[kx, ky]]), np.array([fj]), np.array([jk]),
                                        branch)
        sep = separation(phi, held_sets(h, ms))[0]
    turn = phi.max() - phi.min()
    if not closes[0] or not np.isfinite(sep) or turn > MAX_TURN_DEG:
        return 1e3
    # the separator meets mu_min exactly in the Fig. 42 position, so it gets no margin
    pen = 50 * max(0.0, mu - trans[0])
    pen += 50 * max(0.0, mu - SEARCH_MARGIN_DEG - TRANSMISSION_TOL - ms.min_transmission)
    return float(-sep + pen)


def search_planar(canonical: tuple[int, ...], mu_min_deg: float = 45.0, seed: int = 5,
                  candidates: int = SCREEN_CANDIDATES, polish: int = N_POLISH
                  ) -> tuple[float, tuple[int, ...], tuple[float, ...], int] | None:
    """Search one NPN class (module docstring): (separation deg on the screening samples,
    wiring function h, (p1, p2, offset, K_x, K_y, FJ, JK), branch), or None when no candidate
    reaches a positive separation with every constraint met."""
    mu = mu_min_deg + SEARCH_MARGIN_DEG
    hs = list(wirings(canonical))
    unit = qmc.Sobol(6, seed=seed).random(candidates)
    starts = []
    for p2 in SCREEN_P2:
        ms = move_samples(planar_layout(0.5, p2, 0.0, mu_min_deg), SCREEN_SAMPLES)
        if ms.min_transmission < mu_min_deg - TRANSMISSION_TOL:
            continue
        centre = 0.5 * (ms.A[:8] + ms.D[:8]).mean(0)
        p1 = P1_MAX * unit[:, 0]
        q = OFFSET_MAX * (2 * unit[:, 1] - 1)
        K = centre + 3.0 * (unit[:, 2:4] - 0.5)
        fj = MIN_LINK + (MAX_LINK - MIN_LINK) * unit[:, 4]
        jk = MIN_LINK + (MAX_LINK - MIN_LINK) * unit[:, 5]
        F = _f_points(ms, p1, q)
        for branch in (1, -1):
            with np.errstate(all="ignore"):
                phi, trans, closes = cam_angles(F, K, fj, jk, branch)
            ok = closes & (trans >= mu) & (np.ptp(phi, 1) <= MAX_TURN_DEG)
            for h in hs:
                with np.errstate(all="ignore"):
                    sep = np.where(ok, separation(phi, held_sets(h, ms)), -np.inf)
                i = int(np.argmax(sep))
                starts.append((float(sep[i]), h, branch,
                               np.array([p1[i], q[i], K[i, 0], K[i, 1], fj[i], jk[i], p2])))
    starts.sort(key=lambda s: -s[0])
    best = None
    for _, h, branch, x0 in starts[:polish]:
        with np.errstate(all="ignore"):
            res = minimize(_score, x0, args=(h, branch, mu), method="Nelder-Mead",
                           options={"xatol": 1e-6, "fatol": 1e-4, "maxiter": 1500})
        if best is None or res.fun < best[0]:
            best = (float(res.fun), h, branch, res.x)
    if best is None or best[0] >= 0:
        return None
    f, h, branch, x = best
    p1, q, kx, ky, fj, jk, p2 = (float(v) for v in x)
    return -f, h, (p1, p2, q, kx, ky, fj, jk), branch


#: Results of :func:`search_planar` per NPN class (canonical truth table), kept so that a design
#: costs no search: (wiring function h, (p1, p2, offset, K_x, K_y, FJ, JK) in units of l, branch
#: of J). Every design built from them is re-analysed on fine samples and checked.
#: Only x1(x2 xor x3) has one; for the multiplexer class this eight-bar's best search result
#: separates the held sets by 0.09 deg (0.00 on fine samples): see FREE_DESIGNS.
PLANAR_DESIGNS: dict[tuple[int, ...], tuple[tuple[int, ...], tuple[float, ...], int]] = {
    # x1 (x2 xor x3), FV 6: separation 33.8 deg, search 70 s (seed 5)
    (0, 0, 0, 0, 0, 1, 1, 0): ((0, 1, 1, 0, 0, 0, 0, 0),
                               (0.643534, 1.466117, -0.052735, 0.043105, 1.36733, 0.54962,
                                0.333706), 1),
}


#: Results of :func:`mechc.threshold.freebar.search_free` per NPN class: (wiring function h,
#: free eight-bar parameters (FREE_NAMES), loop (K_x, K_y, FJ, JK), branch of J), units of l.
#: For the classes the eight-bar of :data:`PLANAR_DESIGNS` cannot serve (docs/threshold.md §2).
FREE_DESIGNS: dict[tuple[int, ...], tuple[tuple[int, ...], tuple[float, ...],
                                          tuple[float, ...], int]] = {
    # multiplexer x1 ? (x2 + x3') : x2 x3, FV 27: separation 58.7 deg on 50 samples per move,
    # one transition (output 0 | 1 along phi); search 121 s (seed 1: score 56.4 deg on 10
    # samples), then one more Nelder-Mead pass on 25 samples per change
    (0, 0, 0, 1, 1, 0, 1, 1): ((0, 0, 0, 1, 1, 0, 1, 1),
                               (-1.194974, 0.62606, 1.086716, 0.822484, 1.279785, 0.933223,
                                -0.04271, 0.895012, -0.302869, 0.520251, -0.445225),
                               (0.33843, 2.320938, 1.003855, 0.333334), -1),
}


@lru_cache(maxsize=8)
def planar_generator(canonical: tuple[int, ...], mu_min_deg: float = 45.0, samples: int = 50
                     ) -> PlanarGenerator | None:
    """The planar generator of an NPN class, or None if there is none (the class is in neither
    :data:`PLANAR_DESIGNS` nor :data:`FREE_DESIGNS`, or its design no longer separates the held
    sets)."""
    if canonical in FREE_DESIGNS:
        h, x, (kx, ky, fj, jk), branch = FREE_DESIGNS[canonical]
        return build_free(h, x, (kx, ky, fj, jk), branch, mu_min_deg, samples)
    if canonical not in PLANAR_DESIGNS:
        return None
    h, (p1, p2, q, kx, ky, fj, jk), branch = PLANAR_DESIGNS[canonical]
    return build_planar(h, (p1, p2, q, kx, ky, fj, jk), branch, mu_min_deg, samples)


def build_planar(h: tuple[int, ...], x: tuple[float, ...], branch: int,
                 mu_min_deg: float = 45.0, samples: int = 50) -> PlanarGenerator | None:
    """Analyse a planar design on ``samples`` per move: None if loop FJK cannot close or the
    held sets of outputs 0 and 1 are not separated."""
    p1, p2, q, kx, ky, fj, jk = x
    return _build(h, planar_layout(p1, p2, q, mu_min_deg), (kx, ky, fj, jk), branch, samples,
                  (p1, p2, q), None)


def build_free(h: tuple[int, ...], x: tuple[float, ...], loop: tuple[float, ...], branch: int,
               mu_min_deg: float = 45.0, samples: int = 50) -> PlanarGenerator | None:
    """Analyse a free eight-bar design (:func:`free_layout`) like :func:`build_planar`."""
    lay = free_layout(x, mu_min_deg)
    p = lay.proportions
    return _build(h, lay, loop, branch, samples, (p.p1, p.p2, lay.f_offset),
                  tuple(float(v) for v in x))


def _build(h: tuple[int, ...], lay: SeparatorLayout, loop: tuple[float, ...], branch: int,
           samples: int, p: tuple[float, float, float], free: tuple[float, ...] | None
           ) -> PlanarGenerator | None:
    kx, ky, fj, jk = loop
    ms = move_samples(lay, samples)
    with np.errstate(all="ignore"):
        phi, trans, closes = cam_angles(ms.F[None], np.array([[kx, ky]]), np.array([fj]),
                                        np.array([jk]), branch)
    sep = float(separation(phi, held_sets(h, ms))[0])
    if not closes[0] or sep <= 0:
        return None
    w = ThresholdLoop((kx, ky), fj, jk, branch, 1, 0.0).joint(ms.F) - np.array([kx, ky])
    ang = np.arctan2(w[:, 1], w[:, 0])
    ref = float(np.arctan2(np.sin(ang).mean(), np.cos(ang).mean()))
    loop = ThresholdLoop((kx, ky), fj, jk, branch, 1, ref)
    return PlanarGenerator(h, *p, loop, sep, float(min(trans[0], ms.min_transmission)), free)


def main() -> None:
    """Search every NPN class whose threshold realisations all have static hazards and print
    the entries of :data:`PLANAR_DESIGNS` (``python -m mechc.threshold.planar``)."""
    classes = sorted({npn_canonical(truth_table_from_fv(fv)) for fv in range(256)
                      if static_hazards(realise(fv).weights, truth_table_from_fv(fv))})
    for c in classes:
        t0 = time.perf_counter()
        found = search_planar(c)
        dt = time.perf_counter() - t0
        if found is None:
            print(f"# {c}: no positive separation found ({dt:.0f} s)")
            continue
        sep, h, x, branch = found
        fine = build_planar(h, x, branch)
        print(f"# separation {sep:.2f} deg (fine samples: "
              f"{fine.separation_deg if fine else float('nan'):.2f}), {dt:.0f} s")
        print(f"{c}: ({h}, ({', '.join(repr(round(v, 6)) for v in x)}), {branch}),")


if __name__ == "__main__":
    main()
