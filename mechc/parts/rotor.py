"""``rotor``: a powered roller turning about its ``pivot`` at ``speed`` (rad/s) whatever loads
it; the cell that owns it supplies its angle, and pymunk moves it as a kinematic body."""

from __future__ import annotations

import pymunk

from mechc.ir.mechanism import Body, Point
from mechc.parts.base import BodyKind, SceneBuilder
from mechc.parts.poses import Poses


class Rotor(BodyKind):
    name = "rotor"

    @classmethod
    def pymunk_body(cls, body: Body, ref: Point) -> pymunk.Body:
        return pymunk.Body(body_type=pymunk.Body.KINEMATIC)

    @classmethod
    def place(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point,
              poses: Poses) -> None:
        pm.position = ref
        pm.angular_velocity = float(body.speed or 0.0)
