"""The 3-bar linkage gate of ``000_…``: lengths from separation, stroke and output position.

Geometry (mm).  Input A slides along y = +sep, input B along y = -sep, each from x = 0 (false)
to x = stroke (true).  Input links of length d_i join A and B to the middle joint M; the output
link of length d_o joins M to the output joint O, which slides along the x axis.  With FF, FT
and TF giving the same output position the output moves only for TT: an AND gate (run the other
way round, an OR gate).

Closed form (derived here; the blog wished for one).  Moving both inputs together only
translates the mechanism, so a state depends on delta = b - a alone.  In FF, M = (m, 0) with
m = sqrt(d_i^2 - sep^2).  In FT, M' = (s/2 + k h, s h / (2 b)) with s = stroke,
b = sqrt(sep^2 + s^2/4), k = sep / b, h = sqrt(m^2 - s^2/4) -- on the branch continuing from FF
(M to the right of the line AB).  O lies on the x axis at the same distance d_o from M and M', so
it is where the perpendicular bisector of MM' cuts the axis::

    x_o(m) = k s h / (s + 2 k h - 2 m)

Inverting, k h (2 x_o - s) = x_o (2 m - s); squaring gives a quadratic in m with the root
m = s/2 for every x_o (h = 0: in FT the input links lie in line -- a toggle, and the blog's
d_i = sqrt(sep^2 + (s/2)^2) is exactly this root) and the one other root::

    m* = [sep^2 (2 x_o - s)^2 + x_o^2 (s^2 + 4 sep^2)] / [2 (s x_o^2 + 4 sep^2 x_o - sep^2 s)]

A root is kept only if it satisfies the unsquared equation, puts the output on the branch it
starts on, and survives the independent kinematic check in :func:`evaluate`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq, minimize_scalar

GATE_TOL = 1e-3  # output mismatch allowed, as a fraction of stroke (issue 6: 0.1 %)
MIN_ANGLE = 45.0  # deg, the dissertation's rule (001_…, Appendix D)
MIN_LINK_RATIO = 1.0 / 3.0  # shortest/longest link, as Appendix E of 001_… keeps
WANDER_MARGIN = 5.0  # % of stroke an output may wander while its value does not change
MOTION_SAMPLES = 401
ALT_MARGIN = 0.5  # alternatives keep this margin (deg of transmission angle, % of ratio) inside


@dataclass(frozen=True)
class ThreeBarDesign:
    sep: float  # half the distance between the input slides (inputs at y = +-sep)
    stroke: float  # input travel false -> true
    input_link: float  # d_i
    output_link: float  # d_o
    output_position: float  # x of the output joint O in state FF
    output_side: int = +1  # +1: O to the right of M, -1: to the left

    @property
    def m(self) -> float:
        """x of the middle joint in state FF."""
        return float(np.sqrt(self.input_link**2 - self.sep**2))


@dataclass
class ThreeBarState:
    """Vectorised kinematics (arrays broadcast from the inputs a, b)."""

    m: np.ndarray  # complex: middle joint M
    output: np.ndarray  # x of the output joint O
    mu_inputs: np.ndarray  # deg: transmission angle between the two input links at M
    mu_output: np.ndarray  # deg: output link against the normal of its slide (90 = ideal)
    disc_inputs: np.ndarray  # mm^2: d_i^2 - |AB|^2/4 (<0: cannot assemble, ~0: toggle)
    disc_output: np.ndarray  # mm^2: d_o^2 - y_M^2 (<0: cannot assemble, ~0: toggle)
    valid: np.ndarray  # bool: both discriminants clear of zero


def kinematics(design: ThreeBarDesign, a, b) -> ThreeBarState:
    """Closed-form positions for input displacements a (slide at +sep) and b (slide at -sep),
    on the assembly branch reached from FF (M right of the inputs, O on ``output_side``).

    ``valid`` is False where a discriminant is not clearly positive: NaN positions where the
    links cannot reach, finite ones exactly at a toggle (discriminant within rounding of 0).
    """
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    sep, di, do = design.sep, design.input_link, design.output_link
    tol = 1e-12 * max(di, do, design.stroke) ** 2
    # equal input links: M is on AB's perpendicular bisector, so this is the midpoint form of
    # the circle meeting (a = |AB|/2 exactly), not the general kernel's, with a toggle tolerance
    half = 0.5 * np.hypot(b - a, 2.0 * sep)  # half of |AB|
    disc_i = di * di - half * half
    with np.errstate(invalid="ignore"):
        # a discriminant within rounding of zero is a toggle: clamp it so the position is still
        # reported (and flagged invalid); clearly negative means the links cannot reach
        h = np.sqrt(np.where(np.abs(disc_i) <= tol, 0.0, disc_i))
        n = (2.0 * sep + 1j * (b - a)) / (2.0 * half)  # unit normal to AB pointing to +x
        m = 0.5 * (a + b) + h * n
        disc_o = do * do - m.imag**2
        out = m.real + design.output_side * np.sqrt(np.where(np.abs(disc_o) <= tol, 0.0, disc_o))
        pa = a + 1j * sep - m
        pb = b - 1j * sep - m
        cosang = np.real(pa * np.conj(pb)) / (di * di)
        ang = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
        mu_in = np.minimum(ang, 180.0 - ang)
        mu_out = 90.0 - np.degrees(np.arctan2(np.abs(m.imag), np.abs(out - m.real)))
    valid = (disc_i > tol) & (disc_o > tol)
    return ThreeBarState(m, out, mu_in, mu_out, disc_i, disc_o, valid)


# --- synthesis ---------------------------------------------------------------------------------


def output_position_for(sep: float, stroke: float, m):
    """x_o(m): where the output must sit for a middle joint at x = m in FF (closed form)."""
    s = stroke
    bb = np.sqrt(sep * sep + s * s / 4.0)
    k = sep / bb
    with np.errstate(invalid="ignore", divide="ignore"):
        h = np.sqrt(np.asarray(m, float) ** 2 - s * s / 4.0)
        return k * s * h / (s + 2.0 * k * h - 2.0 * np.asarray(m, float))


def _design(sep, stroke, m, xo) -> ThreeBarDesign:
    side = 1 if xo >= m else -1
    return ThreeBarDesign(float(sep), float(stroke), float(np.hypot(m, sep)), float(abs(xo - m)),
                          float(xo), side)


def solve_closed_form(sep: float, stroke: float, output: float) -> list[ThreeBarDesign]:
    """Designs from the closed form m*, excluding the toggle root m = stroke/2."""
    s, x = stroke, output
    den = 2.0 * (s * x * x + 4.0 * sep * sep * x - sep * sep * s)
    if den == 0.0:
        return []
    m = (sep * sep * (2 * x - s) ** 2 + x * x * (s * s + 4 * sep * sep)) / den
    if not (m > s / 2.0 * (1.0 + 1e-9)):
        return []
    k = sep / np.sqrt(sep * sep + s * s / 4.0)
    h = np.sqrt(m * m - s * s / 4.0)
    lhs, rhs = k * h * (2 * x - s), x * (2 * m - s)
    if abs(lhs - rhs) > 1e-9 * max(abs(lhs), abs(rhs), s * s):
        return []  # a root of the squared equation only
    r = _gate_residual(sep, stroke, m, x)
    if not abs(r) <= 1e-9 * max(s, sep, abs(x)):
        # O is equidistant from M and M' but on the other side of M' in FT: the output link
        # would have to pass upright (a toggle) on the way, so not a gate on this branch
        return []
    return [_design(sep, stroke, m, x)]


def toggle_design(sep: float, stroke: float, output: float) -> ThreeBarDesign:
    """The root m = stroke/2 that exists for every output position (the blog's answer): in FT
    and TF the input links are stretched in line."""
    m = stroke / 2.0
    return _design(sep, stroke, m, output)


def _gate_residuals(sep, stroke, m, xo) -> np.ndarray:
    """Output in FT minus output in FF for many m at once, by forward kinematics (the circle
    intersections of :func:`kinematics`, not the closed form); NaN where either state cannot be
    assembled clear of a toggle."""
    m = np.asarray(m, float)
    s = stroke
    di, do = np.hypot(m, sep), np.abs(xo - m)
    side = np.where(xo >= m, 1.0, -1.0)
    tol = 1e-12 * np.maximum(np.maximum(di, do), s) ** 2
    with np.errstate(invalid="ignore"):
        # FF: a = b = 0, M on the axis at (m, 0)
        disc_i0, disc_o0 = di * di - sep * sep, do * do
        out0 = np.sqrt(disc_i0) + side * np.sqrt(disc_o0)
        # FT: a = 0, b = stroke
        half = 0.5 * np.hypot(s, 2.0 * sep)
        disc_i1 = di * di - half * half
        mm = 0.5 * s + np.sqrt(disc_i1) * (2.0 * sep + 1j * s) / (2.0 * half)
        disc_o1 = do * do - mm.imag**2
        out1 = mm.real + side * np.sqrt(disc_o1)
    ok = (disc_i0 > tol) & (disc_o0 > tol) & (disc_i1 > tol) & (disc_o1 > tol)
    return np.where(ok, out1 - out0, np.nan)


def _gate_residual(sep, stroke, m, xo) -> float:
    """Scalar :func:`_gate_residuals` (for root refinement)."""
    return float(_gate_residuals(sep, stroke, np.array([m]), xo)[0])


def solve_numeric(sep: float, stroke: float, output: float, samples: int = 5000
                  ) -> list[ThreeBarDesign]:
    """Robust numerical solution: roots in m of the forward-kinematic gate residual, bracketed
    on a log-spaced grid above the toggle root and refined by Brent's method."""
    s = stroke
    lo = s / 2.0
    span = 200.0 * (sep + s + abs(output))
    grid = lo + np.geomspace(1e-6 * s, span, samples)
    r = _gate_residuals(sep, s, grid, output)
    fin = np.isfinite(r)
    brackets = [(grid[i], grid[i + 1])
                for i in np.nonzero(fin[:-1] & fin[1:] & (r[:-1] * r[1:] < 0.0))[0]]
    # a root close to the edge of an assembly window may have no grid point beyond it: find
    # the edge by bisection and bracket against the last assemblable point
    for i in np.nonzero(fin[:-1] != fin[1:])[0]:
        good, bad = (grid[i], grid[i + 1]) if fin[i] else (grid[i + 1], grid[i])
        for _ in range(60):
            mid = 0.5 * (good + bad)
            if np.isfinite(_gate_residual(sep, s, mid, output)):
                good = mid
            else:
                bad = mid
        inner = grid[i] if fin[i] else grid[i + 1]
        if _gate_residual(sep, s, good, output) * r[i if fin[i] else i + 1] < 0.0:
            brackets.append((min(inner, good), max(inner, good)))
    out = []
    for lo_m, hi_m in brackets:
        try:
            m = brentq(lambda mm: _gate_residual(sep, s, mm, output), lo_m, hi_m,
                       xtol=1e-13 * s, rtol=1e-15)
        except ValueError:
            # NaN inside the bracket: the sign changes across a stretch where the mechanism
            # cannot be assembled (e.g. O passing M, the output side flipping), not at a root
            continue
        if abs(_gate_residual(sep, s, m, output)) < 1e-9 * s:
            out.append(_design(sep, s, m, output))
    return out


# --- checks --------------------------------------------------------------------------------------


STATES = {"FF": (0.0, 0.0), "FT": (0.0, 1.0), "TF": (1.0, 0.0), "TT": (1.0, 1.0)}
MOTIONS = {"FF-FT": ("FF", "FT"), "FF-TF": ("FF", "TF"), "FT-TT": ("FT", "TT"),
           "TF-TT": ("TF", "TT"), "FF-TT": ("FF", "TT")}


@dataclass
class ThreeBarReport:
    design: ThreeBarDesign
    outputs: dict[str, float]  # output x per state
    gate_error: float  # max |O(FT) - O(FF)|, |O(TF) - O(FF)| in mm
    state_angles: dict[str, dict[str, float]]  # state -> {inputs, output} deg
    motion_min_angle: dict[str, float]  # motion -> min transmission angle along it (deg)
    min_transmission_angle: float  # over states and motions
    singular_clearance: float  # mm: least extra travel to an in-line configuration, stable states
    link_ratio: float
    wander: float  # % of stroke: output excursion during FF-FT / FF-TF
    output_stroke: float  # O(TT) - O(FF)
    assembles: bool
    checks: dict[str, dict] = field(default_factory=dict)

    @property
    def healthy(self) -> bool:
        return all(c["ok"] for c in self.checks.values() if c.get("required", True))

    def failed(self) -> list[str]:
        return [f"{name}: {c['text']}" for name, c in self.checks.items()
                if c.get("required", True) and not c["ok"]]


def evaluate(design: ThreeBarDesign, min_angle: float = MIN_ANGLE,
             min_link_ratio: float = MIN_LINK_RATIO, max_wander: float | None = None,
             samples: int = MOTION_SAMPLES) -> ThreeBarReport:
    """Independent kinematic check of a design over every state and every input motion."""
    s = design.stroke
    st = {k: kinematics(design, a * s, b * s) for k, (a, b) in STATES.items()}
    outputs = {k: float(v.output) for k, v in st.items()}
    t = np.linspace(0.0, 1.0, samples)
    motion_min, wander = {}, 0.0
    where = [k for k, v in st.items() if not v.valid]
    for name, (p, q) in MOTIONS.items():
        (a0, b0), (a1, b1) = STATES[p], STATES[q]
        mv = kinematics(design, (a0 + (a1 - a0) * t) * s, (b0 + (b1 - b0) * t) * s)
        ok = bool(mv.valid.all())
        if not ok:
            where.append(name)
        motion_min[name] = (float(min(np.min(mv.mu_inputs), np.min(mv.mu_output))) if ok
                            else 0.0)
        if name in ("FF-FT", "FF-TF") and ok:
            wander = max(wander, float(np.max(np.abs(mv.output - outputs["FF"])) / s * 100.0))
    assembles = not where
    state_angles = {k: {"inputs": float(v.mu_inputs), "output": float(v.mu_output)}
                    for k, v in st.items()}
    mins = [min(v["inputs"], v["output"]) for v in state_angles.values()]
    mins += list(motion_min.values())
    mu_min = float(np.nanmin(mins)) if assembles else 0.0
    gate = max(abs(outputs["FT"] - outputs["FF"]), abs(outputs["TF"] - outputs["FF"]))
    if not np.isfinite(gate):
        gate = float("inf")
    # clearance to singular configurations in the stable states (mm of extra travel)
    m = design.m if design.input_link > design.sep else 0.0
    clear = []
    for v in st.values():
        if v.valid:
            half = np.sqrt(design.input_link**2 - v.disc_inputs)
            dlt = np.sqrt(max(4 * half * half - 4 * design.sep**2, 0.0))
            clear.append(2.0 * m - dlt)  # input travel left before A, M, B fall in line
            clear.append(design.output_link - abs(float(v.m.imag)))  # before MO stands upright
    clearance = float(min(clear)) if clear and assembles else 0.0
    links = (design.input_link, design.output_link)
    ratio = min(links) / max(links)
    rep = ThreeBarReport(design, outputs, float(gate), state_angles, motion_min, mu_min,
                         clearance, float(ratio), float(wander),
                         float(outputs["TT"] - outputs["FF"]) if assembles else float("nan"),
                         assembles)
    c = rep.checks
    c["assembles"] = {"ok": assembles, "value": assembles,
                      "text": "assembles on one branch in every state and along every motion"
                      if assembles else "cannot be assembled, or reaches a toggle, at "
                      + ", ".join(dict.fromkeys(where))}
    c["gate"] = {"ok": bool(gate <= GATE_TOL * s), "value": float(gate),
                 "limit": GATE_TOL * s,
                 "text": f"FF, FT, TF outputs agree to {gate:.3g} mm (limit {GATE_TOL * s:.3g})"}
    c["transmission"] = {"ok": bool(mu_min >= min_angle - 1e-9), "value": mu_min,
                         "limit": min_angle, "text": f"minimum transmission angle "
                         f"{mu_min:.2f} deg (limit {min_angle:g})"}
    c["singular"] = {"ok": bool(clearance > 1e-6 * s), "value": clearance,
                     "text": f"stable states are {clearance:.3g} mm of travel from the nearest "
                     "in-line (toggle) configuration"}
    c["link_ratio"] = {"ok": bool(ratio >= min_link_ratio - 1e-12), "value": float(ratio),
                       "limit": min_link_ratio, "text": f"shortest/longest link {ratio:.3f} "
                       f"(limit {min_link_ratio:.3f})"}
    c["wander"] = {"ok": bool(max_wander is None or wander <= max_wander), "value": wander,
                   "limit": max_wander, "required": max_wander is not None,
                   "text": f"output wanders {wander:.2f} % of stroke during FF-FT / FF-TF"
                   + (f" (limit {max_wander:g} %)" if max_wander is not None else "")}
    return rep


# --- the answer: a healthy design or an explicit refusal with alternatives ----------------------


@dataclass
class Criteria:
    min_angle: float = MIN_ANGLE
    min_link_ratio: float = MIN_LINK_RATIO
    max_wander: float | None = None

    def evaluate(self, d: ThreeBarDesign) -> ThreeBarReport:
        return evaluate(d, self.min_angle, self.min_link_ratio, self.max_wander)


def _margin(rep: ThreeBarReport, cr: Criteria) -> float:
    """A continuous health score (>= 0 healthy): the tightest required check, in degrees-ish."""
    if not rep.assembles:
        return -90.0
    s = rep.design.stroke
    terms = [rep.min_transmission_angle - cr.min_angle,
             (rep.link_ratio - cr.min_link_ratio) * 100.0,
             (GATE_TOL * s - rep.gate_error) / s * 1e4,
             rep.singular_clearance / s * 100.0]
    if cr.max_wander is not None:
        terms.append(cr.max_wander - rep.wander)
    return float(min(terms))


def _m_grid(sep, s, n=600):
    return s / 2.0 + np.geomspace(1e-4 * s, 60.0 * (sep + s), n)


def scan_margin(sep, stroke, m, xo, cr: Criteria | None = None, samples: int = 121):
    """Health margins (as :func:`_margin`) of many designs at once, for scanning and charts.

    Vectorised over broadcast arrays sep, stroke, m, xo.  It uses the symmetry of the gate (a
    state depends only on delta = b - a; TF mirrors FT) so one sweep delta = 0..stroke covers
    every state and motion; final answers are always re-checked by :func:`evaluate`.
    """
    cr = cr or Criteria()
    sep, s, m, xo = (a[..., None] for a in np.broadcast_arrays(*(np.asarray(v, float) for v in
                                                                  (sep, stroke, m, xo))))
    dlt = s * np.linspace(0.0, 1.0, samples)
    di = np.hypot(m, sep)
    do = np.abs(xo - m)
    side = np.where(xo >= m, 1.0, -1.0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        tol = 1e-12 * np.maximum(np.maximum(di, do), s) ** 2
        half = 0.5 * np.hypot(dlt, 2.0 * sep)
        disc_i = di * di - half * half
        mm = 0.5 * dlt + np.sqrt(disc_i) * (2.0 * sep + 1j * dlt) / (2.0 * half)
        disc_o = do * do - mm.imag**2
        out = mm.real + side * np.sqrt(disc_o)
        pa, pb = 1j * sep - mm, dlt - 1j * sep - mm
        ang = np.degrees(np.arccos(np.clip(np.real(pa * np.conj(pb)) / (di * di), -1, 1)))
        mu = np.minimum(np.minimum(ang, 180.0 - ang),
                        90.0 - np.degrees(np.arctan2(np.abs(mm.imag), np.abs(out - mm.real))))
        valid = np.all((disc_i > tol) & (disc_o > tol), axis=-1)
        gate = np.abs(out[..., -1] - out[..., 0])
        clear = np.minimum(2.0 * m[..., 0] - s[..., 0],
                           do[..., 0] - np.abs(mm.imag[..., -1]))
        ratio = np.minimum(di, do)[..., 0] / np.maximum(di, do)[..., 0]
        wander = np.max(np.abs(out - out[..., :1]), axis=-1) / s[..., 0] * 100.0
        s0 = s[..., 0]
        terms = [np.min(mu, axis=-1) - cr.min_angle, (ratio - cr.min_link_ratio) * 100.0,
                 (GATE_TOL * s0 - gate) / s0 * 1e4, clear / s0 * 100.0]
        if cr.max_wander is not None:
            terms.append(cr.max_wander - wander)
        marg = np.min(np.stack(terms), axis=0)
    return np.where(valid & np.isfinite(marg), marg, -90.0)


def healthy_range(sep: float, stroke: float, cr: Criteria | None = None, n: int = 600,
                  refine: bool = True):
    """Healthy designs for (sep, stroke) as intervals of m, with the output range of each;
    ``refine`` bisects each edge with the full check (else grid resolution)."""
    cr = cr or Criteria()
    ms = _m_grid(sep, stroke, n)
    xs = output_position_for(sep, stroke, ms)
    marg = np.where(np.isfinite(xs), scan_margin(sep, stroke, ms, np.nan_to_num(xs), cr), -90.0)
    ok = marg >= 0.0
    out = []
    i = 0
    while i < n:
        if ok[i]:
            j = i
            while j + 1 < n and ok[j + 1]:
                j += 1
            lo, hi = ms[i], ms[j]
            if refine and i > 0:
                lo = _edge(sep, stroke, ms[i - 1], ms[i], cr)
            if refine and j < n - 1:
                hi = _edge(sep, stroke, ms[j + 1], ms[j], cr)
            xo = output_position_for(sep, stroke, np.array([lo, hi]))
            out.append({"m": [float(lo), float(hi)], "output": [float(xo[0]), float(xo[1])],
                        "best_margin": float(marg[i:j + 1].max())})
            i = j + 1
        else:
            i += 1
    return out


def _edge(sep, s, bad, good, cr, iters=40, target=0.0):
    """Bisect in m between a design below and one above the margin ``target``; returns the one
    above."""
    for _ in range(iters):
        mid = 0.5 * (bad + good)
        x = output_position_for(sep, s, mid)
        ok = np.isfinite(x) and _margin(cr.evaluate(_design(sep, s, mid, float(x))), cr) >= target
        if ok:
            good = mid
        else:
            bad = mid
    return good


def best_design(sep: float, stroke: float, cr: Criteria | None = None):
    """The healthy design with the largest margin (output position left free), or None."""
    cr = cr or Criteria()
    ms = _m_grid(sep, stroke, 400)
    xs = output_position_for(sep, stroke, ms)
    sc = -np.where(np.isfinite(xs), scan_margin(sep, stroke, ms, np.nan_to_num(xs), cr), -90.0)

    def score(m):
        x = output_position_for(sep, stroke, m)
        if not np.isfinite(x):
            return 90.0
        return -_margin(cr.evaluate(_design(sep, stroke, m, float(x))), cr)

    i = int(np.argmin(sc))
    if sc[i] > 0.0:
        return None
    lo, hi = ms[max(i - 1, 0)], ms[min(i + 1, len(ms) - 1)]
    r = minimize_scalar(score, bounds=(lo, hi), method="bounded", options={"xatol": 1e-9})
    m = r.x if r.fun <= sc[i] else ms[i]
    return _design(sep, stroke, m, float(output_position_for(sep, stroke, m)))


def answer_dict(d: ThreeBarDesign | None, rep: ThreeBarReport | None, note: str = "") -> dict:
    """One design in the JSON shape of ``mechc synth three-bar`` (keys fixed by issue 6)."""
    out = {
        "healthy": bool(rep is not None and rep.healthy),
        "input_link": None if d is None else d.input_link,
        "output_link": None if d is None else d.output_link,
        "output_position": None if d is None else d.output_position,
        "min_transmission_angle_deg": None if rep is None else rep.min_transmission_angle,
        "reason": None,
        "alternatives": [],
    }
    if d is not None:
        out.update({"sep": d.sep, "stroke": d.stroke, "output_side": d.output_side,
                    "middle_joint_ff": [d.m, 0.0]})
    if rep is not None:
        out.update({
            "outputs": rep.outputs, "gate_error_mm": rep.gate_error,
            "state_angles_deg": rep.state_angles, "motion_min_angle_deg": rep.motion_min_angle,
            "singular_clearance_mm": rep.singular_clearance, "link_ratio": rep.link_ratio,
            "output_wander_pct": rep.wander, "output_stroke_mm": rep.output_stroke,
            "checks": {k: {kk: vv for kk, vv in v.items()} for k, v in rep.checks.items()},
        })
        if not rep.healthy:
            out["reason"] = "; ".join(rep.failed())
    if note:
        out["note"] = note
    return out


@dataclass
class ThreeBarAnswer:
    healthy: bool
    design: ThreeBarDesign | None
    report: ThreeBarReport | None
    reason: str | None
    candidates: list[tuple[ThreeBarDesign, ThreeBarReport, str]]  # every root examined
    alternatives: list[dict]
    feasible: list[dict]  # healthy output ranges for this sep and stroke
    warnings: list[str]

    def to_json(self) -> dict:
        out = answer_dict(self.design, self.report)
        out["healthy"] = self.healthy
        out["reason"] = self.reason
        out["alternatives"] = self.alternatives
        out["candidates"] = [answer_dict(d, r, note) for d, r, note in self.candidates]
        out["feasible_outputs"] = self.feasible
        out["warnings"] = self.warnings
        return out


def synthesise(sep: float, stroke: float, output: float | None = None,
               cr: Criteria | None = None, alternatives: bool = True) -> ThreeBarAnswer:
    """Lengths for the gate; never presents an unhealthy (e.g. toggle) design as healthy."""
    cr = cr or Criteria()
    if not (sep > 0 and stroke > 0):
        raise ValueError("sep and stroke must be positive")
    warnings: list[str] = []
    cands: list[tuple[ThreeBarDesign, ThreeBarReport, str]] = []
    if output is None:
        d = best_design(sep, stroke, cr)
        if d is not None:
            cands.append((d, cr.evaluate(d), "largest margin over all output positions"))
    else:
        closed = solve_closed_form(sep, stroke, output)
        numeric = solve_numeric(sep, stroke, output)
        for d in closed:
            agree = [n for n in numeric if abs(n.input_link - d.input_link) < 1e-7 * stroke]
            note = "closed form" + (", confirmed by the numerical solution" if agree else
                                    ", NOT found by the numerical solution")
            cands.append((d, cr.evaluate(d), note))
        for n in numeric:
            if not any(abs(n.input_link - d.input_link) < 1e-7 * stroke for d in closed):
                cands.append((n, cr.evaluate(n), "numerical solution only"))
        tg = toggle_design(sep, stroke, output)
        cands.append((tg, cr.evaluate(tg), "toggle root m = stroke/2 (the blog's answer): in FT "
                      "and TF the input links lie in line"))
    healthy = [(d, r) for d, r, _ in cands if r.healthy]
    feasible = healthy_range(sep, stroke, cr) if alternatives else []
    if healthy:
        d, r = max(healthy, key=lambda dr: dr[1].min_transmission_angle)
        reason = None
    else:
        d, r = (cands[0][0], cands[0][1]) if cands else (None, None)
        if not cands:
            reason = "no design reaches the transmission-angle and link-ratio limits"
        else:
            reason = "no healthy design for the requested numbers: " + " | ".join(
                f"d_i={dd.input_link:.4g}, d_o={dd.output_link:.4g} ({note}): "
                + "; ".join(rr.failed()) for dd, rr, note in cands)
    alts = _alternatives(sep, stroke, output, cr, feasible) if (alternatives and not healthy) \
        else []
    if r is not None and r.wander > WANDER_MARGIN:
        warnings.append(f"the output wanders {r.wander:.1f} % of stroke in mid-motion FF-FT/FF-TF "
                        f"(design brief margin {WANDER_MARGIN:g} %); --max-wander "
                        f"{WANDER_MARGIN:g} requires the margin, which with the default limits "
                        "only sep/stroke of about 0.255-0.40 can meet")
    return ThreeBarAnswer(bool(healthy), d if healthy else d, r, reason, cands, alts, feasible,
                          warnings)


def _alternatives(sep, stroke, output, cr, feasible) -> list[dict]:
    """Nearest healthy designs: same sep and stroke (nearest output position and the most
    robust), same stroke and output (nearest separation), same sep and output (nearest
    stroke)."""
    alts: list[dict] = []

    def add(d, note):
        rep = cr.evaluate(d)
        if rep.healthy:
            alts.append(answer_dict(d, rep, note))

    if feasible and output is not None:
        best = None
        for iv in feasible:
            for m, x, inner in zip(iv["m"], iv["output"], iv["m"][::-1]):
                if best is None or abs(x - output) < abs(best[1] - output):
                    best = (m, x, inner)
        if best is not None:
            m, x, inner = best
            if _margin(cr.evaluate(_design(sep, stroke, m, x)), cr) < ALT_MARGIN:
                # step inside the healthy range so the design is not exactly on a limit
                mid = 0.5 * (m + inner)
                if _margin(cr.evaluate(_design(sep, stroke, mid, float(output_position_for(
                        sep, stroke, mid)))), cr) >= ALT_MARGIN:
                    m = _edge(sep, stroke, m, mid, cr, target=ALT_MARGIN)
            add(_design(sep, stroke, m, float(output_position_for(sep, stroke, m))),
                "same separation and stroke, nearest healthy output position")
    b = best_design(sep, stroke, cr)
    if b is not None:
        add(b, "same separation and stroke, largest margin")
    if output is not None:
        for which in ("sep", "stroke"):
            d = _nearest_by(which, sep, stroke, output, cr)
            if d is not None:
                add(d, f"same {'stroke' if which == 'sep' else 'separation'} and output "
                    f"position, nearest healthy {'separation' if which == 'sep' else 'stroke'}")
    if not alts:
        # nothing healthy keeps both the separation/stroke ratio and the output: let the output
        # go and move the ratio, which alone decides whether a healthy gate exists (it scales)
        r = _nearest_ratio(sep / stroke, cr)
        if r is not None:
            for sp, st, what in ((r * stroke, stroke, "same stroke, nearest healthy separation"),
                                 (sep, sep / r, "same separation, nearest healthy stroke")):
                d = best_design(sp, st, cr)
                if d is not None:
                    add(d, what + ", output position free (largest margin there)")
    return alts


def _nearest_ratio(ratio: float, cr: Criteria) -> float | None:
    """The sep/stroke ratio nearest ``ratio`` (within x100 either way) at which the best design
    keeps ALT_MARGIN; the gate scales exactly, so health depends on this ratio alone."""

    def marg(r):
        d = best_design(r, 1.0, cr)
        return -90.0 if d is None else _margin(cr.evaluate(d), cr)

    fac = np.geomspace(1 / 100, 100, 41)
    mg = np.array([marg(ratio * f) for f in fac])
    ok = np.nonzero(mg >= ALT_MARGIN)[0]
    if len(ok) == 0:
        return None
    i = ok[np.argmin(np.abs(np.log(fac[ok])))]
    j = i - 1 if fac[i] > 1.0 else i + 1
    good = fac[i]
    if 0 <= j < len(fac) and mg[j] < ALT_MARGIN:
        bad = fac[j]
        for _ in range(25):
            mid = np.sqrt(good * bad)
            if marg(ratio * mid) >= ALT_MARGIN:
                good = mid
            else:
                bad = mid
    return float(ratio * good)


def _nearest_by(which, sep, stroke, output, cr):
    """Vary sep (or stroke) by a factor in [1/20, 20] to find the nearest healthy design that
    keeps the requested output position."""
    base = sep if which == "sep" else stroke
    fac = np.geomspace(1 / 20, 20, 241)

    def des(f):
        sp, st = (base * f, stroke) if which == "sep" else (sep, base * f)
        ds = solve_closed_form(sp, st, output)
        return ds[0] if ds else None

    def marg(f):
        d = des(f)
        return -90.0 if d is None else _margin(cr.evaluate(d), cr)

    mg = np.array([marg(f) for f in fac])
    ok = np.nonzero(mg >= ALT_MARGIN)[0]
    if len(ok) == 0:
        return None
    i = ok[np.argmin(np.abs(np.log(fac[ok])))]
    # refine toward the request (f = 1) between i and its neighbour below the margin
    j = i - 1 if fac[i] > 1.0 else i + 1
    if 0 <= j < len(fac) and mg[j] < ALT_MARGIN:
        good, bad = fac[i], fac[j]
        for _ in range(40):
            mid = np.sqrt(good * bad)
            if marg(mid) >= ALT_MARGIN:
                good = mid
            else:
                bad = mid
        return des(good)
    return des(fac[i])


def feasible_chart(stroke: float, seps, cr: Criteria | None = None) -> list[dict]:
    """Healthy output positions over separation for one stroke (the designer's chart)."""
    return [{"sep": float(s), "ranges": [iv["output"] for iv in healthy_range(
        s, stroke, cr, n=300, refine=False)]} for s in seps]
