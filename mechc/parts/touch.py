"""``touch``: a shape contact with friction. On a, the polyline ``profile`` (a cam, a face) or a
circle of ``radius_a`` about ``pa``; on b, a roller of radius ``length`` about ``q``.

Used where the contact point travels (cams, friction rollers): the cell that owns it supplies
the kinematics, so the closed form neither solves nor checks it. In pymunk: shapes that collide
only with each other; their overrun is measured like a contact's (``Scene.touch_overrun``)."""

from __future__ import annotations

import numpy as np
import pymunk

from mechc.ir.mechanism import Joint
from mechc.parts.base import JointKind, SceneBuilder


class Touch(JointKind):
    name = "touch"

    @classmethod
    def add_to_scene(cls, scene: SceneBuilder, j: Joint) -> None:
        bit = 1 << (len(scene.touches) % 31)
        filt = pymunk.ShapeFilter(group=0, categories=bit, mask=bit)
        a, b = scene.body_of(j.a), scene.body_of(j.b)
        mu = 0.0 if j.friction is None else j.friction
        shapes: list[pymunk.Shape] = []
        if j.profile:
            pts = [scene.anchor(j.a, p) for p in j.profile]
            shapes += [pymunk.Segment(a, p, q, 0.0) for p, q in zip(pts, pts[1:])]
        else:
            shapes.append(pymunk.Circle(a, j.radius_a, scene.anchor(j.a, j.pa)))
        roller = pymunk.Circle(b, j.length, scene.anchor(j.b, j.q))
        shapes.append(roller)
        for sh in shapes:
            sh.filter = filt
            sh.friction = mu  # pymunk multiplies the two shapes' values: the roller's is 1
            sh.elasticity = 0.0
        roller.friction = 1.0
        scene.space.add(*shapes)
        scene.touches.append((j, shapes))
        if j.profile:  # the segments in the profile body's frame, for the overrun measure
            pa = np.array([[sh.a.x, sh.a.y] for sh in shapes[:-1]])
            pb = np.array([[sh.b.x, sh.b.y] for sh in shapes[:-1]])
            scene.profiles.append((pa, pb - pa))
        else:
            scene.profiles.append(None)
