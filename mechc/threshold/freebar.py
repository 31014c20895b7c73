"""Search for free eight-bar generators (:func:`mechc.threshold.planar.free_layout`): the cure for
the multiplexer class, whose held paths no point of the 45-degree eight-bar's link AD keeps apart.

Two stages, both vectorised over candidates. (1) Separator only: Sobol samples of the eleven
free proportions (:data:`~mechc.threshold.planar.FREE_NAMES`), kept if both dyads assemble and
keep transmission >= 45 deg on every rest state and change (about X and X'), scored by the
*planar gap*, the smallest distance between F's images of held sets of outputs 0 and 1 (positive
only if the images are disjoint, which any cam needs). (2) For the best separators, loop FJK by
Sobol over K, FJ, JK and the branch of J, scored by the cam-angle separation; then Nelder-Mead
on all fifteen numbers. ``python -m mechc.threshold.freebar`` prints the entry of
:data:`~mechc.threshold.planar.FREE_DESIGNS`.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import minimize
from scipy.stats import qmc

from mechc.geometry.circles import branch_of, circle_meeting, line_angle_deg, polar, quarter_turn
from mechc.threshold.functions import input_matrix
from mechc.threshold.linkage import MAX_LINK, MAX_TURN_DEG, MIN_LINK
from mechc.threshold.planar import separation, wirings
from mechc.threshold.separator import input_stroke

#: Search box of the free proportions (FREE_NAMES order), units of l and rad
LOWER = np.array([-1.2, 0.5, -3.14, 0.4, 0.0, -0.5, -1.0, 0.5, -3.14, -0.5, -1.0])
UPPER = np.array([1.2, 1.5, 3.14, 1.5, 3.14, 1.5, 1.0, 1.5, 3.14, 1.5, 1.0])
SEP_MARGIN_DEG = 0.5  # separator transmission kept this far above mu_min while polishing
LOOP_MARGIN_DEG = 1.0


def _tips(samples: int) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int, np.ndarray]]]:
    """Tip parameters (P, 3), primed flags (P, 3) and (from, to, rows) of each change."""
    conf = input_matrix(3)
    t = np.linspace(0.0, 1.0, samples)
    T, pr, edges, n = [conf.astype(float)], [np.zeros((8, 3), bool)], [], 8
    for i in range(3):
        for a in range(8):
            if conf[a, i]:
                continue
            rows = []
            for primed in (False, True):
                tt = np.repeat(conf[a][None].astype(float), samples, 0)
                tt[:, i] = t
                T.append(tt)
                pr.append(np.full((samples, 3), primed))
                rows.append(np.arange(n, n + samples))
                n += samples
            edges.append((a, a | (4 >> i), np.concatenate(rows)))
    return np.concatenate(T), np.concatenate(pr), edges


def _held(h, edges):
    return ([(int(h[m]), np.array([m])) for m in range(8)]
            + [(int(h[a]), rows) for a, b, rows in edges if h[a] == h[b]])


def free_points(X: np.ndarray, T: np.ndarray, PR: np.ndarray, mu_min_deg: float = 45.0
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """F (C, P, 2), separator transmission (C,) and assembly flags (C,) of candidates X (C, 11);
    the same construction as planar.free_layout, for many candidates at once."""
    beta, ad, gam, de, bg_dir, be, e_left, cg, cg_dir, af, f_left = np.asarray(X, float).T
    s_i, _ = input_stroke(mu_min_deg)
    delta = float(np.arcsin(s_i / 2))
    a0 = np.array([-np.sin(delta), np.cos(delta)])
    d0 = a0 + polar(np.pi / 2 - beta) * ad[:, None]
    e0 = d0 + polar(gam) * de[:, None]
    ub = polar(bg_dir)
    vb = quarter_turn(ub)
    b0 = e0 - be[:, None] * ub - e_left[:, None] * vb
    g0 = b0 + ub
    c0 = g0 - polar(cg_dir) * cg[:, None]
    lift = np.array([0.0, 2 * np.cos(delta)])

    def tip(pin0, t, primed):
        ang = np.where(primed, -np.pi / 2 - delta + 2 * delta * t,
                       np.pi / 2 + delta - 2 * delta * t)
        return (pin0 - a0)[:, None, :] + np.where(primed[..., None], lift, 0.0) + polar(ang)

    A = tip(np.broadcast_to(a0, b0.shape), T[None, :, 0], PR[None, :, 0])
    B = tip(b0, T[None, :, 1], PR[None, :, 1])
    C = tip(c0, T[None, :, 2], PR[None, :, 2])
    # joints clamped where the circles miss, so every candidate can still be scored
    G, h2_g = circle_meeting(B, 1.0, C, cg[:, None], branch_of(b0, c0, g0)[:, None],
                             miss="clamp")
    v = G - B
    E = B + be[:, None, None] * v + e_left[:, None, None] * quarter_turn(v)
    D, h2_d = circle_meeting(A, ad[:, None], E, de[:, None], branch_of(a0, e0, d0)[:, None],
                             miss="clamp")
    w = D - A
    F = A + (af[:, None, None] * w + f_left[:, None, None] * quarter_turn(w)) / ad[:, None, None]
    mu = np.minimum(line_angle_deg(E - D, A - D), line_angle_deg(C - G, B - G)).min(1)
    return F, mu, (h2_g > 0).all(1) & (h2_d > 0).all(1)


def _cam(F, K, fj, jk, branch):
    J, h2 = circle_meeting(F, fj[:, None], np.broadcast_to(K[:, None, :], F.shape), jk[:, None],
                           branch, miss="clamp")
    w = J - K[:, None, :]
    ang = np.arctan2(w[..., 1], w[..., 0])
    ref = np.arctan2(np.sin(ang).mean(1), np.cos(ang).mean(1))
    phi = np.degrees((ang - ref[:, None] + np.pi) % (2 * np.pi) - np.pi)
    return phi, line_angle_deg(F - J, K[:, None, :] - J).min(1), (h2 > 0).all(1)


def _score(x, h, branch, tips, mu_min):
    xs, K, fj, jk = x[:11], x[11:13], x[13], x[14]
    if (np.any(xs < LOWER - 0.3) or np.any(xs > UPPER + 0.3)
            or not (MIN_LINK <= fj <= MAX_LINK and MIN_LINK <= jk <= MAX_LINK)):
        return 1e3
    T, PR, edges = tips
    with np.errstate(all="ignore"):
        F, mu, ok = free_points(xs[None], T, PR, mu_min)
        phi, mu_j, ok_j = _cam(F, K[None], np.array([fj]), np.array([jk]), branch)
        sep = separation(phi, _held(h, edges))[0]
    if not (ok[0] and ok_j[0]) or not np.isfinite(sep) or np.ptp(phi) > MAX_TURN_DEG:
        return 1e3
    return float(-sep + 50 * max(0.0, mu_min + SEP_MARGIN_DEG - mu[0])
                 + 50 * max(0.0, mu_min + LOOP_MARGIN_DEG - mu_j[0]))


def search_free(canonical: tuple[int, ...], mu_min_deg: float = 45.0, seed: int = 1,
                separators: int = 32768, keep: int = 40, loops: int = 8192, polish: int = 6,
                samples: int = 10):
    """(separation deg on ``samples`` per change, wiring h, 11 proportions, (K_x, K_y, FJ, JK),
    branch of J), or None if no candidate separates the held sets."""
    hs = list(wirings(canonical))
    T, PR, edges = tips = _tips(samples)
    X = LOWER + (UPPER - LOWER) * qmc.Sobol(11, seed=seed).random(separators)
    found = []
    for ch in range(0, len(X), 1024):
        with np.errstate(all="ignore"):
            F, mu, ok = free_points(X[ch:ch + 1024], T, PR, mu_min_deg)
            good = ok & (mu >= mu_min_deg)
            for k, h in enumerate(hs):
                sets = _held(h, edges)
                r0 = np.concatenate([r for v, r in sets if v == 0])
                r1 = np.concatenate([r for v, r in sets if v == 1])
                gap = np.sqrt(((F[:, r0, None] - F[:, None, r1]) ** 2).sum(-1)).min((1, 2))
                found += [(float(gap[i]), k, ch + i) for i in np.flatnonzero(good & (gap > 0))]
    found.sort(key=lambda r: -r[0])
    U = qmc.Sobol(4, seed=3).random(loops)
    starts = []
    for _gap, k, i in found[:keep]:
        with np.errstate(all="ignore"):
            F, _, _ = free_points(X[i][None], T, PR, mu_min_deg)
        K = F[0].mean(0) + 4.0 * (U[:, :2] - 0.5)
        fj = MIN_LINK + (MAX_LINK - MIN_LINK) * U[:, 2]
        jk = MIN_LINK + (MAX_LINK - MIN_LINK) * U[:, 3]
        for branch in (1, -1):
            with np.errstate(all="ignore"):
                phi, mu_j, ok_j = _cam(np.broadcast_to(F, (loops,) + F.shape[1:]), K, fj, jk,
                                       branch)
                sep = separation(phi, _held(hs[k], edges))
            sep = np.where(ok_j & (mu_j >= mu_min_deg + LOOP_MARGIN_DEG)
                           & (np.ptp(phi, 1) <= MAX_TURN_DEG), sep, -np.inf)
            j = int(np.argmax(sep))
            starts.append((float(sep[j]), k, branch,
                           np.concatenate([X[i], K[j], [fj[j], jk[j]]])))
    starts.sort(key=lambda s: -s[0])
    best = None
    for _s, k, branch, x in starts[:polish]:
        for _ in range(2):  # a restart lets the simplex recover its size
            x = minimize(_score, x, args=(hs[k], branch, tips, mu_min_deg), method="Nelder-Mead",
                         options={"maxiter": 4000, "xatol": 1e-6, "fatol": 1e-4}).x
        f = _score(x, hs[k], branch, tips, mu_min_deg)
        if best is None or f < best[0]:
            best = (f, k, branch, x)
    if best is None or best[0] >= 0:
        return None
    f, k, branch, x = best
    x = np.array(x)
    x[13:15] = np.maximum(x[13:15], MIN_LINK + 1e-6)  # the strict l/3 check at synthesis
    return -f, hs[k], tuple(float(v) for v in x[:11]), tuple(float(v) for v in x[11:]), branch


def main() -> None:
    canonical = (0, 0, 0, 1, 1, 0, 1, 1)  # the multiplexer class (FV 27)
    t0 = time.perf_counter()
    found = search_free(canonical)
    if found is None:
        print(f"# {canonical}: no positive separation found")
        return
    sep, h, x, loop, branch = found
    print(f"# separation {sep:.2f} deg (penalised score, {time.perf_counter() - t0:.0f} s)")
    print(f"{canonical}: ({h}, {tuple(round(v, 6) for v in x)}, "
          f"{tuple(round(v, 6) for v in loop)}, {branch}),")


if __name__ == "__main__":
    main()
