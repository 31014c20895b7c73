"""AMPLIFIER: a bistable toggle switched by powered friction rollers (001 §2.6, Fig. 17).

Two rollers R1, R2 turn continuously (R1 counter-clockwise, R2 clockwise here; Fig. 17 is this
layout mirrored). The input slider S carries two friction rollers F1, F2, each floating in a
short slot and pressed towards its wedge by a light spring. The output toggle T turns about Q;
its cylindrical surface C (radius ``Rc`` about Q) has a relief I. When A goes on, F1 enters the
wedge between R1 and C: R1's friction drags F1 deeper into the wedge, which gives the normal
force, and F1, an idler, turns C (and T) counter-clockwise. Just before T reaches its stop Sp1
the relief comes under F1 and the drive stops; momentum and the over-centre toggle spring carry
T onto Sp1. Going off, F2, R2 and Sp2 do the same the other way. A crank pin on T and a rod turn
T's swing into the output slider's stroke.

Because the rollers and C are cylinders about fixed centres, the wedge keeps its shape while T
turns, and nothing but F's spring and the slider guide resists the input: the input force is
about its slider friction, the output force comes from the motor.

Kinematic model (quasi-static): T rests on the stop its input state selects (off below half
stroke, on from half stroke), the output slider follows the crank closed form, F1/F2 follow the
slider until their wedge stops them. The switching itself is only in the dynamic model.

Dynamic model: the wedge is a one-way roller clutch, and pymunk cannot find its lock on its own
(see ``_add_wedge_clutches``), so each wedge also gets a ratchet that holds T at the roller-matched
speed while its F touches both R and C.

Landing: past dead centre the toggle spring gives back what the drive put into it, about the hold
torque times half the swing, and the loads may push the same way; with nothing to take that
energy T would land on its stop many times faster than the rollers drive it (15x for the loads
of a 2-bit adder: see docs/amplifier.md). Where that work exceeds ``SNAP_WORK_LIMIT`` a dashpot
on the output slider, sized from those torques, bounds the landing speed whatever the masses;
``check_landing`` is the design check (the cell's ``checks``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pymunk
from scipy.optimize import brentq

from mechc.cells.builder import Builder, rect
from mechc.cells.cell import Cell
from mechc.cells.springs import design_coil
from mechc.errors import DesignError
from mechc.ir.check import Check
from mechc.ir.mechanism import GROUND, Body, Demand, Joint, Part, Point, Spring, SynthContext
from mechc.parts.contact import stiff_stops
from mechc.parts.lever import Lever
from mechc.physics.closed_form import solve
from mechc.physics.scene import FAR, N

#: A table computed once by ``python benchmarks/amplifier.py`` (pymunk, default SynthContext
#: and DynSettings: stroke 20 mm, rollers at 60 rad/s) and re-measured by
#: tests/test_amplifier.py; stored in every instance's part.data for the mapper and the
#: sequential proof. Delay: input at 95 % of its stroke -> output within 5 % of its new end
#: (worst of on and off). Fan-out: OR inputs driven with prove_dynamic passing. With massless
#: rods 4 failed; since the nets' rods are bodies with mass the benchmark passes up to 6 (its
#: --kmax): 3 is kept, a conservative limit the mapper splits fan-outs by, until the splitting
#: is re-derived from the new measurement.
MEASURED = {
    "switching_delay_s": 0.048,
    "fanout_max": 3,
}


@dataclass(frozen=True)
class AmpDesign:
    """The numbers that fix an amplifier (mm, N, rad, rad/s)."""

    stroke: float
    r_f: float  # friction roller radius
    r_r: float  # powered roller radius
    rc: float  # radius of the cylindrical surface C
    beta: float  # F's contact on C, from the top of C (rad): also half the relief travel
    gamma: float  # F's contact on R, from the vertical (rad)
    coast: float  # T's coast from the relief to its stop (rad)
    relief_depth: float
    r_o: float  # crank radius
    rod: float  # crank rod length
    theta_on: float  # T's stops, from the design pose (output at half stroke)
    theta_off: float
    engage: float  # slider travel short of its end at which F meets its wedge
    slot: float  # F's slot length
    play: float  # F's free play across its slot (each way)
    press: float  # F's spring force at its slot end (N)
    press_rate: float  # N/mm
    mu: float  # roller friction coefficient
    speed: float  # powered roller speed (rad/s)
    toggle_e: float  # toggle spring: radius of its point on T (above Q at design)
    toggle_g: float  # distance of its ground anchor below Q
    toggle_rate: float  # N/mm
    toggle_rest: float  # mm
    toggle_damping: float  # damping ratio of T on its toggle spring
    hold_required: float  # N mm, torque T must hold on either stop
    hold_torque: float  # N mm, the toggle spring's torque at the weaker stop
    load_torque: float = 0.0  # N mm, the most the loads push T with (demand, no margin)
    dashpot: float = 0.0  # N s/mm, viscous damper on the output slider (0: none)


def crank_u(theta, r_o: float, rod: float):
    """Output slider travel for T at ``theta`` (crank pin below Q at theta = 0, rod level)."""
    dy = r_o * (1.0 - np.cos(theta))
    return r_o * np.sin(theta) + np.sqrt(rod * rod - dy * dy) - rod


def toggle_torque(theta, d: AmpDesign):
    """Counter-clockwise torque (N mm) of the over-centre spring on T at ``theta``."""
    e, g = d.toggle_e, d.toggle_g
    length = np.sqrt(e * e + g * g + 2 * e * g * np.cos(theta))
    return d.toggle_rate * (length - d.toggle_rest) * e * g * np.sin(theta) / length


#: Work (N mm) the snap may bring onto a stop per switch without a dashpot: the toggle spring's
#: energy from dead centre to the stop plus the loads' push over that half swing (independent of
#: any mass; see ``snap_work``). The dynamic proof passed undamped amplifiers up to 94 N mm
#: (seed-203 flow table; fan-out 3 at 74 N mm, landing at 3-4.3x the driven speed) and refused
#: every one from 98 N mm (fan-out 4 ORs: the bars overran their stops) to the 2-bit adder's
#: force amplifiers (940-1780 N mm: 11-15x, the output slider at 5.4 m/s, contacts overrun by
#: 1.2 mm). 0.1 J is also the kinetic energy of a 50 g output at 2 m/s.
SNAP_WORK_LIMIT = 100.0
#: A fitted dashpot is sized so that T lands on a stop at no more than this multiple of the
#: speed the rollers drive it at, with the loads pushing it all the way, whatever the masses.
LANDING_RATIO = 2.0
#: The design check on a damped amplifier: its landing bound may not exceed this multiple.
MAX_LANDING_RATIO = 4.0


def roller_matched_speed(d: AmpDesign) -> float:
    """T's speed (rad/s) while a closed wedge drives it: C's surface moves with R's."""
    return d.speed * d.r_r / d.rc


