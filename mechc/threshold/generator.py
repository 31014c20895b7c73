"""A threshold logic generator for any function of up to three inputs: weights, separator, loop
FJK, cam and follower, dimensioned in millimetres and checked (001 Chapter III, by program).

Units inside are the crank length l (Tables V and VI); :func:`design_generator` scales by
l = stroke / s_I, where the stroke is the horizontal travel of every input crank pin between its
"0" and "1" positions. Input and output terminals are cranks turning clockwise from "0" to "1"
through the same angle (36.43 deg for mu_min = 45 deg).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from mechc.errors import DesignError
from mechc.ir.check import Check
from mechc.threshold.cam import (
    Follower,
    FollowerProgram,
    closed_program,
    curvature_radius,
    profile,
)
from mechc.threshold.functions import (
    as_truth_table,
    function_value,
    input_matrix,
    n_inputs,
    npn_canonical,
)
from mechc.threshold.linkage import (
    ThresholdLoop,
    basic_loop,
    sample_points,
    threshold_gaps,
)
from mechc.threshold.planar import (
    PlanarGenerator,
    held_sets,
    move_samples,
    planar_generator,
    runs,
    wiring_for,
)
from mechc.threshold.separator import SeparatorLayout, analyse, layout
from mechc.threshold.weights import Realisation, realise, static_hazards

#: Share of each threshold gap left as dwell on either side of the rise or return.
DWELL_CLEARANCE = 0.10
#: Distance K-H at mid swing, units of l (Table VI uses 0.77 and 1.0).
FOLLOWER_RADIUS = 1.0
ARM_MAX = 0.35  # Table VI's ZH
ARM_MIN = 0.08
ROLLER_MAX = 0.10  # Table VI's R_r(max)
TRANSMISSION_TOL = 1e-6  # deg: the separator meets mu_min exactly in the Fig. 42 position

#: Rigid bodies of a generator and the joints (or pivots) each carries, for building a dynamic
#: model: F lies on AD (AF from A), E on BG (BE from B), the cam is fixed to JK, the roller
#: turns at H on the output crank. Pivot names are completed with the chosen centre (X or X').
TOPOLOGY = {
    "crank_A": ("X_A", "A"), "crank_B": ("X_B", "B"), "crank_C": ("X_C", "C"),
    "AD": ("A", "D", "F"), "DE": ("D", "E"), "BG": ("B", "G", "E"), "CG": ("C", "G"),
    "FJ": ("F", "J"), "cam": ("K", "J"), "output_crank": ("Z", "H"),
}


@dataclass
class KinematicState:
    """Positions (mm) and angles (rad) for N input vectors; ``output`` is 0..1 of the stroke."""

    joints: dict[str, np.ndarray]  # name -> (N, 2) mm
    cam_angle: np.ndarray  # (N,) rad, grows with the weighted sum (0 at the mid level)
    follower: np.ndarray  # (N,) 0 = inner dwell .. 1 = outer dwell
    output_angle: np.ndarray  # (N,) absolute angle of the output crank (rad)
    output: np.ndarray  # (N,)


@dataclass
class GeneratorDesign:
    truth_table: tuple[int, ...]
    fv: int
    kind: str  # "constant", "literal" or "generator"
    realisation: Realisation
    stroke_mm: float
    scale: float = 0.0  # mm per unit crank length
    literal: tuple[int, bool] | None = None  # (input, inverted) for kind "literal"
    crank_of_input: dict[int, str] = field(default_factory=dict)
    primed: dict[str, bool] = field(default_factory=dict)  # crank turns about X' (Fig. 28)
    separator: SeparatorLayout | None = None
    loop: ThresholdLoop | None = None
    follower: Follower | None = None
    program: FollowerProgram | None = None
    links: dict[str, float] = field(default_factory=dict)  # mm
    pivots: dict[str, tuple[float, float]] = field(default_factory=dict)  # mm
    cam_profile: np.ndarray | None = None  # (M, 2) mm, cam frame (K at origin, body angle 0)
    cam_pitch: np.ndarray | None = None
    cam_range: tuple[float, float] = (0.0, 0.0)  # working cam angles (rad)
    threshold_gaps_deg: tuple[float, ...] = ()
    checks: list[Check] = field(default_factory=list)
    hazards: list[tuple[int, int]] = field(default_factory=list)
    planar: PlanarGenerator | None = None  # set when F moves in two dimensions (no hazards)

    @property
    def ok(self) -> bool:
        return all(c.passed for c in self.checks)

    def check(self, name: str) -> Check:
        return next(c for c in self.checks if c.name == name)

    def cam_body_angle(self, phi: np.ndarray) -> np.ndarray:
        """Absolute rotation of the cam (rad) at cam angle ``phi``: ``cam_profile`` turned by it
        about K gives the cam in place."""
        return self.loop.reference + self.loop.orientation * np.asarray(phi, dtype=float)

    def kinematics(self, inputs: np.ndarray) -> KinematicState:
        """Closed-form positions for input positions ``inputs`` (n_inputs, N), each 0..1 of the
        stroke (crank angle linear in it). Raises LoopClosureError where a loop cannot close."""
        x = np.atleast_2d(np.asarray(inputs, dtype=float))
        n = n_inputs(self.truth_table)
        if x.shape[0] != n:
            raise ValueError(f"expected {n} input rows, got {x.shape[0]}")
        N = x.shape[1]
        if self.kind == "constant":
            v = np.full(N, float(self.realisation.below))
            return KinematicState({}, np.zeros(N), v, np.zeros(N), v)
        if self.kind == "literal":
            j, inv = self.literal
            v = 1.0 - x[j] if inv else x[j].copy()
            return KinematicState({}, np.zeros(N), v, np.zeros(N), v)
        lay, loop, fol = self.separator, self.loop, self.follower
        tips = {}
        for j, c in self.crank_of_input.items():
            t = 1.0 - x[j] if self.primed[c] else x[j]
            tips[c] = lay.tip(c, t, self.primed[c])
        joints = lay.solve(tips)
        F = joints["F"]
        joints["J"] = loop.joint(F)
        phi = loop.cam_angle(F)
        y = self.program(phi)
        joints["H"] = fol.roller_centre(y)
        joints = {k: v * self.scale for k, v in joints.items()}
        return KinematicState(joints, phi, y, fol.crank_angle(y), fol.output(y))


def _mirror(r: Realisation) -> Realisation:
    """Same function with every weight negated: the sum levels run the other way."""
    top = (r.below + r.k) % 2
    return Realisation(tuple(-w for w in r.weights), tuple(sorted(-t for t in r.thresholds)), top)


def generator_realisation(tt: Sequence[int]) -> Realisation:
    """The module's minimum realisation, or its mirror when that puts the thresholds in earlier
    separation angles (Table III lists tau_a first), so fewer basic linkages serve all 256."""
    r = realise(tt, n=n_inputs(tt))
    m = _mirror(r)
    return m if r.k and m.gaps() < r.gaps() else r


def design_generator(f: Sequence[int] | int, stroke_mm: float = 20.0, n: int = 3,
                     mu_min_deg: float = 45.0, pressure_limit_deg: float = 30.0,
                     samples: int = 50, strict: bool = True) -> GeneratorDesign:
    """Design the generator of ``f`` (truth table, or FV for ``n`` inputs).

    With ``strict`` a failed design check raises :class:`mechc.errors.DesignError` naming the
    check and its number; otherwise the design is returned with the failure in ``checks``.
    """
    tt = as_truth_table(f, n)
    n = n_inputs(tt)
    if n > 3:
        raise ValueError(f"threshold generators take at most 3 inputs, got {n}")
    r = generator_realisation(tt)
    design = GeneratorDesign(tt, function_value(tt), "generator", r, float(stroke_mm))
    design.hazards = static_hazards(r.weights, tt)
    active = [j for j, w in enumerate(r.weights) if w]
    if r.k == 0:
        design.kind = "constant"
        return design
    if len(active) == 1:
        j = active[0]
        design.kind = "literal"
        design.literal = (j, tt[(1 << (n - 1 - j))] == 0)  # value with only input j on
        return design
    if design.hazards:
        # no threshold generator holds every output: F must move in two dimensions
        pg = planar_generator(npn_canonical(tt), mu_min_deg, samples)
        if pg is not None:
            return _design_planar(design, pg, mu_min_deg, pressure_limit_deg, samples, strict)

    mags = tuple(sorted((abs(r.weights[j]) for j in active), reverse=True))
    lay = layout(mags, mu_min_deg)
    design.separator = lay
    scale = stroke_mm / lay.s_i
    design.scale = scale
    free = list(active)
    for c, m, coef in zip(lay.cranks, lay.proportions.pattern, lay.proportions.coeffs):
        j = next(j for j in free if abs(r.weights[j]) == m)
        free.remove(j)
        design.crank_of_input[j] = c
        design.primed[c] = (r.weights[j] > 0) != (coef > 0)

    gaps = r.gaps()
    loop = basic_loop(mags, gaps, mu_min_deg, samples)
    design.loop = loop
    an = analyse(lay, samples)
    sp = sample_points(an)
    phi = loop.cam_angle(sp.F)
    room = threshold_gaps(phi, sp, gaps)
    design.threshold_gaps_deg = tuple(float(np.degrees(g)) for g in room)
    bands = []
    for g in gaps:
        low = phi[sp.hi <= g].max()
        high = phi[sp.lo >= g + 1].min()
        c = DWELL_CLEARANCE * (high - low)
        bands.append((float(low + c), float(high - c)))
    at = _where(design)
    checks = [
        Check("separator transmission angle", at, an.min_transmission,
              mu_min_deg - TRANSMISSION_TOL, ">=", "deg"),
        Check("loop FJK transmission angle", at, float(loop.transmission(sp.F).min()),
              mu_min_deg, ">=", "deg"),
        Check("threshold gap", at, float(np.degrees(room.min())), 0.0, ">=", "deg"),
        Check("F gap between adjacent levels", at, an.min_gap * scale, 0.0, ">=", "mm"),
        Check("separator structural error", at,
              float(np.abs(an.structural_error).max() / an.unit), 0.5, "<=", "level"),
    ]
    return _finish(design, phi, tuple(bands), r.below == 1, checks, pressure_limit_deg, strict)


def _design_planar(design: GeneratorDesign, pg: PlanarGenerator, mu_min_deg: float,
                   pressure_limit_deg: float, samples: int, strict: bool) -> GeneratorDesign:
    """A generator whose F moves in two dimensions (:mod:`mechc.threshold.planar`): the wiring
    makes this function read as the class design's ``h``; the cam holds every held set."""
    perm, neg, inverted = wiring_for(design.truth_table, pg.h)
    design.planar = pg
    lay = pg.layout(mu_min_deg)
    design.separator = lay
    design.scale = design.stroke_mm / lay.s_i
    for j in range(3):
        c = lay.cranks[perm[j]]
        design.crank_of_input[j] = c
        design.primed[c] = bool(neg[j])
    design.loop = pg.loop
    ms = move_samples(lay, samples)
    F = ms.F
    phi = pg.loop.cam_angle(F)
    sets = held_sets(pg.h, ms)
    rr = runs(phi, sets)  # raises if held sets of outputs 0 and 1 overlap
    bands, gaps = [], []
    for (_, hi, _), (lo, _, _) in zip(rr, rr[1:]):
        c = DWELL_CLEARANCE * (lo - hi)
        bands.append((hi + c, lo - c))
        gaps.append(float(np.degrees(lo - hi)))
    design.threshold_gaps_deg = tuple(gaps)
    design.hazards = []  # held outputs stay on their dwells: the mechanism has none
    at = _where(design)
    checks = [
        Check("separator transmission angle", at, ms.min_transmission,
              mu_min_deg - TRANSMISSION_TOL, ">=", "deg"),
        Check("loop FJK transmission angle", at, float(pg.loop.transmission(F).min()),
              mu_min_deg, ">=", "deg"),
        Check("threshold gap", at, min(gaps), 0.0, ">=", "deg"),
    ]
    primed_out = (rr[0][2] ^ int(inverted)) == 1
    return _finish(design, phi, tuple(bands), primed_out, checks, pressure_limit_deg, strict)


