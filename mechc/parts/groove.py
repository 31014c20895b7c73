"""``groove``: a straight slot on body a from ``p0`` to ``p1`` with a pin on body b at ``q``.

Closed forms: a lever's pin in a slot on a known body gives the lever angle from
``a cos θ + b sin θ = c`` (branch fixed at the design pose); a slot on a slider follows a known
pin linearly. Drawn as a slot with its pin; pymunk's GrooveJoint."""

from __future__ import annotations

import numpy as np
import pymunk

from mechc.ir.mechanism import GROUND, Body, Joint
from mechc.parts.base import (
    JointKind,
    Placer,
    SceneBuilder,
    Shape,
    arccos_tan,
    cross,
    lever_arm,
    line_cotan,
    position,
    unit,
)
from mechc.parts.poses import KinematicsError, Poses


def lever_from_slot(j: Joint, lever: Body, slot_body: Body | None, poses: Poses,
                    size: int) -> None:
    """Pin on the lever (unknown angle) in a slot on a known body."""
    P = lever.pivot
    d = unit((j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
    r = (j.q[0] - P[0], j.q[1] - P[1])
    a = cross(r, d)
    b = -(r[0] * d[0] + r[1] * d[1])
    rho = float(np.hypot(a, b))
    phi = float(np.arctan2(b, a))
    x0, y0 = position(slot_body, poses, j.p0)
    c = (x0 - P[0]) * d[1] - (y0 - P[1]) * d[0]
    if slot_body is not None and slot_body.kind == "lever":
        raise KinematicsError(f"{j.id}: slot on a lever driving a lever is not supported")
    ratio = np.broadcast_to(c / rho, (size,))
    ok = np.abs(ratio) <= 1.0
    s = -1.0 if phi > 0 else 1.0
    theta = phi + s * np.arccos(np.clip(ratio, -1.0, 1.0))
    theta = (theta + np.pi) % (2 * np.pi) - np.pi
    poses.theta[lever.id] = np.where(ok, theta, np.nan)
    poses.mark(lever.id, ~ok | poses.bad.get(slot_body.id if slot_body else GROUND,
                                              np.zeros(size, bool)))
    poses.singular_margin.set_tan(j.id, arccos_tan(np.abs(ratio)))
    # transmission: 90° minus the angle between the slot's normal force and the pin's motion
    rx, ry = lever_arm(lever, poses, j.q)
    nx, ny = -d[1], d[0]  # force line: normal to the slot
    poses.transmission.set_tan(j.id, line_cotan(nx, ny, -ry, rx))


def slot_from_pin(j: Joint, slider: Body, pin_body: Body | None, poses: Poses,
                  size: int) -> None:
    """Slot on the slider (unknown), pin on a known body: linear."""
    d = unit((j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
    qx, qy = position(pin_body, poses, j.q)
    den = cross(slider.axis, d)
    if abs(den) < 1e-12:
        raise KinematicsError(f"{j.id}: slot parallel to its slider's travel")
    u = ((qx - j.p0[0]) * d[1] - (qy - j.p0[1]) * d[0]) / den
    poses.u[slider.id] = np.broadcast_to(u, (size,)).copy()
    poses.mark(slider.id, np.broadcast_to(poses.bad.get(pin_body.id, np.zeros(size, bool)),
                                          (size,)))
    slider_mu = line_cotan(-d[1], d[0], slider.axis[0], slider.axis[1])
    mu = np.broadcast_to(np.asarray(slider_mu, dtype=float), (size,))
    arm = lever_arm(pin_body, poses, j.q)
    if arm is not None:  # the lever's side of the pair
        rx, ry = arm
        mu = np.minimum(mu, line_cotan(-d[1], d[0], -ry, rx))
        poses.singular_margin.set_tan(j.id, np.broadcast_to(mu, (size,)).copy())
    poses.transmission.set_tan(j.id, np.broadcast_to(mu, (size,)).copy())


class Groove(JointKind):
    name = "groove"
    solvers = {("lever", "b"): lever_from_slot, ("slider", "a"): slot_from_pin}

    @classmethod
    def violation(cls, j: Joint, a: Body | None, b: Body | None, poses: Poses, size: int,
                  tol: float) -> np.ndarray:
        """The pin off its slot's line or past either end."""
        d = unit((j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
        x0, y0 = position(a, poses, j.p0)
        qx, qy = position(b, poses, j.q)
        off = (qx - x0) * d[1] - (qy - y0) * d[0]
        along = (qx - x0) * d[0] + (qy - y0) * d[1]
        length = float(np.hypot(j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
        return np.broadcast_to((np.abs(off) > 1e-6) | (along < -1e-6)
                               | (along > length + 1e-6), (size,))

    @classmethod
    def shapes(cls, j: Joint, at: Placer) -> list[Shape]:
        """The slot on its body's plane, and the pin."""
        return [Shape("slot", [at.pt(j.a, j.p0), at.pt(j.a, j.p1)], ref=j.id,
                      layer=at.layer(j.a)),
                Shape("pin", [at.pt(j.b, j.q)], ref=j.id)]

    @classmethod
    def add_to_scene(cls, scene: SceneBuilder, j: Joint) -> None:
        c = pymunk.GrooveJoint(scene.body_of(j.a), scene.body_of(j.b), scene.anchor(j.a, j.p0),
                               scene.anchor(j.a, j.p1), scene.anchor(j.b, j.q))
        scene.measure(j.id, "groove", scene.order_of(j.a), scene.anchor(j.a, j.p0),
                      scene.order_of(j.b), scene.anchor(j.b, j.q), (scene.anchor(j.a, j.p1),))
        scene.space.add(c)