def snap_energy(d: AmpDesign) -> float:
    """Energy (N mm) the toggle spring gives T from dead centre to the farther stop, from the
    spring's own energy k (L - L0)^2 / 2 (L = e + g at dead centre)."""
    e, g = d.toggle_e, d.toggle_g

    def u(theta: float) -> float:
        length = math.sqrt(e * e + g * g + 2 * e * g * math.cos(theta))
        return 0.5 * d.toggle_rate * (length - d.toggle_rest) ** 2

    return u(0.0) - min(u(d.theta_on), u(d.theta_off))


def snap_work(d: AmpDesign) -> float:
    """Most work (N mm) that drives T past dead centre onto a stop: the spring's snap energy and
    the loads pushing with their whole demand over the half swing. Undamped it all arrives at
    the stop as kinetic energy of T, its output and whatever loads move with them."""
    return snap_energy(d) + d.load_torque * max(d.theta_on, -d.theta_off)


def _max_spring_torque(d: AmpDesign) -> float:
    thetas = np.linspace(d.theta_off, d.theta_on, 181)
    return float(np.max(np.abs(toggle_torque(thetas, d))))


def landing_speed(d: AmpDesign) -> float:
    """Upper bound (rad/s) of T's speed as it lands on a stop, for any masses of T, its output
    and the loads (infinite without a dashpot).

    Where T turns faster than (spring + load torque) / (c arm^2) the dashpot's torque
    c (w arm) arm exceeds everything that drives T, so T slows: it cannot land faster than
    that, nor than the rollers drive it (arm: the crank's smallest, at a stop)."""
    if d.dashpot <= 0.0:
        return math.inf
    arm = d.r_o * math.cos(max(d.theta_on, -d.theta_off))
    terminal = (_max_spring_torque(d) + d.load_torque) / (d.dashpot * arm * arm)
    return max(roller_matched_speed(d), terminal)


