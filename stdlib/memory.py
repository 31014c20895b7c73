"""MEMORY: the set/reset toggle lever held by an over-centre detent spring (001 Figs 9, 16h).

Logic: Q goes on when S is on, off when R is on, and holds while both are off; S and R on
together is a design error the sequential synthesis rules out.

Mechanism (all terminals translate, +x is on): a lever pivoted at O turns between two stops at
±alpha. S pushes its upper arm to the right, R its lower arm to the right (so R turns it back).
A compression spring between the lower end of the lever and a ground seat below it is shortest
with the lever upright, so it pushes the lever away from upright: two stable positions, each
held against its stop (the detent), and a dead point between them. An input carries the lever
past upright; the spring finishes the throw. A rod from the lever to the output slider Q turns
the throw into the stroke. Quasi-static kinematics need the previous state (``extra``).
"""

from __future__ import annotations

import math

import numpy as np

from mechc.cells.builder import Builder, rect
from mechc.cells.cell import Cell
from mechc.cells.springs import design_coil
from mechc.ir.mechanism import GROUND, Body, Demand, Joint, Spring
from mechc.parts.contact import stiff_stops
from mechc.parts.lever import Lever
from mechc.parts.rod import slider_from_rod
from mechc.physics.closed_form import KinematicsError, Poses

PUSH = 0.6  # contact travel of an input arm from upright to a stop, in strokes
CLEAR = 0.1  # gap (strokes) between an input face at off and the lever at its far stop


