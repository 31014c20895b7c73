"""THRESHOLD: any function of up to three inputs as one separator + cam linkage (001 Ch. III).

The generator of :mod:`mechc.threshold` (weights, separator, loop FJK, dwell-rise-dwell cam,
roller follower; dimensions in mm, design checks) is turned into bodies and joints here:

- each input slider (x = 0, off -> on in +x) drives its separator crank by a horizontal rod (a
  crank-slider converter); a crank turning about X' (negative weight, Fig. 28) is driven on the
  far side of its centre, so its pin moves opposite to the slider;
- separator links AD, DE (and BG, CG) and FJ are free "link" bodies joined by "pin" joints, F
  lies on AD; J is pinned to the cam, a lever about K;
- the cam profile is a "touch" polyline on the cam; the roller is a circle on the output crank
  (a lever about Z or Z'), held on the cam by a spring at the crank's drive point Q;
- Q drives the translating output slider by a horizontal rod.

The generic closed forms solve everything up to the cam (rods and dyads); :meth:`kinematics`
then applies the follower program (the cam is the envelope of the roller, so the follower
follows the program exactly) and solves the output slider. A cam angle outside the range the
cam was designed for is marked bad, not extrapolated.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from mechc.cells.builder import Builder
from mechc.cells.cell import Cell
from mechc.errors import DesignError
from mechc.geometry.circles import quarter_turn
from mechc.ir.logic_types import evaluate_type
from mechc.ir.mechanism import Body, Demand, Joint, Part
from mechc.physics.closed_form import Poses, solve
from mechc.threshold.cam import Follower, FollowerProgram
from mechc.threshold.functions import input_matrix
from mechc.threshold.generator import GeneratorDesign, design_generator

ROD_FACTOR = 1.5  # shortest input rod, in crank lengths (keeps the rod-crank angle >= 70 deg)
PRESSURE_LIMIT_DEG = 30.0
MU_MIN_DEG = 45.01  # the separator meets mu_min exactly in the Fig. 42 position: keep 0.01 deg
PROFILE_POINTS = 720  # cam outline vertices (0.5 deg apart) for the drawing and the contact
TOUCH_SLACK_DEG = 3.0  # contact arc beyond the cam angles the roller can reach
CAM_RANGE_TOL = np.radians(4.9)  # the closed cam dwells 5 deg beyond its working range
CAM_FRICTION = 0.05  # coefficient between cam and roller (a rolling roller: small)
# planes of the input cranks (input sliders take planes 0..2, the separator links 5..9): cranks
# A and B, and B and C, sweep across each other in some generators (24 of the 256 functions), so
# B has a plane of its own; A and C never come near (the interference design check watches them)
CRANK_PLANES = {"A": 4, "B": 3, "C": 4}


def truth_table(params: dict, n: int) -> tuple[int, ...]:
    """The function the cell's params describe (minterm order, input 0 most significant), by
    the logic type's own evaluator so the mechanism and the logic level cannot disagree."""
    x = input_matrix(n).T.astype(bool)
    out = evaluate_type("THRESHOLD", list(x), params, 1 << n)
    return tuple(int(v) for v in out)