def check_landing(d: AmpDesign, where: str = "amplifier") -> list[Check]:
    """The design check: a snap of more than ``SNAP_WORK_LIMIT`` needs a dashpot, and a
    dashpot must bound the landing to ``MAX_LANDING_RATIO`` x the driven speed (a light snap
    without a dashpot has nothing to check)."""
    if d.dashpot <= 0.0:
        work = snap_work(d)
        if work <= SNAP_WORK_LIMIT:
            return []
        return [Check("toggle snap onto its stop without a dashpot (slams the output and its "
                      "loads)", where, work, SNAP_WORK_LIMIT, "<=", "N mm")]
    ratio = landing_speed(d) / roller_matched_speed(d)
    # the 1e-9 lets a dashpot sized for exactly MAX_LANDING_RATIO pass despite rounding
    return [Check("toggle landing on a stop with its dashpot / driven speed", where, ratio,
                  MAX_LANDING_RATIO * (1 + 1e-9), "<=", "x")]


def rest_shortfall(part: Part, poses) -> float:
    """How far (mm) the input slider rests short of its nearer end, at worst over the states of
    ``poses`` (NaN where unsolved counts as not reaching)."""
    d = part.data["design"]
    slider = next(b for b in part.bodies if b.role == "input A")
    u = np.asarray(poses.u[slider.id], dtype=float)
    short = d["stroke"] / 2 - np.abs(u)
    return float(np.nanmax(np.where(np.isfinite(short), short, np.inf))) if short.size else 0.0


def check_rest(part: Part, poses, where: str) -> list[Check]:
    """The design check on the input's rest positions: short of its end by at most engage."""
    return [Check("input at rest short of its end (the wedge engages within)", where,
                  rest_shortfall(part, poses), part.data["design"]["engage"], "<=", "mm")]


def design(ctx: SynthContext, demand: Demand, params: dict | None = None) -> AmpDesign:
    """Dimensions from the stroke, the toggle spring from what the output must hold, and the
    dashpot from what the spring and the loads give back past dead centre.

    ``params``: geometry (``beta_deg``, ``coast_deg``, ``gamma_deg``, ``rod``), the drive
    (``speed``, ``mu``, ``press_N``, ``press_rate``), ``toggle_damping``, ``landing_ratio``
    (default ``LANDING_RATIO``, used where the snap work exceeds ``SNAP_WORK_LIMIT``; 0 never
    fits a dashpot, which ``check_landing`` then fails for a heavy snap)."""
    p = params or {}
    S = ctx.stroke
    beta = math.radians(p.get("beta_deg", 15.0))
    coast = math.radians(p.get("coast_deg", 5.0))
    half = beta  # T swings ±beta: the relief travels from F2 to F1 (2 beta)
    r_o = S / (2.0 * math.sin(half))
    rod = p.get("rod", 1.0 * S)
    # stops where the output is exactly at its ends (the crank is a hair asymmetric)
    theta_on = brentq(lambda t: crank_u(t, r_o, rod) - S / 2, 0.0, 2 * half)
    theta_off = brentq(lambda t: crank_u(t, r_o, rod) + S / 2, -2 * half, 0.0)
    e, g = 0.5 * 1.6 * S, 1.0 * S
    arm_on = r_o * math.cos(theta_on)  # moment arm of a level rod force about Q
    arm_off = r_o * math.cos(theta_off)
    need = max((demand.right + ctx.friction) * arm_on, (demand.left + ctx.friction) * arm_off)
    need = max(need, ctx.min_preload * arm_on)
    hold_required = ctx.margin * need
    # spring: tension at the stops T_s with 30 % rise towards dead centre (k * dL = 0.3 T_s)
    l_stop = math.sqrt(e * e + g * g + 2 * e * g * math.cos(max(theta_on, -theta_off)))
    l_mid = e + g
    geo = e * g * min(math.sin(theta_on), -math.sin(theta_off)) / l_stop
    tension = hold_required / geo
    rate = ctx.spring_range * tension / (l_mid - l_stop)
    rest = l_stop - tension / rate
    d = AmpDesign(S, 0.2 * S, 0.25 * S, 1.6 * S, beta, math.radians(p.get("gamma_deg", 15.0)),
                  coast, 0.1 * S, r_o, rod, theta_on, theta_off, 0.025 * S, 0.075 * S, 0.0125 * S,
                  p.get("press_N", 0.1), p.get("press_rate", 0.02), p.get("mu", 0.6),
                  p.get("speed", 60.0), e, g, rate, rest, p.get("toggle_damping", 0.3),
                  hold_required, 0.0)
    hold = min(float(toggle_torque(theta_on, d)), -float(toggle_torque(theta_off, d)))
    d = AmpDesign(**{**d.__dict__, "hold_torque": hold, "load_torque": need})
    if hold < hold_required * (1 - 1e-9):
        raise DesignError(f"amplifier toggle spring holds {hold:.4g} N mm, needs "
                          f"{hold_required:.4g} N mm")
    # dashpot: at LANDING_RATIO x the driven speed its torque c (w arm) arm matches the most
    # the spring and the loads can drive T with (terminal speed; see landing_speed). A light
    # snap goes without: T then runs ahead of the rollers past dead centre, as Fig. 17 has it
    ratio = p.get("landing_ratio", LANDING_RATIO)
    if ratio and snap_work(d) > SNAP_WORK_LIMIT:
        arm = r_o * min(math.cos(theta_on), math.cos(theta_off))
        w0 = roller_matched_speed(d)
        c = (_max_spring_torque(d) + need) / (ratio * w0 * arm * arm)
        d = AmpDesign(**{**d.__dict__, "dashpot": c})
        # the rollers drive T through it (the dashpot's torque is largest at dead centre,
        # arm r_o), against the spring before dead centre and the loads
        drive = c * w0 * r_o * r_o + _max_spring_torque(d) + need
        if drive > CLUTCH_TORQUE * hold_required:
            raise DesignError(f"amplifier rollers must drive T with {drive:.4g} N mm through "
                              f"its dashpot, more than their {CLUTCH_TORQUE:g} x hold torque")
    return d


