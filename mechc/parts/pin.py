"""``pin``: bodies a and b turn about one shared point ``pa`` (a revolute pair).

The closed form solves pins in pairs (a dyad, ``mechc.physics.closed_form``); the closure
check asks both bodies' copies of the point to coincide. In pymunk a PivotJoint."""

from __future__ import annotations

import numpy as np
import pymunk

from mechc.ir.mechanism import Body, Joint
from mechc.parts.base import JointKind, SceneBuilder, position
from mechc.parts.poses import Poses


class Pin(JointKind):
    name = "pin"
    revolute = True

    @classmethod
    def violation(cls, j: Joint, a: Body | None, b: Body | None, poses: Poses, size: int,
                  tol: float) -> np.ndarray:
        ax_, ay_ = position(a, poses, j.pa)
        bx_, by_ = position(b, poses, j.pa)
        return np.broadcast_to(np.hypot(bx_ - ax_, by_ - ay_) > 1e-6, (size,))

    @classmethod
    def add_to_scene(cls, scene: SceneBuilder, j: Joint) -> None:
        c = pymunk.PivotJoint(scene.body_of(j.a), scene.body_of(j.b), scene.anchor(j.a, j.pa),
                              scene.anchor(j.b, j.pa))
        scene.measure(j.id, "pivot", scene.order_of(j.a), scene.anchor(j.a, j.pa),
                      scene.order_of(j.b), scene.anchor(j.b, j.pa))
        scene.space.add(c)