def _finish(design: GeneratorDesign, phi: np.ndarray, bands: tuple[tuple[float, float], ...],
            primed_out: bool, checks: list[Check], pressure_limit_deg: float,
            strict: bool) -> GeneratorDesign:
    """Follower program, follower, closed cam and the remaining checks, from the cam angles
    ``phi`` (rad) F reaches at rest and on every change and the transition bands."""
    loop, lay, scale = design.loop, design.separator, design.scale
    lo_w, hi_w = float(phi.min()), float(phi.max())
    design.cam_range = (lo_w, hi_w)
    program = FollowerProgram(bands)
    design.program = program
    # the pressure angle peaks inside the bands; dwells are sampled coarsely while sizing
    coarse = np.concatenate([np.linspace(lo_w, hi_w, 101)]
                            + [np.linspace(a, b, 201) for a, b in bands])
    fol = _size_follower(loop, program, coarse, primed_out, lay.half_swing * 2,
                         pressure_limit_deg)
    grid = np.linspace(lo_w, hi_w, 4001)
    pa = float(fol.pressure_angle(grid, program, loop.orientation).max())
    design.follower = fol

    # closed cam and its undercut check
    margin = np.radians(5.0)
    full = closed_program(program, lo_w - margin, hi_w + margin)
    ring = np.linspace(lo_w - margin, lo_w - margin + 2 * np.pi, 3600, endpoint=False)
    body = loop.reference + loop.orientation * ring
    pitch = fol.pitch_curve(ring, full, body)
    rho = curvature_radius(pitch)
    area = np.sum(pitch[:, 0] * np.roll(pitch[:, 1], -1) - np.roll(pitch[:, 0], -1) * pitch[:, 1])
    convex = rho * np.sign(area)
    convex_min = float(convex[convex > 0].min())
    design.cam_pitch = pitch * scale
    design.cam_profile = profile(pitch, fol.roller) * scale

    at = _where(design)
    design.checks = checks[:2] + [
        Check("cam pressure angle", at, pa, pressure_limit_deg, "<=", "deg")] + checks[2:] + [
        Check("pitch curve convex radius / roller radius", at, convex_min / fol.roller, 1.0,
              ">=", ""),
        Check("shortest loop link / l", at, min(loop.FJ, loop.JK), 1.0 / 3.0 - 1e-9, ">=", ""),
    ]
    _record_dimensions(design)
    if strict and not design.ok:
        bad = "; ".join(str(c) for c in design.checks if not c.passed)
        raise DesignError(f"threshold generator FV {design.fv}: {bad}")
    return design