def rated_force(d: AmpDesign, ctx: SynthContext) -> float:
    """Largest level force on the output slider the toggle spring holds on either stop
    (static: no margin), net of the output slider's guide friction."""
    on = float(toggle_torque(d.theta_on, d)) / (d.r_o * math.cos(d.theta_on))
    off = -float(toggle_torque(d.theta_off, d)) / (d.r_o * math.cos(d.theta_off))
    return min(on, off) - ctx.friction


def _arc(c: Point, r: float, a0: float, a1: float, step: float = math.radians(2.0)):
    n = max(1, int(math.ceil(abs(a1 - a0) / step)))
    return [(c[0] + r * math.cos(a), c[1] + r * math.sin(a)) for a in np.linspace(a0, a1, n + 1)]


def _disc(c: Point, r: float, n: int = 16) -> list[Point]:
    return [(c[0] + r * math.cos(a), c[1] + r * math.sin(a))
            for a in np.linspace(0, 2 * math.pi, n, endpoint=False)]


#: The wedge clutch's torque limit as a multiple of the torque T must hold on a stop. It stands
#: for the roller drive's stall torque (a self-locking wedge has no friction limit of its own):
#: enough to bring T and its loads to the roller speed within a millisecond or so, finite so an
#: output blocked by its loads still stalls visibly.
CLUTCH_TORQUE = 10.0
CLUTCH_RATCHET = 1e-6  # rad: the ratchet's notch, a stand-in for a continuous one-way clutch
CLUTCH_MAX_BIAS = 1e-3  # rad/s: the ratchet corrects a lag by speed, not by a position jump


def pymunk_damping(c: float, mass: float, dt: float) -> float:
    """The coefficient to give a pymunk damped spring so that it removes ``c * v * dt`` of
    momentum per step, as the dashpot ``c`` does.

    pymunk (Chipmunk) damps a spring's relative speed by the factor exp(-c' dt / m) once per
    step, m being the mass at the spring's own ends, and then holds the damped speed against the
    other constraints for the rest of the step. Where something keeps the body moving at v (the
    roller drive, the loads) that costs m v (exp(c' dt / m) - 1) per step, which equals c v dt
    for c' = m ln(1 + c dt / m). With c' = c and the amplifier's c dt / m up to ~1.9 (an
    output slider of 46 g, 0.34 N s/mm, dt 0.25 ms) the model's dashpot was 3x the design's:
    T crept onto its stop at a third of the designed speed, and the roller drive forcing the
    output through it stretched the crank rod by 0.2 mm (the proof's limit is 0.1 mm)."""
    if c <= 0.0 or mass <= 0.0 or not math.isfinite(mass):
        return c
    return mass * math.log1p(c * dt / mass) / dt


