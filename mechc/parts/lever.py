"""``lever``: a body turning about a fixed ground ``pivot`` (coordinate ``theta``, rad ccw
from the design pose); drawn with a ground bearing, held in pymunk by a ground pivot joint."""

from __future__ import annotations

import numpy as np
import pymunk

from mechc.ir.mechanism import Body, Joint, Point
from mechc.parts.base import BodyKind, Coords, SceneBuilder, Shape, placed_key, rotate
from mechc.parts.poses import Poses


class Lever(BodyKind):
    name = "lever"
    dyad = True

    @classmethod
    def position(cls, body: Body, poses: Poses, p) -> Coords:
        """The point where this solve's closed form placed it (no trig), else
        pivot + R(θ)·arm, skipping the terms of an arm component that is exactly 0."""
        turn = poses.theta.entry(body.id)
        hit = poses.placed.get(placed_key(body, p))
        if hit is not None and hit[2] is turn:
            return hit[0], hit[1]
        c, s = turn.cos_sin() if turn is not None else poses.theta.cos_sin(body.id)
        return rotate(p[0] - body.pivot[0], p[1] - body.pivot[1], c, s, body.pivot)

    @classmethod
    def arm(cls, body: Body, poses: Poses, p) -> Coords:
        r = (p[0] - body.pivot[0], p[1] - body.pivot[1])
        c, s = poses.theta.cos_sin(body.id)
        return r[0] * c - r[1] * s, r[0] * s + r[1] * c

    @classmethod
    def angle_at_face(cls, body: Body, p, face, normal, guess: float) -> np.ndarray:
        """The angle (rad ccw from the design pose) at which the lever's point ``p`` lies on
        the plane through ``face`` with ``normal``: where a stop on the frame catches it; of
        the two such angles, the one nearer ``guess``. The points may be arrays (a tolerance
        run's samples), so a stop or a hole cut off its drawing moves the angle it sets."""
        vx, vy = p[0] - body.pivot[0], p[1] - body.pivot[1]
        nx, ny = normal
        a, b = nx * vx + ny * vy, ny * vx - nx * vy  # n . R(theta) v = a cos + b sin
        rhs = nx * (face[0] - body.pivot[0]) + ny * (face[1] - body.pivot[1])
        mid = np.arctan2(b, a)
        half = np.arccos(np.clip(rhs / np.hypot(a, b), -1.0, 1.0))
        lo, hi = mid - half, mid + half
        near = lambda t: np.abs(np.angle(np.exp(1j * (t - guess))))  # noqa: E731
        return np.where(near(lo) <= near(hi), lo, hi)

    @classmethod
    def dyad_anchor(cls, body: Body, joints: list[Joint], bodies: dict[str, Body],
                    poses: Poses):
        return body.pivot, np.asarray(body.pivot[0]), np.asarray(body.pivot[1]), None, None

    @classmethod
    def symbols(cls, body: Body) -> list[Shape]:
        if body.pivot is None:
            return []
        return [Shape("pivot", [body.pivot], ref=body.id, ground=(0.0, -1.0))]

    @classmethod
    def reach(cls, body: Body, stroke: float) -> list[Point]:
        """The square its largest radius sweeps."""
        if body.pivot is None:
            return super().reach(body, stroke)
        pts = np.array([p for poly in body.outline for p in poly], dtype=float)
        r = float(np.hypot(pts[:, 0] - body.pivot[0], pts[:, 1] - body.pivot[1]).max())
        return [(body.pivot[0] - r, body.pivot[1] - r), (body.pivot[0] + r, body.pivot[1] + r)]

    @classmethod
    def hold(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point) -> None:
        scene.space.add(pymunk.PivotJoint(scene.space.static_body, pm, ref, (0, 0)))
        scene.measure(f"{body.id}.pivot", "pivot", -1, ref, scene.order_of(body.id), (0, 0))
