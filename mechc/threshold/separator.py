"""Separator linkages (001 §3.5, Appendix D): proportions by the linear approximation, then exact
loop closure.

Layout (Figs. 22, 31, 33; unit crank length l = 1): input cranks X_A A, X_B B (and X_C C) of
length l swing through the same angle, their "0" and "1" positions symmetric about the vertical.
Vertical link AD carries the output point F (AF = p1 AD); a near-horizontal coupler DE joins D to
E. In the five-bar (two inputs) E is the crank pin B. In the eight-bar, E lies on the vertical
link BG (BE = p2 BG) and coupler CG joins G to crank C. To first order
s_F = (1 - p1) s_A + p1 (1 - p2) s_B + p1 p2 s_C, so the coefficients c = (c_A, c_B, c_C) sum to
one and are proportional to the weight magnitudes; a negative coefficient (F or E on an extension
of its link) enlarges F's travel for the same input stroke (Fig. 31(d), (e)). The sign of a weight
is set by which fixed centre a crank turns about: X (below its pin) or X' (above, Fig. 28).

Coordinates: X_A at the origin, all inputs at the tip-left position (t = 0), AD and BG vertical.
Each coupler (DE, CG) droops by a = l sin(alpha) towards its far end so that when the vertical
link's own crank moves alone, the joint (D or G) swings to the mirror position and returns to the
same x: the linear approximation is then exact for that input (the construction of Fig. 42).
With mu_min = 45 deg this gives alpha = 6.3022 deg and the input stroke s_I = l cos(mu_min +
alpha) = 0.62521 l, as in Appendix D.1.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from mechc.geometry.circles import branch_of, circle_intersection, line_angle_deg, polar

#: Limits on extensions used when choosing proportions: F at most l/3 beyond D, E at most l/2
#: beyond G. The dissertation states no rule; these reproduce its five choices (Fig. 31).
P1_MAX = 4.0 / 3.0
P2_MAX = 1.5


@dataclass(frozen=True)
class Proportions:
    """Linear-approximation proportions for weight magnitudes ``pattern`` on cranks A, B[, C]."""

    pattern: tuple[int, ...]
    coeffs: tuple[float, ...]  # signed c_A, c_B[, c_C]; sum 1
    p1: float  # AF / AD
    p2: float | None  # BE / BG (eight-bar only)

    @property
    def travel(self) -> float:
        """F's horizontal travel over the full level range, in units of the input stroke s_I
        (the dissertation's k u / k s)."""
        return float(sum(abs(c) for c in self.coeffs))

    @property
    def u_over_s(self) -> float:
        return self.travel


def _proportions_for(pattern: tuple[int, ...], signs: tuple[int, ...]) -> Proportions | None:
    n_den = sum(s * m for s, m in zip(signs, pattern))
    if n_den <= 0:
        return None
    c = tuple(s * m / n_den for s, m in zip(signs, pattern))
    p1 = 1.0 - c[0]
    if len(c) == 2:
        return Proportions(pattern, c, p1, None)
    if abs(p1) < 1e-12:
        return None
    return Proportions(pattern, c, p1, c[2] / p1)


def proportion(magnitudes: tuple[int, ...]) -> Proportions:
    """Choose crank assignment and signs of the coefficients: largest F travel, F and E within
    :data:`P1_MAX`, :data:`P2_MAX` of their links; then F and E between link ends; then
    proportions nearest one half. ``magnitudes`` are the nonzero |w| (2 or 3 of them)."""
    mags = tuple(sorted((int(m) for m in magnitudes if m), reverse=True))
    if len(mags) not in (2, 3):
        raise ValueError(f"a separator needs 2 or 3 nonzero weights, got {magnitudes}")
    best, best_key = None, None
    for perm in sorted(set(itertools.permutations(mags))):
        for signs in itertools.product((1, -1), repeat=len(mags)):
            p = _proportions_for(perm, signs)
            if p is None or not 0 < p.p1 <= P1_MAX + 1e-12:
                continue
            if p.p2 is not None and not 0 < p.p2 <= P2_MAX + 1e-12:
                continue
            inside = (p.p1 <= 1 + 1e-12, p.p2 is None or p.p2 <= 1 + 1e-12)
            dev = abs(p.p1 - 0.5) + (abs(p.p2 - 0.5) if p.p2 is not None else 0.0)
            key = (-round(p.travel, 9), not inside[0], not inside[1], round(dev, 9), perm, signs)
            if best_key is None or key < best_key:
                best, best_key = p, key
    if best is None:
        raise ValueError(f"no proportions within the extension limits for {mags}")
    return best


@lru_cache(maxsize=16)
def input_stroke(mu_min_deg: float = 45.0) -> tuple[float, float]:
    """(s_I, alpha) for unit crank length from the two conditions of 001 Appendix D.1
    (Eqs. D.2, D.3): transmission angle mu_min in the Fig. 42 position, and the coupler's mirror
    position reached exactly when the vertical link's crank moves through s_I."""
    mu = np.radians(mu_min_deg)

    def closure(a: float) -> float:
        return np.cos(mu + a) ** 2 + (1 - 2 * np.sin(a)) ** 2 - 1

    alpha = brentq(closure, 1e-9, np.pi / 2 - mu - 1e-9)
    return float(np.cos(mu + alpha)), float(alpha)


def droop(link: float, s_i: float) -> float:
    """a such that a link of length ``link`` whose bottom moves s_I sideways drops by 2a:
    s_I^2 + (L - 2a)^2 = L^2 (Eq. D.3 with L in place of l)."""
    return (link - np.sqrt(link * link - s_i * s_i)) / 2


@dataclass(frozen=True)
class SeparatorLayout:
    """A proportioned separator in units of the crank length (multiply by l for mm)."""

    proportions: Proportions
    s_i: float
    half_swing: float  # delta: each crank swings +-delta about the vertical (rad)
    lengths: dict[str, float]
    centres: dict[str, tuple[tuple[float, float], tuple[float, float]]]  # crank: (X, X')
    tilts: dict[str, float]  # coupler droop angles (rad)
    branches: dict[str, int] = field(default_factory=dict)
    #: F's distance from the line AD, as a fraction of AD, to the left of A -> D (0: F on the
    #: line, as in every threshold generator; see mechc.threshold.planar for the others)
    f_offset: float = 0.0
    #: E's distance from the line BG, as a fraction of BG, to the left of B -> G (0 in every
    #: threshold generator; the free eight-bar of mechc.threshold.planar makes E a coupler point)
    e_offset: float = 0.0

    @property
    def cranks(self) -> tuple[str, ...]:
        return ("A", "B", "C")[: len(self.proportions.pattern)]

    @property
    def five_bar(self) -> bool:
        return len(self.proportions.pattern) == 2

    def tip(self, crank: str, t: np.ndarray, primed: bool) -> np.ndarray:
        """Crank pin for tip parameter t in [0, 1] (0 = leftmost, 1 = rightmost), crank angle
        linear in t, turning about X (``primed`` False) or X'."""
        t = np.asarray(t, dtype=float)
        d = self.half_swing
        if primed:
            ang = -np.pi / 2 - d + 2 * d * t
        else:
            ang = np.pi / 2 + d - 2 * d * t
        c = np.asarray(self.centres[crank][1 if primed else 0])
        return c + polar(ang)

    def solve(self, tips: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Joint positions from crank pins by loop closure (closed form, vectorised)."""
        L = self.lengths
        A, B = tips["A"], tips["B"]
        out = {"A": A, "B": B}
        if self.five_bar:
            E = B
        else:
            C = tips["C"]
            G = circle_intersection(B, L["BG"], C, L["CG"], self.branches["G"], "loop BGC")
            E = B + (L["BE"] / L["BG"]) * (G - B)
            if self.e_offset:
                E = E + self.e_offset * np.stack([B[..., 1] - G[..., 1], G[..., 0] - B[..., 0]],
                                                 -1)
            out.update(C=C, G=G)
        D = circle_intersection(A, L["AD"], E, L["DE"], self.branches["D"], "loop ADE")
        F = A + (L["AF"] / L["AD"]) * (D - A)
        if self.f_offset:
            F = F + self.f_offset * np.stack([A[..., 1] - D[..., 1], D[..., 0] - A[..., 0]], -1)
        out.update(D=D, E=E, F=F)
        return out

    def transmission(self, j: dict[str, np.ndarray]) -> np.ndarray:
        """Transmission angles (degrees) at D (between DE and DA) and, in the eight-bar, at G
        (between GC and GB), stacked on the last axis."""
        ang = [line_angle_deg(j["E"] - j["D"], j["A"] - j["D"])]
        if not self.five_bar:
            ang.append(line_angle_deg(j["C"] - j["G"], j["B"] - j["G"]))
        return np.stack(ang, axis=-1)

    def level(self, t: np.ndarray) -> np.ndarray:
        """Sum level 0..sum|w| of tip configurations t (..., m): F moves right as it grows."""
        t = np.asarray(t)
        lv = 0
        for i, (m, c) in enumerate(zip(self.proportions.pattern, self.proportions.coeffs)):
            lv = lv + m * (t[..., i] if c > 0 else 1 - t[..., i])
        return lv


def layout(magnitudes: tuple[int, ...], mu_min_deg: float = 45.0,
           proportions: Proportions | None = None, tilt_rule: str = "table_v",
           f_offset: float = 0.0) -> SeparatorLayout:
    """Dimension a separator. ``tilt_rule`` "mirror" droops every coupler by :func:`droop` of the
    vertical link it meets; "table_v" uses the droop of a unit link for every coupler except DE
    when AD != l, which is horizontal as printed in Table V column V. ``f_offset`` moves F off
    the line AD (see :attr:`SeparatorLayout.f_offset`)."""
    p = proportions or proportion(magnitudes)
    s_i, alpha = input_stroke(mu_min_deg)
    delta = float(np.arcsin(s_i / 2))
    be = 0.0 if p.p2 is None else p.p2  # BG = l
    ad = max(1.0, be)  # AD = BE when E is beyond G (Table V col. V); otherwise l
    lengths = {"crank": 1.0, "AD": ad, "DE": 1.0, "AF": p.p1 * ad}
    if p.p2 is not None:
        lengths.update(BG=1.0, CG=1.0, BE=be)

    def tilt(link: float) -> float:
        if tilt_rule == "table_v":
            return alpha if abs(link - 1.0) < 1e-12 else 0.0
        if tilt_rule != "mirror":
            raise ValueError(f"unknown tilt rule {tilt_rule!r}")
        return float(np.arcsin(droop(link, s_i)))

    tilts = {"DE": tilt(ad)}
    lift = 2 * np.cos(delta)  # X' is the mirror of X through the line of the crank pins
    a0 = np.array([-np.sin(delta), np.cos(delta)])  # pin A at t = 0 about X_A = origin
    down = np.array([np.sin(delta), -np.cos(delta)])  # from a t = 0 pin to its centre X

    def centre_pair(pin0: np.ndarray) -> tuple[tuple[float, float], tuple[float, float]]:
        x = pin0 + down
        return (float(x[0]), float(x[1])), (float(x[0]), float(x[1] + lift))

    d0 = a0 + np.array([0.0, ad])
    e0 = d0 - polar(tilts["DE"])
    centres = {"A": centre_pair(a0)}
    joints0 = {"A": a0, "D": d0, "E": e0}
    if p.p2 is None:
        centres["B"] = centre_pair(e0)
        joints0["B"] = e0
    else:
        tilts["CG"] = tilt(1.0)
        b0 = e0 - np.array([0.0, be])
        g0 = b0 + np.array([0.0, 1.0])
        c0 = g0 - polar(tilts["CG"])
        centres["B"] = centre_pair(b0)
        centres["C"] = centre_pair(c0)
        joints0.update(B=b0, G=g0, C=c0)
    branches = {"D": branch_of(joints0["A"], joints0["E"], joints0["D"])}
    if p.p2 is not None:
        branches["G"] = branch_of(joints0["B"], joints0["C"], joints0["G"])
    return SeparatorLayout(p, s_i, delta, lengths, centres, tilts, branches, float(f_offset))


# --- analysis ----------------------------------------------------------------------------------


@dataclass
class SeparatorAnalysis:
    """Exact positions of F for every tip configuration and along every single-crank move."""

    layout: SeparatorLayout
    configs: np.ndarray  # (2**m, m) tip configurations t
    levels: np.ndarray  # (2**m,) sum level of each configuration
    F: np.ndarray  # (2**m, 2) exact F at each configuration
    structural_error: np.ndarray  # (2**m,) F_x - ideal linear sum, units of l
    unit: float  # ideal F travel per level, units of l
    min_gap: float  # smallest F_x gap between adjacent levels, units of l
    edges: list[tuple[int, int, int]]  # (config t=0 index, config t=1 index, crank index)
    paths: np.ndarray  # (n_edges, 2 centre variants (X, X'), samples, 2) F along each move
    min_transmission: float  # degrees, over all configurations and moves


def analyse(lay: SeparatorLayout, samples: int = 50) -> SeparatorAnalysis:
    m = len(lay.cranks)
    configs = np.array(list(itertools.product((0, 1), repeat=m)))
    tips = {c: lay.tip(c, configs[:, i], False) for i, c in enumerate(lay.cranks)}
    j = lay.solve(tips)
    F = j["F"]
    levels = lay.level(configs)
    unit = lay.s_i * lay.proportions.travel / sum(lay.proportions.pattern)
    ref = F[np.argmin(levels)]
    err = (F[:, 0] - ref[0]) - unit * levels
    gaps = [F[levels == lv + 1, 0].min() - F[levels == lv, 0].max()
            for lv in range(int(levels.max()))]
    trans = [lay.transmission(j).min()]
    edges = []
    for i in range(m):
        for a in range(len(configs)):
            if configs[a, i] == 0:
                b = int(np.flatnonzero((configs == np.where(np.arange(m) == i, 1, configs[a]))
                                       .all(1))[0])
                edges.append((a, b, i))
    t = np.linspace(0.0, 1.0, samples)
    paths = np.empty((len(edges), 2, samples, 2))
    for e, (a, _b, i) in enumerate(edges):
        for v, primed in enumerate((False, True)):
            tp = {}
            for q, c in enumerate(lay.cranks):
                if q == i:
                    tp[c] = lay.tip(c, t, primed)
                else:
                    tp[c] = np.broadcast_to(lay.tip(c, configs[a, q], primed), (samples, 2))
            jj = lay.solve(tp)
            paths[e, v] = jj["F"]
            trans.append(lay.transmission(jj).min())
    return SeparatorAnalysis(lay, configs, levels, F, err, unit, float(min(gaps)), edges, paths,
                             float(min(trans)))
