"""Loop FJK of the threshold linkage (001 §3.6, Appendix E.1): F's position -> cam angle.

Link FJ joins the separator's output point F to J; JK turns about the fixed cam centre K and
carries the cam. The cam angle depends on where F is, not on how it got there (Fig. 27): that is
why a cam turning about a fixed pivot makes the output insensitive to F's path.

The dissertation placed K and sized FJ, JK by overlays drawn by hand. Here they are found by a
seeded quasi-random search refined by Nelder-Mead, maximising the smallest *threshold gap*: for a
threshold between sum levels g and g+1, the cam angles reached by F at rest at levels <= g and on
every single-input move between such levels lie on one side, those of levels >= g+1 on the
other; the gap between the two sets is the room for the cam's rise or return. Moves are taken
about both fixed centres X and X' of every crank, so one loop serves every sign pattern of the
weights. Constraints: transmission angle at J >= mu_min everywhere, FJ and JK >= l/3 (Appendix E)
and at most 1.2 l, total cam turn <= 300 deg.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize
from scipy.stats import qmc

from mechc.geometry.circles import (
    LoopClosureError,
    circle_intersection,
    circle_meeting,
    line_angle_deg,
)
from mechc.threshold.separator import SeparatorAnalysis, analyse, layout

MIN_LINK = 1.0 / 3.0
MAX_LINK = 1.2
MAX_TURN_DEG = 300.0


@dataclass(frozen=True)
class ThresholdLoop:
    K: tuple[float, float]  # cam centre, units of l, separator frame (X_A at the origin)
    FJ: float
    JK: float
    branch: int  # assembly branch of J (see geometry.circle_intersection)
    orientation: int  # +1 if the absolute angle of KJ grows with the sum level, else -1
    reference: float  # absolute angle of KJ (rad) at the middle of the level range

    def joint(self, F: np.ndarray) -> np.ndarray:
        K = np.broadcast_to(np.asarray(self.K, float), np.shape(F))
        return circle_intersection(F, self.FJ, K, self.JK, self.branch, "loop FJK")

    def cam_angle(self, F: np.ndarray) -> np.ndarray:
        """Cam angle (rad): KJ's direction relative to ``reference``, signed so that it grows
        with the sum level."""
        J = self.joint(F)
        v = J - np.asarray(self.K)
        a = np.arctan2(v[..., 1], v[..., 0]) - self.reference
        return self.orientation * ((a + np.pi) % (2 * np.pi) - np.pi)

    def transmission(self, F: np.ndarray) -> np.ndarray:
        J = self.joint(F)
        return line_angle_deg(F - J, np.asarray(self.K) - J)


@dataclass
class SamplePoints:
    """F positions at rest and along every single-crank move (both fixed centres), each with the
    lower and upper sum level of the move's two ends."""

    F: np.ndarray  # (P, 2)
    lo: np.ndarray  # (P,)
    hi: np.ndarray  # (P,)
    top: int  # highest level


def sample_points(an: SeparatorAnalysis, primed: tuple[bool, ...] | None = None) -> SamplePoints:
    """Rest positions and moves of F. ``primed`` (one flag per crank) keeps only the move about
    the centre each crank actually turns about; None keeps both (a sign-independent design)."""
    pts, lo, hi = [an.F], [an.levels], [an.levels]
    for e, (a, b, i) in enumerate(an.edges):
        la, lb = sorted((int(an.levels[a]), int(an.levels[b])))
        variants = (0, 1) if primed is None else (int(primed[i]),)
        for v in variants:
            p = an.paths[e, v]
            pts.append(p)
            lo.append(np.full(len(p), la))
            hi.append(np.full(len(p), lb))
    return SamplePoints(np.concatenate(pts), np.concatenate(lo), np.concatenate(hi),
                        int(an.levels.max()))


def threshold_gaps(phi: np.ndarray, sp: SamplePoints, gaps: tuple[int, ...]) -> np.ndarray:
    """Angular room (same unit as phi) at each gap index: min over the upper side minus max over
    the lower side. ``phi`` may carry leading candidate axes: (..., P)."""
    out = []
    for g in gaps:
        low = sp.hi <= g
        high = sp.lo >= g + 1
        out.append(phi[..., high].min(-1) - phi[..., low].max(-1))
    return np.stack(out, -1)


def _orient(phi_abs: np.ndarray, sp: SamplePoints) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Angles relative to the mid-level rest positions, signed to grow with level."""
    rest = sp.lo == sp.hi
    mid = rest & (sp.lo == sp.top // 2)
    ref = np.arctan2(np.sin(phi_abs[..., mid]).mean(-1), np.cos(phi_abs[..., mid]).mean(-1))
    rel = (phi_abs - ref[..., None] + np.pi) % (2 * np.pi) - np.pi
    rise = (rel[..., rest & (sp.lo == sp.top)].mean(-1) - rel[..., rest & (sp.lo == 0)].mean(-1))
    sign = np.where(rise >= 0, 1, -1)
    return rel * sign[..., None], ref, sign


def _evaluate(params: np.ndarray, branch: int, sp: SamplePoints, gaps: tuple[int, ...],
              mu_min: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(min gap deg, min transmission deg, total turn deg, feasible) for candidates (C, 4):
    K_x, K_y, FJ, JK."""
    K = params[:, None, 0:2]
    fj = params[:, 2:3]
    jk = params[:, 3:4]
    F = sp.F[None, :, :]
    # from K towards F, so the branch flips
    J, h2 = circle_meeting(K, jk, F, fj, -branch, miss="clamp")
    closes = np.all(h2 > 0, axis=1)
    v = J - K
    phi_abs = np.arctan2(v[..., 1], v[..., 0])
    phi, _, _ = _orient(phi_abs, sp)
    phi = np.degrees(phi)
    trans = line_angle_deg(F - J, K - J).min(1)
    turn = phi.max(1) - phi.min(1)
    gap = threshold_gaps(phi, sp, gaps).min(1)
    links_ok = (params[:, 2] >= MIN_LINK) & (params[:, 3] >= MIN_LINK)
    links_ok &= (params[:, 2] <= MAX_LINK) & (params[:, 3] <= MAX_LINK)
    feasible = closes & (trans >= mu_min) & (turn <= MAX_TURN_DEG) & links_ok
    return gap, trans, turn, feasible


