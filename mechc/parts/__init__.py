"""Part kinds: each body kind and joint kind as a class that knows its own closed-form
kinematics, drawing and pymunk construction.

The geometry data (``mechc.ir.mechanism``: ``Body``, ``Joint``) names a part's kind by a string
(the JSON format); ``BODY_KINDS`` and ``JOINT_KINDS`` below map that string to its class, and
the solver (``mechc.physics.closed_form``), the scene (``mechc.physics.scene``) and the drawing
(``mechc.backends.svg``) reach a part's maths only through them. ``mechc.parts.base`` says what a
kind provides (``BodyKind``, ``JointKind``: defaults that do nothing where a kind has nothing to
say).

Adding a part kind is one new file here (a ``BodyKind`` or ``JointKind`` subclass with its
``name``) and its line in the registry below; the JSON schema (mechc/schema) lists the kinds a
design file may hold.
"""

from __future__ import annotations

from mechc.parts.base import (
    BODY_KINDS,
    JOINT_KINDS,
    BodyKind,
    JointKind,
    Shape,
    body_kind,
    displacement,
    joint_kind,
    lever_arm,
    position,
)
from mechc.parts.contact import Contact
from mechc.parts.groove import Groove
from mechc.parts.lever import Lever
from mechc.parts.link import Link
from mechc.parts.pin import Pin
from mechc.parts.pushrod import PushRod
from mechc.parts.rod import Rod
from mechc.parts.rotor import Rotor
from mechc.parts.slider import Slider
from mechc.parts.touch import Touch

BODY_KINDS.update({k.name: k for k in (Slider, Lever, Link, Rotor, PushRod)})
JOINT_KINDS.update({k.name: k for k in (Groove, Rod, Contact, Pin, Touch)})

__all__ = ["BODY_KINDS", "JOINT_KINDS", "BodyKind", "JointKind", "Shape", "body_kind",
           "displacement", "joint_kind", "lever_arm", "position", "Contact", "Groove", "Lever",
           "Link", "Pin", "PushRod", "Rod", "Rotor", "Slider", "Touch"]