class Memory(Cell):
    name = "memory"
    type = "MEMORY"
    min_inputs = 2
    max_inputs = 2
    outputs = ("Q",)
    stateful = True
    description = "set/reset toggle lever held by an over-centre detent spring (Figs 9, 16h)"

    @classmethod
    def input_names(cls, n: int) -> list[str]:
        return ["S", "R"]

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 6  # toggle lever, detent spring, S and R sliders, output rod and slider

    @staticmethod
    def dims(stroke: float, arm: float) -> dict:
        """The lever's proportions: contact arms ``a``, throw ``alpha``, output radius, detent
        spring points; chosen so an input's stroke carries the lever CLEAR+... past upright."""
        S = stroke
        a = arm
        sin_a = PUSH * S / a
        alpha = math.asin(sin_a)
        rq = S / (2 * sin_a)  # the output pin's throw equals the stroke
        rd, g = a + 0.5 * S, a + 1.5 * S  # detent spring: lever end, ground seat
        return dict(a=a, alpha=alpha, rq=rq, rd=rd, g=g)

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w = ctx.stroke, ctx.bar
        d = cls.dims(S, ctx.arm)
        a, alpha, rq, rd, g = d["a"], d["alpha"], d["rq"], d["rd"], d["g"]
        xo = 1.5 * S + a * math.sin(alpha) + w
        O = (xo, -a)  # S row is y = 0 (upper contact), R row y = -2a (lower contact)
        face = xo - (PUSH + CLEAR) * S + S / 2  # an input's face at the design pose (mid)
        s_sig = b.input_slider("S", 0.0, 0.0, face)
        r_sig = b.input_slider("R", 0.0, -2 * a, face)
        lever = b.name("toggle")
        poly = rect(xo - w / 2, max(0.0, -a + rq) + w / 2, xo + w / 2, -a - rd - w / 2)
        b.part.bodies.append(Body(lever, "lever", [poly], ctx.mass([poly]), pivot=O, layer=2,
                                  role="toggle lever"))
        b.contact(s_sig.body, lever, (face, 0.0), (xo, 0.0), driven=lever)
        b.contact(r_sig.body, lever, (face, -2 * a), (xo, -2 * a), driven=lever)
        # stops on the upper arm at ±alpha (x of the contact point a·sin(alpha) from upright)
        top = (xo, 0.0)
        b.part.joints.append(_stop(b, lever, (xo + a * math.sin(alpha), 0.0), top, -1.0))
        b.part.joints.append(_stop(b, lever, (xo - a * math.sin(alpha), 0.0), top, 1.0))
        # output: a rod from the lever at radius rq to the Q slider on its own plane
        yq = -a + rq
        x_pin = xo + 2.0 * S
        q = b.slider("Q", x_pin, x_pin + 1.5 * S, yq, "memory output", layer=3)
        b.rod(lever, q.body, (xo, yq), (x_pin, yq))
        b.output(q, "Q", reach=q.x)
        h = rq * (1 - math.cos(alpha))  # the pin's rise at a stop shortens the rod's reach
        du = math.sqrt(4 * S * S - h * h) - 2 * S
        t = b.part.terminals["Q"]
        tip = (t.off[0] + S / 2, t.off[1])
        t.off, t.on = (tip[0] - S / 2 + du, tip[1]), (tip[0] + S / 2 + du, tip[1])
        t.at = tip
        # detent: a compression spring from the lever end to a ground seat, sized so its
        # holding torque at a stop beats the output load with the design margin
        load = max(demand.left, demand.right) + ctx.friction
        need = ctx.margin * max(load, ctx.min_preload) * rq * math.cos(alpha)
        k, rest = cls.detent_rate(need, d, S)
        D, G = (xo, -a - rd), (xo, -a - g)
        mass = ctx.mass([poly])
        omega = math.sqrt(k * 1000.0 * max(rd, 1.0) ** 2 / max(mass * a * a, 1e-9))
        f_max = k * (rest - (g - rd))  # most compressed with the lever upright
        b.part.springs.append(Spring(b._id("detent"), GROUND, lever, G, D, k, rest,
                                     2 * ctx.damping_ratio * mass * omega / 1000.0,
                                     preload=f_max, max_force=f_max,
                                     coil=design_coil(k, f_max, "compression")))
        tau_peak = cls.torque(np.linspace(0, alpha, 200), k, rest, d).max()
        b.part.data.update({
            "alpha_deg": round(math.degrees(alpha), 4), "hold_torque_Nmm":
                round(float(cls.torque(np.array([alpha]), k, rest, d)[0]), 4),
            "rated_load_N": round(float(cls.torque(np.array([alpha]), k, rest, d)[0])
                                  / (rq * math.cos(alpha)), 4),
            "initial": int(params.get("initial", 0)),
            "spring_required_N": {},
        })
        arm_force = tau_peak / (a * math.cos(alpha))
        push_s = ctx.margin * (arm_force + (demand.right + ctx.friction) * rq / a)
        push_r = ctx.margin * (arm_force + (demand.left + ctx.friction) * rq / a)
        return b.finish({"S": Demand(push_s, 0.0), "R": Demand(push_r, 0.0)})

    @classmethod
    def build_dynamics(cls, scene, part) -> None:
        _stiff_stops(scene, part)

    @staticmethod
    def torque(phi: np.ndarray, k: float, rest: float, d: dict) -> np.ndarray:
        """Detent torque (N mm) pushing the lever away from upright at throw ``phi``."""
        rd, g = d["rd"], d["g"]
        ell = np.sqrt(rd * rd + g * g - 2 * rd * g * np.cos(phi))
        return k * (rest - ell) * rd * g * np.sin(phi) / ell

    @classmethod
    def detent_rate(cls, need: float, d: dict, S: float) -> tuple[float, float]:
        """Spring rate (N/mm) and free length so the holding torque at a stop is ``need``."""
        rest = d["g"] - d["rd"] + 1.5 * S  # compressed by 1.5 S when upright
        unit = float(cls.torque(np.array([d["alpha"]]), 1.0, rest, d)[0])
        return need / unit, rest

    @classmethod
    def kinematics(cls, part, fixed, size, extra=None):
        """Lever and Q for the inputs' positions and the previous state (0/1 per state):
        an input that carries the lever past upright throws it to the other stop."""
        bodies = {bd.id: bd for bd in part.bodies}
        lever = next(bd for bd in part.bodies if bd.kind == "lever")
        s_body, r_body = part.terminals["S"].body, part.terminals["R"].body
        q_body = part.terminals["Q"].body
        d = part.data
        alpha = math.radians(d["alpha_deg"])
        state = np.broadcast_to(np.asarray(d.get("initial", 0) if extra is None else extra,
                                           dtype=float), (size,))
        S = abs(part.terminals["S"].on[0] - part.terminals["S"].off[0])
        us = np.broadcast_to(fixed.get(s_body, np.full(size, -S / 2)), (size,))
        ur = np.broadcast_to(fixed.get(r_body, np.full(size, -S / 2)), (size,))
        cs = next((j for j in part.joints if j.kind == "contact" and j.a == s_body), None)
        cr = next((j for j in part.joints if j.kind == "contact" and j.a == r_body), None)
        if cs is None or cr is None:
            raise KinematicsError(f"MEMORY lever {lever.id}: no contact between its "
                                  f"{'S' if cs is None else 'R'} slider and the lever")
        xo, a = lever.pivot[0], cs.pb[1] - lever.pivot[1]
        sig_s = (cs.pa[0] + us - xo) / a  # sin of the throw the S face imposes (clockwise)
        sig_r = -(cr.pa[0] + ur - xo) / a  # R: upper bound on sin(throw)
        # the throw at each stop, from where the stops and the lever's point that meets them
        # are (alpha at nominal: a stop cut off its drawing throws the lever further or less)
        stops = [j for j in part.joints if j.kind == "contact" and j.a == GROUND
                 and j.b == lever.id]
        throw = {j.normal[0] < 0: -Lever.angle_at_face(lever, j.pb, j.pa, j.normal,
                                                       -alpha if j.normal[0] < 0 else alpha)
                 for j in stops}
        sin_hi = np.sin(throw.get(True, alpha))  # clockwise, on
        sin_lo = np.sin(throw.get(False, -alpha))  # counter-clockwise, off
        on = state > 0.5
        sin_phi = np.where(on, sin_hi, sin_lo)
        set_ = sig_s > 0.0
        reset = sig_r < 0.0
        sin_phi = np.where(~on & ~set_, np.maximum(sin_phi, sig_s), sin_phi)
        sin_phi = np.where(on & ~reset, np.minimum(sin_phi, sig_r), sin_phi)
        new = np.where(set_, 1.0, np.where(reset, 0.0, state))
        sin_phi = np.where(set_ & ~reset, sin_hi, np.where(reset & ~set_, sin_lo, sin_phi))
        # the faces bind the lever when S asks for more throw than R allows (both pressing,
        # from either side); beyond a stop the input itself is blocked
        jam = (sig_s > sig_r + 1e-9) | (sig_s > sin_hi + 1e-9) | (sig_r < sin_lo - 1e-9)
        phi = np.arcsin(np.clip(sin_phi, -1, 1))
        poses = Poses()
        poses.u[s_body], poses.u[r_body] = np.array(us, float), np.array(ur, float)
        poses.theta[lever.id] = -phi  # counter-clockwise positive
        for bid in (s_body, r_body, lever.id):
            poses.bad[bid] = np.array(jam)
        rod = next(j for j in part.joints if j.kind == "rod")
        slider_from_rod(rod, bodies[q_body], lever, poses, size)
        poses.mark(q_body, jam)
        poses.state[lever.id.rsplit(".", 1)[0]] = new
        return poses


def _stiff_stops(scene, part) -> None:
    """The lever lands on a stop at speed when the detent throws it, and the detent holds it
    there (:func:`mechc.parts.contact.stiff_stops`)."""
    lever = next(bd.id for bd in part.bodies if bd.kind == "lever")
    stiff_stops(scene.space, scene.bodies[lever])


def _stop(b: Builder, lever: str, at, point, nx: float) -> Joint:
    """A ground face at ``at`` the lever's ``point`` may not pass (normal fixed in the world)."""
    return Joint(b._id("stop"), "contact", GROUND, lever, pa=at, pb=point, normal=(nx, 0.0),
                 driven=lever)