@dataclass
class _Clutch:
    """One wedge's clutch: engaged while F has contacts with both R and C (arbiter counts)."""

    ratchet: pymunk.RatchetJoint
    drive: pymunk.Body
    toggle: pymunk.Body
    torque: float  # pymunk units
    touching: dict[str, int]

    def begin(self, arbiter, space, key: str) -> None:
        self.touching[key] += 1
        if all(self.touching.values()) and self.ratchet.max_force == 0.0:
            # engage from T's present angle: no lag carried over from the last engagement
            self.ratchet.angle = self.toggle.angle - self.drive.angle
            self.ratchet.max_force = self.torque

    def separate(self, arbiter, space, key: str) -> None:
        self.touching[key] -= 1
        if not all(self.touching.values()):
            self.ratchet.max_force = 0.0


def _add_wedge_clutches(scene, part: Part, t_id: str) -> list[_Clutch]:
    """Make each wedge lock as a real one does.

    F between R and C is a roller freewheel: with mu > tan(beta), tan(gamma) it cannot slip, so
    while F touches both, C's surface moves with R's (T at ``speed * r_r / rc``) unless T runs
    ahead, when the wedge opens. Rigid contacts with Coulomb friction have no finite solution
    while F slips on C in such a wedge (the frictions draw F in harder than the normals push it
    out, Painlevé's paradox); pymunk's solver then raises the contact forces only by about F's
    momentum per iteration, and F rolls into the wedge at half R's surface speed while T is slowly
    brought up. Measured (seed-204 flow table, AMPLIFIER a4): F went 0.5 mm past the wedge point
    in 3 ms, overlapping R by 0.26 mm, and reached its slot end; the slot end then carried the
    wedge's pull, the contact forces fell to ~0 and T fell back to its stop. A real wedge locks
    within its contacts' elastic deflection (~1 um at 40 N for aluminium rollers 3 mm wide).

    So each wedge gets a ratchet from T to a kinematic body turning at the roller-matched speed:
    T may not lag it, may run ahead. It is switched on only while F's contacts with R and C both
    exist (pymunk begin/separate events: no Python per step), so it drives exactly when the
    wedge is closed: not before F arrives, not over the relief, not after the input leaves."""
    d = part.data["design"]
    omega = d["speed"] * d["r_r"] / d["rc"]
    if omega <= 0.0:  # rollers at rest, or turning so that they draw F out: no wedge closes
        return []
    toggle = scene.bodies[t_id]
    rollers = [b.id for b in part.bodies if b.role == "friction roller"]
    powered = [b.id for b in part.bodies if b.role == "powered roller"]
    touches = {(j.a, j.b): (i, shapes) for i, (j, shapes) in enumerate(scene.touches)}
    out = []
    # (F1, R1) turn T counter-clockwise to on, (F2, R2) clockwise to off (synthesise's order)
    for f_id, r_id, sense in ((rollers[0], powered[0], 1.0), (rollers[1], powered[1], -1.0)):
        drive = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        drive.position = toggle.position
        drive.angular_velocity = sense * omega
        ratchet = pymunk.RatchetJoint(drive, toggle, 0.0, sense * CLUTCH_RATCHET)
        ratchet.max_force = 0.0
        ratchet.max_bias = CLUTCH_MAX_BIAS
        scene.space.add(drive, ratchet)
        clutch = _Clutch(ratchet, drive, toggle, CLUTCH_TORQUE * d["hold_required"] * N,
                         {"R": 0, "C": 0})
        for key, surface in (("R", r_id), ("C", t_id)):
            i, shapes = touches[(surface, f_id)]
            kind_surface, kind_roller = 2 * i + 2, 2 * i + 3  # unique per touch in the scene
            for sh in shapes[:-1]:
                sh.collision_type = kind_surface
            shapes[-1].collision_type = kind_roller
            scene.space.on_collision(kind_surface, kind_roller, begin=clutch.begin,
                                     separate=clutch.separate, data=key)
        out.append(clutch)
    return out