def bar_poly(p, q, w: float) -> list[tuple[float, float]]:
    """A bar of width ``w`` from p to q (rounded ends left to the drawing)."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    n = math.hypot(dx, dy) or 1.0
    ox, oy = -dy / n * w / 2, dx / n * w / 2
    return [(p[0] + ox, p[1] + oy), (q[0] + ox, q[1] + oy), (q[0] - ox, q[1] - oy),
            (p[0] - ox, p[1] - oy)]


def _crank_offset(l_mm: float, delta: float, rod: float) -> float:
    """Crank angle u (from its mid position, rad) when its slider is at mid stroke: the rod is
    horizontal at both ends of the stroke, so at mid stroke the pin sits a little high and the
    crank a little short of its mid position (solved exactly)."""
    dy = lambda u: l_mm * (math.cos(u) - math.cos(delta))  # noqa: E731

    def f(u: float) -> float:
        return (rod + l_mm * math.sin(u)) ** 2 + dy(u) ** 2 - rod * rod

    return brentq(f, -delta, delta)


class ThresholdCell(Cell):
    name = "threshold"
    type = "THRESHOLD"
    min_inputs = 2
    max_inputs = 3
    description = ("threshold generator: separator linkage + loop FJK + dwell-rise-dwell cam "
                   "and roller follower, any function of 2-3 inputs (001 Ch. III)")

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        # input sliders, cranks, AD, DE (+ BG, CG), FJ, cam, follower, output slider, spring
        return n_inputs * 2 + (2 if n_inputs == 2 else 4) + 5

    @classmethod
    def design(cls, n_inputs: int, params: dict, stroke: float,
               angle_margin: float = 0.0) -> GeneratorDesign:
        """``angle_margin``: degrees of separator transmission angle beyond the limit (robust
        design asks for it: the angle scatters with the tolerances)."""
        tt = truth_table(params, n_inputs)
        d = design_generator(tt, stroke_mm=stroke, mu_min_deg=MU_MIN_DEG + angle_margin,
                             pressure_limit_deg=PRESSURE_LIMIT_DEG)
        if d.kind != "generator":
            raise DesignError(f"THRESHOLD {params}: the function is a {d.kind}; map it to a "
                              "wire, NOT or CONST cell, not a generator")
        return d

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        d = cls.design(n_inputs, params, ctx.stroke, ctx.angle_margin)
        return build_part(cid, ctx, n_inputs, d, demand, cls.input_names(n_inputs))

    @classmethod
    def kinematics(cls, part: Part, fixed, size, extra=None):
        info = part.data["threshold"]
        fol_id, out_id, cam_id = info["follower_body"], info["output_body"], info["cam_body"]
        back_ids = {fol_id, out_id}
        front = Part([b for b in part.bodies if b.id not in back_ids],
                     [j for j in part.joints if j.a not in back_ids and j.b not in back_ids])
        poses = solve(front, fixed, size, extra)
        phi = info["phi_design"] + info["orientation"] * poses.theta[cam_id]
        program = FollowerProgram(tuple(tuple(b) for b in info["bands"]))
        y, _ = program.evaluate(phi)
        lo, hi = info["cam_range"]
        outside = (phi < lo - CAM_RANGE_TOL) | (phi > hi + CAM_RANGE_TOL) | ~np.isfinite(phi)
        sense = 1.0 if info["follower_primed"] else -1.0
        th = sense * info["swing"] * (y - info["y_design"])
        err = info.get("profile_error")
        if err is not None:  # a cam, roller or pivots cut off their drawing (tolerance runs)
            th = th + contact_error_turn(part, info, err, poses.theta[cam_id], phi, th,
                                         program, outside)
        back = Part([b for b in part.bodies if b.id in back_ids],
                    [j for j in part.joints if j.kind == "rod" and {j.a, j.b} == back_ids])
        rest = solve(back, {fol_id: np.where(outside, np.nan, th)}, size)
        poses.update(Poses(u=rest.u, theta={fol_id: rest.theta[fol_id]},
                           transmission=rest.transmission,
                           singular_margin=rest.singular_margin))
        bad = poses.bad.get(cam_id, np.zeros(size, bool)) | outside
        poses.mark(fol_id, bad)
        poses.mark(out_id, bad | rest.bad.get(out_id, np.zeros(size, bool)))
        f = info["follower"]
        fol = Follower(tuple(f["K"]), f["direction"], f["radius"], f["arm"], info["swing"],
                       f["roller"], info["follower_primed"])
        pa = fol.pressure_angle(np.where(outside, lo, phi), program, info["orientation"])
        # the transmission angle of a cam pair is 90 deg minus its pressure angle
        poses.transmission[info["touch_joint"]] = np.where(outside, np.nan, 90.0 - pa)
        return poses


def _follower(info: dict) -> Follower:
    f = info["follower"]
    return Follower(tuple(f["K"]), f["direction"], f["radius"], f["arm"], info["swing"],
                    f["roller"], info["follower_primed"])


def _rot(a, v):
    """Vectors (..., 2) turned by angles ``a`` (rad, counter-clockwise)."""
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], -1)


def contact_error_turn(part: Part, info: dict, err: dict, cam_theta, phi, th,
                       program: FollowerProgram, outside) -> np.ndarray:
    """How far (rad, counter-clockwise) the follower turns from its program when the cam pair
    is made off its drawing: the cam's outline off radially by ``err["mm"]`` at the cam angles
    ``err["phi"]`` (linear between them), the roller's radius off by ``err["roller_mm"]``, and
    the cam's pivot K, the follower's pivot Z and the roller's centre on it moved from where the
    drawing put them (``err["K"]``, ``err["Z"]``, ``err["H"]``, mm, the drawing's values: the
    part's own are the made ones).

    First order, as every tolerance here: the roller must stay on the cam, so the gap these
    errors open along the contact's common normal n is closed by turning the follower by
    gap / (dH/dtheta . n). A perturbed design written as JSON carries ``err`` in this cell's
    data, so the kinematic proof of that file sees the same cam (its drawn outline stays
    nominal)."""
    fol = _follower(info)
    safe = np.where(outside, info["cam_range"][0], phi)
    y, dy = program.evaluate(safe)
    H = fol.roller_centre(y)  # separator frame, crank lengths
    arm = H - fol.pivot
    dpsi = (fol.swing if fol.primed else -fol.swing) * dy
    rel = H - np.asarray(fol.K)
    tangent = dpsi[..., None] * quarter_turn(arm) - info["orientation"] * quarter_turn(rel)
    n = quarter_turn(tangent)
    n = n / np.hypot(n[..., 0], n[..., 1])[..., None]
    n = np.where(((n * rel).sum(-1) < 0)[..., None], -n, n)  # outwards, cam to roller
    cam = next(b for b in part.bodies if b.id == info["cam_body"])
    fol_body = next(b for b in part.bodies if b.id == info["follower_body"])
    touch = next(j for j in part.joints if j.id == info["touch_joint"])
    K0, Z0, H0 = (np.asarray(err[k], float) for k in ("K", "Z", "H"))
    scale = float(np.hypot(*(H0 - Z0))) / fol.arm  # mm per crank length
    size = np.shape(phi)

    def delta(now, was) -> np.ndarray:
        return np.stack([np.broadcast_to(np.asarray(now[c], float) - was[c], size)
                         for c in (0, 1)], -1)

    dK, dZ, dH = delta(cam.pivot, K0), delta(fol_body.pivot, Z0), delta(touch.q, H0)
    angles = np.asarray(err["phi"], float)
    radial = 0.0
    for k, v in enumerate(err["mm"]):  # hat functions: linear between the cam angles
        radial = radial + np.interp(safe, angles, np.eye(len(angles))[k]) * np.asarray(v)
    radial = radial + np.asarray(err.get("roller_mm", 0.0))
    cam_turn = np.broadcast_to(np.asarray(cam_theta, float), size)
    th_b = np.broadcast_to(np.asarray(th, float), size)
    pitch_moved = dK - _rot(cam_turn, dK)  # the profile turns about the moved pivot
    roller_moved = dZ + _rot(th_b, dH - dZ)
    gap = radial + ((pitch_moved - roller_moved) * n).sum(-1)
    gain = (quarter_turn(arm) * n).sum(-1) * scale  # mm of normal travel per rad
    return np.where(outside, 0.0, gap / gain)


def build_part(cid: str, ctx, n_inputs: int, d: GeneratorDesign, demand: Demand,
               pins: list[str]) -> Part:
    """Bodies and joints of generator ``d`` (see the module docstring), at the design pose:
    every input slider and the output slider at mid stroke."""
    b = Builder(cid, ctx)
    S, w = ctx.stroke, ctx.bar
    lay, loop, fol = d.separator, d.loop, d.follower
    sc = d.scale
    l_mm = sc  # crank length
    delta = lay.half_swing
    rod_min = ROD_FACTOR * l_mm

    # --- crank angles at the design pose (every input slider at mid stroke) -----------------
    centres = {}  # crank -> centre (mm, separator frame)
    for c in lay.cranks:
        x, xp = lay.centres[c]
        centres[c] = np.array(xp if d.primed[c] else x) * sc
    x_att = min(float(c[0]) for c in centres.values()) - rod_min  # input rods start here
    x_in = np.full((n_inputs, 1), 0.5)
    drive: dict[str, tuple[float, float]] = {}
    rods: dict[str, float] = {}
    for j, c in d.crank_of_input.items():
        rod = float(centres[c][0]) - x_att
        u = _crank_offset(l_mm, delta, rod)  # drive point's clockwise angle from vertical
        x_in[j, 0] = (u + delta) / (2 * delta)  # the input fraction with the crank there
        rods[c] = rod
    ks = d.kinematics(x_in)
    J = {k: v[0] for k, v in ks.joints.items()}
    # drive point: the pin (turning about X) or the point opposite the pin (about X')
    for c in lay.cranks:
        pin = J[c]
        ctr = centres[c]
        drive[c] = tuple(2 * ctr - pin) if d.primed[c] else tuple(pin)

    # separator frame -> cell frame: input sliders' left ends (terminals) at x = 0
    ox = -(x_att - 1.5 * S)
    ys = [float(centres[c][1]) + l_mm * math.cos(delta) for c in lay.cranks]  # rod rows
    oy = -max(ys)

    def P(p) -> tuple[float, float]:
        return (float(p[0]) + ox, float(p[1]) + oy)

    # --- input sliders and cranks -----------------------------------------------------------
    spare_y = min(float(np.min([v[1] for v in J.values()])), min(ys)) - 2 * w
    for j, pin in enumerate(pins):
        c = d.crank_of_input.get(j)
        y = (float(centres[c][1]) + l_mm * math.cos(delta) if c else spare_y - j * 2 * w) + oy
        b.slider(f"in_{pin}", 0.0, 1.5 * S, y, f"input {pin}", layer=j)
        b.terminal(pin, b.name(f"in_{pin}"), (0.0, y))
        if c is None:
            continue
        crank = b.name(f"crank_{c}")
        ctr, pinp, drv = P(centres[c]), P(J[c]), P(drive[c])
        polys = [bar_poly(ctr, pinp, w)]
        if d.primed[c]:
            polys.append(bar_poly(ctr, drv, w))
        b.part.bodies.append(Body(crank, "lever", polys, ctx.mass(polys), pivot=ctr,
                                  layer=CRANK_PLANES[c], role=f"input crank {c} ({pin})"))
        b.rod(b.name(f"in_{pin}"), crank, (1.5 * S, y), drv)

    # --- separator links ---------------------------------------------------------------------
    def link(local: str, pts: list, layer: int, role: str) -> str:
        bid = b.name(local)
        polys = [bar_poly(P(p), P(q), w) for p, q in zip(pts, pts[1:])]
        b.part.bodies.append(Body(bid, "link", polys, ctx.mass(polys), pivot=P(pts[0]),
                                  layer=layer, role=role))
        return bid

    def pin(a: str, bb: str, p) -> None:
        b.part.joints.append(Joint(b._id("pin"), "pin", a, bb, pa=P(p)))

    far_f = J["F"] if np.dot(J["F"] - J["A"], J["D"] - J["A"]) > np.dot(
        J["D"] - J["A"], J["D"] - J["A"]) or lay.f_offset else J["D"]
    ad = link("AD", [J["A"], J["D"], far_f] if far_f is not J["D"] else [J["A"], J["D"]], 5,
              "separator link AD (carries F)")
    de = link("DE", [J["D"], J["E"]], 6, "separator coupler DE")
    pin(b.name("crank_A"), ad, J["A"])
    pin(ad, de, J["D"])
    if lay.five_bar:
        pin(b.name("crank_B"), de, J["E"])
    else:
        # E beyond G, or off the line BG (free eight-bar, mechc.threshold.planar): bent bar
        far_e = J["E"] if np.dot(J["E"] - J["B"], J["G"] - J["B"]) > np.dot(
            J["G"] - J["B"], J["G"] - J["B"]) or lay.e_offset else J["G"]
        bg = link("BG", [J["B"], J["G"], far_e] if far_e is not J["G"] else [J["B"], J["G"]],
                  7, "separator link BG (carries E)")
        cg = link("CG", [J["C"], J["G"]], 8, "separator coupler CG")
        pin(b.name("crank_B"), bg, J["B"])
        pin(b.name("crank_C"), cg, J["C"])
        pin(bg, cg, J["G"])
        pin(bg, de, J["E"])
    fj = link("FJ", [J["F"], J["J"]], 9, "loop link FJ")
    pin(ad, fj, J["F"])

    # --- cam on the K crank -----------------------------------------------------------------
    K = np.asarray(d.pivots["K"])
    phi_d = float(ks.cam_angle[0])
    ang = float(d.cam_body_angle(phi_d))
    rot = np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]])
    step = max(1, len(d.cam_profile) // PROFILE_POINTS)
    prof_w = [P(K + rot @ p) for p in d.cam_profile[::step]]
    # the contact: only the arc the roller can reach (the working range, the 5 deg dwells the
    # generator adds beyond it, and TOUCH_SLACK_DEG more), at the outline's resolution -- the
    # dynamic model checks every segment of it at every step
    per_rad = len(d.cam_profile) / (2 * np.pi)  # profile index 0 is at cam angle lo - 5 deg
    slack = np.radians(TOUCH_SLACK_DEG)
    reach = d.cam_range[1] - d.cam_range[0] + 2 * np.radians(5.0)
    idx = np.arange(-int(slack * per_rad), int((reach + slack) * per_rad) + 1, step)
    touch_w = [P(K + rot @ p) for p in d.cam_profile[idx % len(d.cam_profile)]]
    cam = b.name("cam")
    cam_polys = [prof_w, bar_poly(P(K), P(J["J"]), w)]
    b.part.bodies.append(Body(cam, "lever", cam_polys, ctx.mass(cam_polys), pivot=P(K),
                              layer=10, role="cam (on crank KJ)"))
    pin(fj, cam, J["J"])

    # --- follower (output crank) at the design pose: output slider at mid stroke ------------
    # The drive point Q is l above Z at mid swing and turns clockwise from "0" to "1"; its rod
    # runs right to the output slider, long enough to clear the rest of the mechanism.
    Z = fol.pivot * sc
    x_right = max(p[0] for body in b.part.bodies for poly in body.outline for p in poly)
    rod_len = max(rod_min, x_right + w - P(Z)[0])
    v = -_crank_offset(l_mm, delta, rod_len)  # Q's clockwise angle from vertical at design
    o_d = 0.5 + v / fol.swing  # output fraction there
    y_d = 1.0 - o_d if fol.primed else o_d  # output = y about Z, 1 - y about Z'
    H = fol.roller_centre(y_d) * sc
    Q = Z + l_mm * np.array([math.sin(v), math.cos(v)])
    follower = b.name("follower")
    f_polys = [bar_poly(P(Z), P(H), w * 0.6), bar_poly(P(Z), P(Q), w)]
    b.part.bodies.append(Body(follower, "lever", f_polys, ctx.mass(f_polys), pivot=P(Z),
                              layer=11, role="output crank with roller"))
    touch = Joint(b._id("touch"), "touch", cam, follower, q=P(H), profile=touch_w,
                  length=fol.roller * sc, friction=CAM_FRICTION)
    b.part.joints.append(touch)
    y_q = P(Z)[1] + l_mm * math.cos(delta)
    x_s = P(Z)[0] + rod_len  # output slider's left end at mid stroke
    out = b.slider("out", x_s, x_s + 1.5 * S, y_q, "THRESHOLD output", layer=12)
    b.rod(follower, out.body, P(Q), (x_s, y_q))
    b.output(out, "Z")

    # --- spring holding the roller on the cam, acting at Q ----------------------------------
    # it turns the crank towards the inner dwell: towards "0" (Z) or towards "1" (Z')
    direction = 1 if fol.primed else -1
    hold = demand.right if fol.primed else demand.left
    preload = max(ctx.min_preload, ctx.margin * (hold + ctx.friction))
    b.spring(follower, P(Q), direction, preload, b.moving_mass([follower, out.body]))
    b.part.data.setdefault("spring_required_N", {})[b.part.springs[-1].id] = round(
        hold + ctx.friction, 6)

    loads = _input_loads(d, preload * (1 + ctx.spring_range) + max(demand.left, demand.right)
                         + ctx.friction, n_inputs)
    r = d.realisation
    b.part.data["threshold"] = {
        "fv": d.fv, "truth_table": list(d.truth_table),
        "mechanism": "planar" if d.planar else "threshold",
        "mechanism_weights": None if d.planar else list(r.weights),
        "mechanism_thresholds": None if d.planar else list(r.thresholds),
        "mechanism_below": None if d.planar else int(r.below),
        "planar": None if not d.planar else {
            "wiring_function": list(d.planar.h), "p1": d.planar.p1, "p2": d.planar.p2,
            "f_offset": d.planar.offset, "separation_deg": d.planar.separation_deg},
        "cam_body": cam, "follower_body": follower, "output_body": out.body,
        "touch_joint": touch.id,
        "phi_design": phi_d, "orientation": int(loop.orientation),
        "bands": [list(map(float, bd)) for bd in d.program.bands],
        "cam_range": [float(v) for v in d.cam_range],
        "swing": float(fol.swing), "follower_primed": bool(fol.primed), "y_design": float(y_d),
        "follower": {"K": [float(v) for v in fol.K], "direction": float(fol.direction),
                     "radius": float(fol.radius), "arm": float(fol.arm),
                     "roller": float(fol.roller)},
        "crank_of_input": {pins[j]: c for j, c in d.crank_of_input.items()},
        "primed": {c: bool(v) for c, v in d.primed.items()},
        "links_mm": {k: round(v, 4) for k, v in d.links.items()},
        "checks": [str(c) for c in d.checks],
        "hazards": [list(h) for h in d.hazards],
    }
    if d.planar is not None and d.planar.free is not None:
        b.part.data["threshold"]["planar"]["free_eight_bar"] = list(d.planar.free)
    return b.finish({pins[j]: loads[j] for j in range(n_inputs)})


def _input_loads(d: GeneratorDesign, force: float, n: int) -> list[Demand]:
    """What each input must push or pull: the force at Q times the largest ratio of output
    travel to input travel along any single-input change (virtual work; the separator and the
    cam pair are taken as frictionless, which the dynamic proof then tests)."""
    samples = 41
    x = input_matrix(n).astype(float)
    out = []
    u = np.linspace(0.0, 1.0, samples)
    for j in range(n):
        cols = []
        for a in x:
            if a[j]:
                continue
            xs = np.repeat(a[:, None], samples, 1)
            xs[j] = u
            cols.append(xs)
        o = d.kinematics(np.concatenate(cols, 1)).output.reshape(len(cols), samples)
        ratio = float(np.abs(np.diff(o, axis=1)).max() * (samples - 1))
        f = force * ratio
        out.append(Demand(f, f))
    return out


__all__ = ["ThresholdCell", "build_part", "truth_table"]
