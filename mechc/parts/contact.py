"""``contact``: one-sided; the faces at ``pa`` (on a) and ``pb`` (on b) keep
``(pb - pa) . normal >= 0``. A stop is a contact with the ground. ``driven`` names the body the
contact positions (the other side's spring budget is the stronger one).

Closed form: a bound on a slider's travel (the solver takes the nearest bound its spring
pushes it to). Drawn as a ground mark when it is a stop; in pymunk a SlideJoint between the
face on b and a point ``FAR`` behind the face on a (a distance of at least ``FAR`` means the
faces have not passed each other)."""

from __future__ import annotations

import numpy as np
import pymunk

from mechc.ir.mechanism import GROUND, Body, Joint, Point
from mechc.parts.base import JointKind, Placer, SceneBuilder, Shape, direction, position
from mechc.parts.poses import Poses

FAR = 1000.0  # mm: how far behind a contact face its slide-joint anchor sits


class Contact(JointKind):
    name = "contact"
    one_sided = True

    @classmethod
    def slider_limit(cls, j: Joint, slider: Body, other: Body | None, poses: Poses):
        """The contact as ``u·k >= rhs`` on the slider's travel ``u``: (k, rhs), or None when
        the face is parallel to the travel (it bounds nothing)."""
        n = j.normal
        axn = slider.axis[0] * n[0] + slider.axis[1] * n[1]
        if abs(axn) < 1e-9:
            return None
        if j.b == slider.id:  # (pb + u·axis - pa') . n >= 0
            ox, oy = position(other, poses, j.pa)
            rhs = (ox - j.pb[0]) * n[0] + (oy - j.pb[1]) * n[1]  # u·axn >= rhs
        else:  # (pb' - pa - u·axis) . n >= 0  ->  u·axn <= (pb' - pa).n
            ox, oy = position(other, poses, j.pb)
            rhs = -((ox - j.pa[0]) * n[0] + (oy - j.pa[1]) * n[1])  # -u·axn >= rhs
            axn = -axn
        return axn, rhs

    @classmethod
    def violation(cls, j: Joint, a: Body | None, b: Body | None, poses: Poses, size: int,
                  tol: float) -> np.ndarray:
        """The faces passed through each other."""
        ax_, ay_ = position(a, poses, j.pa)
        bx_, by_ = position(b, poses, j.pb)
        gap = (bx_ - ax_) * j.normal[0] + (by_ - ay_) * j.normal[1]
        return np.broadcast_to(gap < -tol * np.maximum(1.0, np.abs(j.pa[0])), (size,))

    @classmethod
    def ground_point(cls, j: Joint) -> Point | None:
        if GROUND not in (j.a, j.b):
            return None
        return j.pa if j.a == GROUND else j.pb

    @classmethod
    def shapes(cls, j: Joint, at: Placer) -> list[Shape]:
        """A stop: a ground mark hatched on the ground's side of the face."""
        gp = cls.ground_point(j)
        if gp is None:
            return []
        n = direction(j.normal)
        into = (-n[0], -n[1]) if j.a == GROUND else n  # the ground lies this way
        return [Shape("stop", [gp], ground=into)]

    @classmethod
    def add_to_scene(cls, scene: SceneBuilder, j: Joint) -> None:
        far = (j.pa[0] - FAR * j.normal[0], j.pa[1] - FAR * j.normal[1])
        c = pymunk.SlideJoint(scene.body_of(j.a), scene.body_of(j.b), scene.anchor(j.a, far),
                              scene.anchor(j.b, j.pb), FAR, FAR + 100 * scene.mech.ctx.stroke)
        scene.measure(j.id, "contact", scene.order_of(j.a), scene.anchor(j.a, far),
                      scene.order_of(j.b), scene.anchor(j.b, j.pb), (FAR,))
        scene.space.add(c)


#: pymunk: the fraction of a joint's error left after 1 s, for a body that lands on its stops at
#: speed (an amplifier's toggle, a memory's lever): corrected within milliseconds, not pymunk's
#: default 1/6 s (a slow creep back off the stop reads as an output that has not settled).
STOP_ERROR_BIAS = 0.1 ** 60
#: mm: how far in a stop held by :func:`stiff_stops` may leave its body at rest.
SLOP = 1e-3


def stiff_stops(space: pymunk.Space, body: pymunk.Body) -> None:
    """Correct every joint error of ``body`` fast (``STOP_ERROR_BIAS``), and hold it on its
    stops without chatter.

    A slide joint acts only past its limit, and a fast correction takes an overrun towards none
    at all: a body a spring presses onto the stop ends, by rounding, a hair outside it, and for
    that step the joint lets go and the spring's whole force moves the body. Where the spring
    is strong against the body's inertia, that is a kick (the amplifier's toggle, below 0.1 mm
    at its output, every 70-380 ms: the 16-bit adder never came to rest). As Chipmunk's own
    contacts do with their collision slop, each stop (a contact's slide joint) holds without
    correcting its overrun, and a second joint ``SLOP`` further in corrects only what lies
    beyond: the body rests up to ``SLOP`` in, and nothing draws it to the edge."""
    for c in list(space.constraints):
        if body not in (c.a, c.b):
            continue
        c.error_bias = STOP_ERROR_BIAS
        if isinstance(c, pymunk.SlideJoint):  # a stop: only contacts are slide joints
            corrector = pymunk.SlideJoint(c.a, c.b, c.anchor_a, c.anchor_b, c.min - SLOP, c.max)
            corrector.error_bias = STOP_ERROR_BIAS
            corrector.max_bias = c.max_bias
            c.error_bias = 1.0  # pymunk: the whole error left after a second: not corrected
            space.add(corrector)