class Amplifier(Cell):
    name = "amplifier"
    type = "AMPLIFIER"
    min_inputs = 1
    max_inputs = 1
    description = ("powered friction rollers switch a bistable toggle: input force ~ slider "
                   "friction (Fig. 17)")
    # loads one amplifier drives in a mapped design: 3 OR inputs pass the measurement above,
    # but in the four-state table of tests/sequential an amplifier with an OR, a 3-input AND
    # and an AND on its output stalled before its toggle's dead point (dynamic proof: S·R
    # overlap downstream); 2 loads of any kind switched. A force-based rule would be better.
    fanout_max = 2
    switching_delay_s = MEASURED["switching_delay_s"]

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        # input slider, F1, F2, R1, R2, toggle T, output slider, toggle spring, 2 press springs
        return 10

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        d = design(ctx, demand, params)
        b = Builder(cid, ctx)
        S, w = ctx.stroke, ctx.bar
        rho = d.rc + d.r_f  # distance Q -> roller centre when it touches C
        sb, cb = math.sin(d.beta), math.cos(d.beta)
        sg, cg = math.sin(d.gamma), math.cos(d.gamma)
        x1_design = 1.2 * S  # F1 on the slider at the design pose (slot end)
        x_w1 = x1_design + S / 2 - d.engage  # where F1 meets its wedge (slider short by engage)
        Q = (x_w1 + rho * sb, -rho * cb)
        x_w2 = Q[0] + rho * sb
        x2_design = x_w2 + S / 2 - d.engage
        y = 0.0
        # ---- input slider with the two floating friction rollers ----------------------------
        sig = b.input_slider("A", 0.0, y, x2_design + d.slot + 0.5 * S)
        slider = sig.body
        f1, f2 = b.name("F1"), b.name("F2")
        for fid, xd in ((f1, x1_design), (f2, x2_design)):
            poly = _disc((xd, y), d.r_f)
            b.part.bodies.append(Body(fid, "link", [poly], ctx.mass([poly]), pivot=(xd, y),
                                      layer=2, role="friction roller"))
        # each roller floats in a hole of the slider: one-sided stops bound it along x (a slot
        # of length ``slot``) and across (± ``play``), a light spring presses it towards its
        # wedge (F1 right, F2 left). Free in the plane inside that hole, the two contacts of
        # the wedge alone decide its normal forces (a tight 1-DOF carrier would take them).
        for fid, xd, sense in ((f1, x1_design, -1), (f2, x2_design, 1)):
            limits = (((xd, y), (float(sense), 0.0)), ((xd + sense * d.slot, y),
                                                       (-float(sense), 0.0)),
                      ((xd, y - d.play), (0.0, 1.0)), ((xd, y + d.play), (0.0, -1.0)))
            for at, n in limits:
                b.part.joints.append(Joint(b._id("hole"), "contact", slider, fid, pa=at,
                                           pb=(xd, y), normal=n, driven=fid))
            m = b.part.body(fid).mass
            anchor = (xd + sense * 0.5 * S, y)
            rest = 0.5 * S + d.press / d.press_rate
            damping = 2 * ctx.damping_ratio * math.sqrt(d.press_rate * 1000.0 * m) / 1000.0
            # heaviest with F pushed to the far end of its slot (a compression spring)
            f_max = d.press + d.press_rate * d.slot
            b.part.springs.append(Spring(b._id("press"), slider, fid, anchor, (xd, y),
                                         d.press_rate, rest, damping, d.press, f_max,
                                         design_coil(d.press_rate, f_max, "compression")))
        # ---- powered rollers ---------------------------------------------------------------
        r1c = (x_w1 + (d.r_f + d.r_r) * sg, y + (d.r_f + d.r_r) * cg)
        r2c = (x_w2 - (d.r_f + d.r_r) * sg, y + (d.r_f + d.r_r) * cg)
        r1, r2 = b.name("R1"), b.name("R2")
        for rid, c, sp, layer in ((r1, r1c, d.speed, 3), (r2, r2c, -d.speed, 4)):
            poly = _disc(c, d.r_r)
            b.part.bodies.append(Body(rid, "rotor", [poly], ctx.mass([poly]), pivot=c,
                                      layer=layer, role="powered roller", speed=sp))
        # ---- toggle T: surface C with its relief, crank arm, stop lug -----------------------
        t_id = b.name("T")
        lead = math.pi / 2 + d.beta - d.theta_on + d.coast  # relief edges (T frame, design)
        trail = math.pi / 2 - d.beta - d.theta_off - d.coast
        margin = math.radians(8.0)
        lo = math.pi / 2 - d.beta - d.theta_on - margin
        hi = math.pi / 2 + d.beta - d.theta_off + margin
        profile = (_arc(Q, d.rc, lo, trail) + _arc(Q, d.rc - d.relief_depth, trail, lead)
                   + _arc(Q, d.rc, lead, hi))
        sector = [Q, *profile]
        pin = (Q[0], Q[1] - d.r_o)
        arm = rect(Q[0] - w / 2, pin[1] - w / 2, Q[0] + w / 2, Q[1])
        b.part.bodies.append(Body(t_id, "lever", [sector, arm], ctx.mass([sector, arm]),
                                  pivot=Q, layer=2, role="output toggle"))
        mu = d.mu
        for fid in (f1, f2):
            b.part.joints.append(Joint(b._id("touch"), "touch", t_id, fid, q=b.part.body(
                fid).pivot, length=d.r_f, profile=profile, friction=mu))
        for rid, c, fid in ((r1, r1c, f1), (r2, r2c, f2)):
            b.part.joints.append(Joint(b._id("touch"), "touch", rid, fid, pa=c, radius_a=d.r_r,
                                       q=b.part.body(fid).pivot, length=d.r_f, friction=mu))
        # stops Sp1 (on) and Sp2 (off) against the crank pin's lug
        for th, n in ((d.theta_on, (-1.0, 0.0)), (d.theta_off, (1.0, 0.0))):
            face = (Q[0] + d.r_o * math.sin(th), Q[1] - d.r_o * math.cos(th))
            b.part.joints.append(Joint(b._id("stop"), "contact", GROUND, t_id, pa=face,
                                       pb=pin, normal=n, driven=t_id))
        # over-centre toggle spring: point E above Q on T, anchor G below Q
        E, G = (Q[0], Q[1] + d.toggle_e), (Q[0], Q[1] - d.toggle_g)
        i_t = b.part.body(t_id).mass * (0.5 * d.rc) ** 2
        omega = math.sqrt(d.toggle_rate * 1000.0 * (d.toggle_e ** 2) / i_t)
        damping = d.toggle_damping * 2 * i_t * omega / d.toggle_e ** 2 / 1000.0
        f_max = d.toggle_rate * (d.toggle_e + d.toggle_g - d.toggle_rest)  # at dead centre
        b.part.springs.append(Spring(b._id("toggle"), GROUND, t_id, G, E, d.toggle_rate,
                                     d.toggle_rest, damping, d.hold_torque, f_max,
                                     design_coil(d.toggle_rate, f_max)))
        # ---- output: rod from the crank pin to the output slider ---------------------------
        x_pin = pin[0] + d.rod
        out = b.slider("out", x_pin - w / 2, x_pin + 0.8 * S, pin[1], "AMPLIFIER output")
        b.rod(t_id, out.body, pin, (x_pin, pin[1]))
        b.output(out, "Z")
        b.part.data.update({
            "design": {k: float(v) for k, v in d.__dict__.items()},
            "snap_work_N_mm": round(snap_work(d), 4),
            "dashpot_N_s_per_mm": round(d.dashpot, 6),
            "rated_output_force_N": round(rated_force(d, ctx), 4),
            "switching_delay_s": MEASURED["switching_delay_s"],
            "fanout_max": MEASURED["fanout_max"],
            "figures_source": "benchmarks/amplifier.py (dynamic pymunk, stroke 20 mm), "
                              "re-measured in tests/test_amplifier.py",
        })
        load = Demand(d.press + d.press_rate * d.engage, d.press + d.press_rate * d.engage)
        return b.finish({"A": load})

    @classmethod
    def checks(cls, cid: str, part: Part, ctx: SynthContext) -> list[Check]:
        """The landing rule on the design recorded in ``part.data``."""
        return check_landing(AmpDesign(**part.data["design"]), f"amplifier {cid}")

    @classmethod
    def rest_checks(cls, cid: str, part: Part, ctx: SynthContext, poses) -> list[Check]:
        """The input must come to rest within ``engage`` of its end in every rest state: F1
        meets its wedge when the input is ``engage`` short of on, F2 when it is that short of
        off, and an input resting farther short (still within the 5 % rest tolerance of the
        proofs) leaves the wedge open and the toggle where it was."""
        return check_rest(part, poses, f"amplifier {cid}")

    @classmethod
    def build_dynamics(cls, scene, part: Part) -> None:
        """pymunk multiplies the two shapes' friction coefficients: make the roller's 1 so a
        touch's contact has the friction its joint says; T's stops stiff; the wedges lock; the
        output slider's dashpot (a pymunk damped spring of zero stiffness along its axis)."""
        mine = {j.id for j in part.joints if j.kind == "touch"}
        for j, shapes in scene.touches:
            if j.id in mine:
                shapes[-1].friction = 1.0
        # T lands on its stop at speed, and its spring holds it there
        toggle = next(b.id for b in part.bodies if b.role == "output toggle")
        tb = scene.bodies[toggle]
        stiff_stops(scene.space, tb)
        _add_wedge_clutches(scene, part, toggle)
        c = part.data["design"].get("dashpot", 0.0)
        if c > 0.0:
            out = next(b.id for b in part.bodies if b.role == "AMPLIFIER output")
            (rx, ry), (ax, ay) = scene.ref[out], scene.axis[out]
            body = scene.bodies[out]
            scene.space.add(pymunk.DampedSpring(scene.space.static_body, body,
                                                (rx - FAR * ax, ry - FAR * ay), (0.0, 0.0), FAR,
                                                0.0, pymunk_damping(c * N, body.mass,
                                                                    scene.settings.dt)))
            # pymunk solves constraints in the order they were added (Gauss-Seidel), the later
            # ones best: T's stops and its rod to the output go after the clutch ratchets and
            # the dashpot (in their own order). Before them, 60 iterations left the rod
            # stretched by 0.21-0.38 mm while the rollers drove 130-190 N through it into a
            # 0.36-0.53 N s/mm dashpot (0.02 mm at 240 iterations, < 0.05 mm reordered)
            for cons in list(scene.space.constraints):
                if (isinstance(cons, (pymunk.PinJoint, pymunk.SlideJoint))
                        and tb in (cons.a, cons.b)):
                    scene.space.remove(cons)
                    scene.space.add(cons)

    @classmethod
    def kinematics(cls, part: Part, fixed: dict[str, np.ndarray], size: int, extra=None):
        """Quasi-static states: T on the stop the input selects (switching is dynamic)."""
        d = part.data["design"]
        S = d["stroke"]
        by_role = {}
        for body in part.bodies:
            by_role.setdefault(body.role, []).append(body)
        slider = next(bd for bd in part.bodies if bd.role == "input A")
        tog = by_role["output toggle"][0]
        out = by_role["AMPLIFIER output"][0]
        u = np.broadcast_to(np.asarray(fixed[slider.id], dtype=float), (size,)).copy()
        # T's angle on each stop from where the stop and T's lug are (the design's angles at
        # nominal: a stop cut off its drawing moves them)
        at = {}
        for j in part.joints:
            if j.kind == "contact" and j.a == GROUND and j.b == tog.id:
                key = "theta_on" if j.normal[0] < 0 else "theta_off"
                at[key] = Lever.angle_at_face(tog, j.pb, j.pa, j.normal, d[key])
        theta = np.where(u >= 0.0, at.get("theta_on", d["theta_on"]),
                         at.get("theta_off", d["theta_off"]))
        rod = next(j for j in part.joints if j.kind == "rod")
        sub = Part([tog, out], [rod])
        poses = solve(sub, {tog.id: theta}, size)
        poses.u[slider.id] = u
        poses.bad[slider.id] = ~np.isfinite(u)
        f1, f2 = by_role["friction roller"]
        reach = S / 2 - d["engage"]
        for f, du in ((f1, np.minimum(u, reach)), (f2, np.maximum(u, -reach))):
            poses.theta[f.id] = np.zeros(size)
            poses.xy[f.id] = (du, np.zeros(size))
            poses.bad[f.id] = np.zeros(size, dtype=bool)
        for r in by_role["powered roller"]:
            poses.theta[r.id] = np.zeros(size)
            poses.bad[r.id] = np.zeros(size, dtype=bool)
        return poses