def _where(design: GeneratorDesign) -> str:
    """The place every check of a generator names (one generator per function)."""
    return f"threshold generator FV {design.fv}"


def _size_follower(loop: ThresholdLoop, program: FollowerProgram, grid: np.ndarray,
                   primed: bool, swing: float, limit: float) -> Follower:
    """Longest arm ZH (<= ARM_MAX) keeping the pressure angle 1 deg inside ``limit``: a longer
    arm gives a larger roller rise for the same swing, so it is kept as large as allowed."""

    def make(arm: float) -> Follower:
        return Follower(loop.K, 0.0, FOLLOWER_RADIUS, arm, swing, min(ROLLER_MAX, arm / 2), primed)

    def worst(arm: float) -> float:
        return float(make(arm).pressure_angle(grid, program, loop.orientation).max())

    lo, hi = ARM_MIN, ARM_MAX
    if worst(hi) <= limit - 1.0:
        return make(hi)
    if worst(lo) > limit - 1.0:
        return make(lo)  # the pressure-angle check will report the failure
    while hi - lo > 1e-4:
        mid = (lo + hi) / 2
        if worst(mid) <= limit - 1.0:
            lo = mid
        else:
            hi = mid
    return make(lo)


def _record_dimensions(d: GeneratorDesign) -> None:
    s = d.scale
    lay = d.separator
    d.links = {k: v * s for k, v in lay.lengths.items()}
    d.links.update(FJ=d.loop.FJ * s, JK=d.loop.JK * s, ZH=d.follower.arm * s,
                   roller=d.follower.roller * s, KH_mid=d.follower.radius * s)
    for c in lay.cranks:
        x, xp = lay.centres[c]
        d.pivots[f"X_{c}"] = (x[0] * s, x[1] * s)
        d.pivots[f"X_{c}'"] = (xp[0] * s, xp[1] * s)
    d.pivots["K"] = (d.loop.K[0] * s, d.loop.K[1] * s)
    z = d.follower.pivot * s
    d.pivots["Z'" if d.follower.primed else "Z"] = (float(z[0]), float(z[1]))


def rest_inputs(n: int) -> np.ndarray:
    """All 2**n input vectors as columns (n, 2**n), minterm order."""
    return input_matrix(n).T.astype(float)
