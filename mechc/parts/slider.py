"""``slider``: a body that travels along its ``axis`` (coordinate ``u``, mm from the design
pose); in pymunk it cannot turn, runs in a ground guide and feels Coulomb guide friction."""

from __future__ import annotations

import math

import numpy as np
import pymunk

from mechc.ir.mechanism import Body, Point
from mechc.parts.base import BodyKind, Coords, N, SceneBuilder
from mechc.parts.poses import Poses


class Slider(BodyKind):
    name = "slider"
    coordinate = "u"
    translates = True
    held_by_contacts = True

    @classmethod
    def displacement(cls, body: Body, poses: Poses, p) -> Coords:
        u = poses.u[body.id]
        return u * body.axis[0], u * body.axis[1]

    @classmethod
    def sweep(cls, body: Body, stroke: float) -> Point:
        if body.axis is None:
            return (0.0, 0.0)
        return (abs(body.axis[0]) * stroke / 2, abs(body.axis[1]) * stroke / 2)

    @classmethod
    def scene_ref(cls, body: Body) -> Point:
        """The outline's vertex centroid (a slider has no pivot)."""
        pts = [p for poly in body.outline for p in poly]
        return (sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts))

    @classmethod
    def pymunk_body(cls, body: Body, ref: Point) -> pymunk.Body:
        return pymunk.Body(body.mass, math.inf)

    @classmethod
    def place(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point,
              poses: Poses) -> None:
        u = float(poses.u[body.id][0])
        scene.axis[body.id] = body.axis
        pm.position = (ref[0] + u * body.axis[0], ref[1] + u * body.axis[1])

    @classmethod
    def hold(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point) -> None:
        """A guide two strokes either way along the axis, and guide friction: a ground pivot
        with no position correction whose force is capped."""
        L = 2.0 * scene.mech.ctx.stroke
        a0 = (ref[0] - L * body.axis[0], ref[1] - L * body.axis[1])
        a1 = (ref[0] + L * body.axis[0], ref[1] + L * body.axis[1])
        scene.space.add(pymunk.GrooveJoint(scene.space.static_body, pm, a0, a1, (0, 0)))
        scene.measure(f"{body.id}.guide", "groove", -1, a0, scene.order_of(body.id), (0, 0),
                      (a1,))
        fr = pymunk.PivotJoint(scene.space.static_body, pm, (0, 0), (0, 0))
        fr.max_bias = 0
        fr.max_force = scene.mech.ctx.friction * N
        scene.space.add(fr)

    @classmethod
    def follow(cls, scene: SceneBuilder, bid: str, pm: pymunk.Body, ref: Poses, i0: int,
               w: float, dt: float) -> None:
        u = ref.u[bid][i0] * (1 - w) + ref.u[bid][i0 + 1] * w
        rx, ry = scene.ref[bid]
        ax, ay = scene.axis[bid]
        goal = (rx + u * ax, ry + u * ay)
        pm.velocity = ((goal[0] - pm.position[0]) / dt, (goal[1] - pm.position[1]) / dt)

    @classmethod
    def scene_pose(cls, scene: SceneBuilder, bid: str, i: int, pos, ang) -> Poses:
        return Poses(u={bid: np.array([scene.body_u(bid, pos)])})