def _score(params, branch, sp, gaps, mu_min) -> float:
    gap, trans, turn, feas = _evaluate(np.asarray(params, float)[None, :], branch, sp, gaps,
                                       mu_min)
    if not np.isfinite(gap[0]) or np.isnan(trans[0]):
        return 1e6
    p = np.asarray(params)
    pen = 50 * max(0.0, mu_min - trans[0])
    pen += 500 * (max(0.0, MIN_LINK - p[2]) + max(0.0, MIN_LINK - p[3]))
    pen += 500 * (max(0.0, p[2] - MAX_LINK) + max(0.0, p[3] - MAX_LINK))
    pen += max(0.0, turn[0] - MAX_TURN_DEG)
    return float(-gap[0] + pen) if feas[0] or pen > 0 else 1e6


def synthesise_loop(sp: SamplePoints, gaps: tuple[int, ...], mu_min: float = 45.0,
                    margin: float = 1.0, n_candidates: int = 2048, seed: int = 5,
                    coarse: SamplePoints | None = None, n_starts: int = 3) -> ThresholdLoop:
    """Best loop FJK for these sample points and threshold gaps (see module docstring).
    ``coarse`` (fewer samples per move) screens the candidates; ``margin`` (deg) is kept above
    mu_min during the search so that the check on finer samples passes."""
    if not gaps:
        gaps = tuple(range(sp.top))
    centre = sp.F[sp.lo == sp.hi].mean(0)
    unit = qmc.Sobol(4, seed=seed).random(n_candidates)
    r = 0.3 + 1.5 * unit[:, 0]
    beta = 2 * np.pi * unit[:, 1]
    params = np.column_stack([centre[0] + r * np.cos(beta), centre[1] + r * np.sin(beta),
                              MIN_LINK + (MAX_LINK - MIN_LINK) * unit[:, 2],
                              MIN_LINK + (MAX_LINK - MIN_LINK) * unit[:, 3]])
    coarse = coarse or sp
    starts = []
    for branch in (1, -1):
        with np.errstate(invalid="ignore", divide="ignore"):
            gap, trans, turn, feas = _evaluate(params, branch, coarse, gaps, mu_min + margin)
        score = np.where(feas, gap, -np.inf)
        for i in np.argsort(-score)[:n_starts]:
            if np.isfinite(score[i]):
                starts.append((branch, params[i]))
    if not starts:
        raise LoopClosureError("loop FJK: no candidate met the transmission-angle and link-length "
                               f"limits (mu_min = {mu_min} deg)")
    best = None
    for branch, x0 in starts:
        with np.errstate(invalid="ignore", divide="ignore"):
            res = minimize(_score, x0, args=(branch, coarse, gaps, mu_min + margin),
                           method="Nelder-Mead",
                           options={"xatol": 1e-5, "fatol": 1e-4, "maxiter": 400})
        if best is None or res.fun < best[0]:
            best = (res.fun, branch, res.x)
    _, branch, x = best
    # polish on the full sample set, from the winner only
    with np.errstate(invalid="ignore", divide="ignore"):
        res = minimize(_score, x, args=(branch, sp, gaps, mu_min + margin), method="Nelder-Mead",
                       options={"xatol": 1e-6, "fatol": 1e-5, "maxiter": 200})
    if res.fun < 1e5:
        x = res.x
    # the penalty lets Nelder-Mead end a hair (< 1e-6 l) short of the l/3 limit: clamp
    return make_loop(x[0:2], max(x[2], MIN_LINK), max(x[3], MIN_LINK), branch, sp)


def make_loop(K, fj: float, jk: float, branch: int, sp: SamplePoints) -> ThresholdLoop:
    """A loop with given dimensions; reference angle and orientation taken from ``sp``."""
    K = np.asarray(K, dtype=float)
    J = circle_intersection(sp.F, fj, np.broadcast_to(K, sp.F.shape), jk, branch, "loop FJK")
    v = J - K
    _, ref, sign = _orient(np.arctan2(v[:, 1], v[:, 0])[None, :], sp)
    return ThresholdLoop((float(K[0]), float(K[1])), float(fj), float(jk), int(branch),
                         int(sign[0]), float(ref[0]))


@lru_cache(maxsize=256)
def basic_loop(magnitudes: tuple[int, ...], gaps: tuple[int, ...], mu_min: float = 45.0,
               samples: int = 50, tilt_rule: str = "table_v") -> ThresholdLoop:
    """The loop for a basic separator and a set of threshold gaps (the dissertation's basic
    threshold linkages, Table III), cached: it serves every sign pattern and input order."""
    lay = layout(magnitudes, mu_min, tilt_rule=tilt_rule)
    fine = sample_points(analyse(lay, samples))
    return synthesise_loop(fine, gaps, mu_min, coarse=sample_points(analyse(lay, 16)))
