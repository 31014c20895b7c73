"""``link``: a body free in the plane, placed by the pins that join it to others; its
``pivot`` is only a reference point, which ``Poses.xy`` carries (with ``theta`` about it)."""

from __future__ import annotations

import numpy as np
import pymunk

from mechc.ir.mechanism import Body, Joint, Point
from mechc.parts.base import (
    JOINT_KINDS,
    BodyKind,
    Coords,
    SceneBuilder,
    body_or_ground,
    position,
    turned,
)
from mechc.parts.poses import Poses


class Link(BodyKind):
    name = "link"
    input_terminal = False
    dyad = True

    @classmethod
    def displacement(cls, body: Body, poses: Poses, p) -> Coords:
        dx, dy = turned(body, poses, p)
        tx, ty = poses.xy[body.id]
        return dx + tx, dy + ty

    @classmethod
    def dyad_anchor(cls, body: Body, joints: list[Joint], bodies: dict[str, Body],
                    poses: Poses):
        """A pin to a body already solved: the link turns about that pin."""
        for j in joints:
            if not JOINT_KINDS[j.kind].revolute:
                continue
            other = j.b if j.a == body.id else j.a
            if poses.known(other):
                x, y = position(body_or_ground(bodies, other), poses, j.pa)
                return j.pa, x, y, poses.bad.get(other), j
        return None

    @classmethod
    def set_turn(cls, body: Body, poses: Poses, th, ok, centre: Point, cx, cy,
                 size: int) -> None:
        """The turn, and the reference point carried with it (the centre moves to cx, cy)."""
        super().set_turn(body, poses, th, ok, centre, cx, cy, size)
        cs, sn = np.cos(th), np.sin(th)
        rx, ry = body.pivot[0] - centre[0], body.pivot[1] - centre[1]
        tx = cx + rx * cs - ry * sn - body.pivot[0]
        ty = cy + rx * sn + ry * cs - body.pivot[1]
        poses.xy[body.id] = (np.where(ok, tx, np.nan) * np.ones(size),
                             np.where(ok, ty, np.nan) * np.ones(size))

    @classmethod
    def place(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point,
              poses: Poses) -> None:
        tx, ty = poses.xy[body.id]
        pm.position = (ref[0] + float(np.ravel(tx)[0]), ref[1] + float(np.ravel(ty)[0]))
        pm.angle = float(poses.theta[body.id][0])

    @classmethod
    def follow(cls, scene: SceneBuilder, bid: str, pm: pymunk.Body, ref: Poses, i0: int,
               w: float, dt: float) -> None:
        super().follow(scene, bid, pm, ref, i0, w, dt)
        rx, ry = scene.ref[bid]
        gx = rx + ref.xy[bid][0][i0] * (1 - w) + ref.xy[bid][0][i0 + 1] * w
        gy = ry + ref.xy[bid][1][i0] * (1 - w) + ref.xy[bid][1][i0 + 1] * w
        pm.velocity = ((gx - pm.position[0]) / dt, (gy - pm.position[1]) / dt)

    @classmethod
    def scene_pose(cls, scene: SceneBuilder, bid: str, i: int, pos, ang) -> Poses:
        p = super().scene_pose(scene, bid, i, pos, ang)
        rx, ry = scene.ref[bid]
        p.xy[bid] = (np.array([pos[i, 0] - rx]), np.array([pos[i, 1] - ry]))
        return p
