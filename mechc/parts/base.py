"""What every part kind provides, and the lookups that reach a body's or joint's kind.

A kind is a class used through its class methods (never instantiated): the per-kind maths of
the closed form, the symbols the drawing adds, and the pymunk bodies and constraints of the
scene. The solver (``mechc.physics.closed_form``), the scene (``mechc.physics.scene``) and the
drawing (``mechc.backends.svg``) keep their algorithms and ask the kind for these pieces.
``BODY_KINDS`` and ``JOINT_KINDS`` are filled by ``mechc/parts/__init__.py``, which importing
this module always runs first.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

import numpy as np
import pymunk

from mechc.ir.mechanism import GROUND, Body, Joint, Point
from mechc.parts.poses import Poses

N = 1000.0  # newtons -> pymunk force units (kg mm / s^2)

BODY_KINDS: dict[str, type[BodyKind]] = {}
JOINT_KINDS: dict[str, type[JointKind]] = {}

Coords = tuple[np.ndarray, np.ndarray]


def body_kind(kind: str) -> type[BodyKind]:
    try:
        return BODY_KINDS[kind]
    except KeyError:
        raise ValueError(f"unknown body kind {kind}") from None


def joint_kind(kind: str) -> type[JointKind]:
    try:
        return JOINT_KINDS[kind]
    except KeyError:
        raise ValueError(f"unknown joint kind {kind}") from None


# ---- small plane maths shared by the kinds and the solver -----------------------------------

def body_or_ground(bodies: dict[str, Body], bid: str) -> Body | None:
    return None if bid == GROUND else bodies[bid]


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def unit(v):
    n = np.hypot(v[0], v[1])  # no float(): a tolerance run gives dimensions as arrays
    return (v[0] / n, v[1] / n)


def is_number(v) -> bool:
    """``v`` is one number (not an array of them): Python and numpy floats without a numpy
    call, as the closed forms ask this of every dimension on every solve."""
    return isinstance(v, (float, int)) or np.ndim(v) == 0


def sized(x, size: int):
    """``x`` over ``size`` states: itself when it already has that shape (no numpy call),
    else a read-only broadcast view."""
    return x if getattr(x, "shape", None) == (size,) else np.broadcast_to(x, (size,))


def side_of(v):
    """The sign of ``v`` with 0 read as +1 (a branch chosen at the design pose): a float for a
    number, an array where the dimensions are arrays (``mechc.tolerance`` perturbs them per
    sample)."""
    if isinstance(v, (float, int)):
        return -1.0 if v < 0 else (1.0 if v >= 0 else math.nan)
    if np.ndim(v) == 0:
        return float(np.sign(v)) or 1.0
    return np.where(np.asarray(v) < 0, -1.0, 1.0)


def direction(v) -> Point:
    """``v`` as a unit vector, or +x when it has no length (drawing: never fails)."""
    n = float(np.hypot(v[0], v[1]))
    return (v[0] / n, v[1] / n) if n > 0 else (1.0, 0.0)


def angle_between_lines(ax, ay, bx, by):
    """Acute angle (deg) between direction fields a and b."""
    dot = np.abs(ax * bx + ay * by) / (np.hypot(ax, ay) * np.hypot(bx, by))
    return np.degrees(np.arccos(np.clip(dot, 0.0, 1.0)))


# The design checks' angles over all states in the cheap domain: the tangent of the angle
# (``Poses.transmission`` and ``singular_margin`` store it with ``Angles.set_tan``), from
# cross and dot products or a square root, or a squared distance the closed form already has
# (``Angles.set_sides``), no trig per state; the check converts only the extreme to degrees
# (``Angles.min_deg``).

def line_tan(ax, ay, bx, by):
    """tan of the acute angle between direction fields a and b: |a×b| / |a·b| (inf: square;
    NaN where a or b has no length)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(ax * by - ay * bx) / np.abs(ax * bx + ay * by)


def line_cotan(ax, ay, bx, by):
    """tan of (90° - the acute angle between a and b): |a·b| / |a×b|."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(ax * bx + ay * by) / np.abs(ax * by - ay * bx)


def arccos_tan(c):
    """tan of arccos(c) for c in 0..1 (clipped): sqrt(1 - c²) / c."""
    c = np.clip(c, 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.sqrt((1.0 - c) * (1.0 + c)) / c


# ---- where a body's points are ----------------------------------------------------------------

def displacement(body: Body | None, poses: Poses, p) -> Coords:
    """Displacement (dx, dy) of the design point ``p`` of ``body`` in every state."""
    if body is None:
        return np.zeros(1), np.zeros(1)
    return BODY_KINDS[body.kind].displacement(body, poses, p)


def position(body: Body | None, poses: Poses, p) -> Coords:
    """World position of the design point ``p`` of ``body`` (None: the ground) in every state."""
    if body is None:
        return p[0] + np.zeros(1), p[1] + np.zeros(1)
    return BODY_KINDS[body.kind].position(body, poses, p)


def lever_arm(body: Body | None, poses: Poses, p) -> Coords | None:
    """The arm from a lever's pivot to ``p``, turned to every state; None for other bodies (a
    transmission angle counts a lever's side of a pair only)."""
    return None if body is None else BODY_KINDS[body.kind].arm(body, poses, p)


def placed_key(body: Body | None, p: Point) -> tuple:
    """The key of a design point of ``body``; a point given as arrays (one value per sample
    of a tolerance run) is keyed by the arrays' identity."""
    bid = GROUND if body is None else body.id
    if isinstance(p[0], (float, int)) and isinstance(p[1], (float, int)):
        return (bid, float(p[0]), float(p[1]))
    if np.ndim(p[0]) or np.ndim(p[1]):
        return (bid, id(p[0]), id(p[1]))
    return (bid, float(p[0]), float(p[1]))


def placed_position(body: Body | None, poses: Poses, p: Point) -> Coords:
    """``position``, reusing the point where a closed form of this solve placed it."""
    hit = poses.placed.get(placed_key(body, p))
    return (hit[0], hit[1]) if hit is not None else position(body, poses, p)


def is_zero(v) -> bool:
    """``v`` is the number 0 (not an array): a term that adds nothing and can be skipped."""
    return isinstance(v, (float, int)) and v == 0


def shifted(a, k):
    """``a + k``, or ``a`` itself when ``k`` is the number 0 (the same values, one array pass
    and one allocation fewer; the caller must not write into the result)."""
    return a if is_zero(k) else a + k


def rotate(rx, ry, c, s, centre) -> Coords:
    """centre + R·(rx, ry) for the cosines ``c`` and sines ``s`` of the states: the terms of
    an arm component or a centre coordinate that is exactly 0 (a number) are skipped, which
    gives the same values (an arm along an axis and a pivot on an axis are common: each saves
    array passes of the eight)."""
    if is_number(rx) and is_number(ry) and (rx == 0 or ry == 0):
        if rx == 0:
            y = ry * c
            if is_zero(centre[0]):
                x = (-ry) * s  # -(ry s): the same value as 0 - ry s
            else:
                x = ry * s
                np.subtract(centre[0], x, out=x)
        else:
            x, y = rx * c, rx * s
            if not is_zero(centre[0]):
                x += centre[0]
        if not is_zero(centre[1]):
            y += centre[1]
        return x, y
    x, y = rx * c, rx * s
    x -= ry * s
    y += ry * c
    if not is_zero(centre[0]):
        x += centre[0]
    if not is_zero(centre[1]):
        y += centre[1]
    return x, y


def turned(body: Body, poses: Poses, p) -> Coords:
    """Displacement of ``p`` on a body turning about its pivot by ``poses.theta``."""
    rx, ry = p[0] - body.pivot[0], p[1] - body.pivot[1]
    c, s = poses.theta.cos_sin(body.id)
    return rx * c - ry * s - rx, rx * s + ry * c - ry


# ---- drawing ----------------------------------------------------------------------------------

@dataclass
class Shape:
    """One thing the drawing shows, in world mm at the drawn state's pose."""

    kind: str  # body | slot | pin | pivot | spring | stop | rod | anchor
    pts: list[Point]
    cls: str = ""
    ref: str = ""  # body or joint id
    layer: int = 0
    ground: Point | None = None  # hatch side (unit vector into the ground)


class Placer(Protocol):
    """What a kind's drawing asks of the drawing: a body's point at the state's pose and the
    plane a body sits on (the ground: plane 0)."""

    def pt(self, bid: str, p: Point) -> Point: ...

    def layer(self, bid: str) -> int: ...


# ---- dynamics ---------------------------------------------------------------------------------

class SceneBuilder(Protocol):
    """What a kind's dynamics asks of the pymunk scene being built."""

    space: pymunk.Space
    mech: Any
    axis: dict[str, tuple[float, float]]
    ref: dict[str, tuple[float, float]]
    touches: list
    profiles: list

    def body_of(self, bid: str) -> pymunk.Body: ...

    def anchor(self, bid: str, p) -> tuple[float, float]: ...

    def order_of(self, bid: str) -> int: ...

    def measure(self, jid: str, kind: str, ia: int, la: tuple, ib: int, lb: tuple,
                extra: tuple = ()) -> None: ...

    def body_u(self, bid: str, pos) -> float: ...


# ---- the kinds --------------------------------------------------------------------------------

class BodyKind:
    """A body kind. The defaults are those of a body turning about its ``pivot``."""

    name: ClassVar[str] = ""
    coordinate: ClassVar[str] = "theta"  # the ``Poses`` field of its coordinate ("u" or "theta")
    translates: ClassVar[bool] = False  # a signal on it is its travel along ``axis``
    input_terminal: ClassVar[bool] = True  # its coordinate can be given (a cell's input)
    dyad: ClassVar[bool] = False  # the closed form may place it as one side of a pinned dyad
    held_by_contacts: ClassVar[bool] = False  # one-sided contacts and a spring may place it

    # closed form
    @classmethod
    def displacement(cls, body: Body, poses: Poses, p) -> Coords:
        return turned(body, poses, p)

    @classmethod
    def position(cls, body: Body, poses: Poses, p) -> Coords:
        dx, dy = cls.displacement(body, poses, p)
        return p[0] + dx, p[1] + dy

    @classmethod
    def arm(cls, body: Body, poses: Poses, p) -> Coords | None:
        return None

    @classmethod
    def dyad_anchor(cls, body: Body, joints: list[Joint], bodies: dict[str, Body],
                    poses: Poses):
        """The point it turns about in a dyad: (design point, world x, world y, bad, joint)."""
        return None

    @classmethod
    def set_turn(cls, body: Body, poses: Poses, th, ok, centre: Point, cx, cy,
                 size: int) -> None:
        """Record the angle ``th`` (valid where ``ok``) of a turn about the design point
        ``centre``, which stands at (cx, cy)."""
        poses.theta[body.id] = np.where(ok, th, np.nan) * np.ones(size)

    # drawing
    @classmethod
    def symbols(cls, body: Body) -> list[Shape]:
        """Marks drawn with the outline (a lever's ground pivot)."""
        return []

    @classmethod
    def reach(cls, body: Body, stroke: float) -> list[Point]:
        """Points that bound where its outline goes in any state (the drawing's frame)."""
        if body.axis is None:
            return []
        pts = np.array([p for poly in body.outline for p in poly], dtype=float)
        ax = np.array(body.axis, dtype=float) * stroke
        return [tuple(p) for p in np.vstack([pts - ax, pts + ax]).tolist()]

    @classmethod
    def sweep(cls, body: Body, stroke: float) -> Point:
        """How far a point may move from its design pose, per axis (for label room)."""
        return (0.0, 0.0)

    # dynamics
    @classmethod
    def scene_ref(cls, body: Body) -> Point:
        """The point the pymunk body's position stands for."""
        return body.pivot

    @classmethod
    def pymunk_body(cls, body: Body, ref: Point) -> pymunk.Body:
        """A dynamic body; its moment from the outline's mean squared radius about ``ref``."""
        r2 = max(sum((p[0] - ref[0]) ** 2 + (p[1] - ref[1]) ** 2 for poly in body.outline
                     for p in poly) / max(1, sum(len(pl) for pl in body.outline)), 1.0)
        return pymunk.Body(body.mass, body.mass * r2)

    @classmethod
    def place(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point,
              poses: Poses) -> None:
        """Put the pymunk body where the closed form's first state has it."""
        pm.position = ref
        pm.angle = float(poses.theta[body.id][0])

    @classmethod
    def hold(cls, scene: SceneBuilder, body: Body, pm: pymunk.Body, ref: Point) -> None:
        """Its constraints to the ground (none by default: free in the plane)."""

    @classmethod
    def follow(cls, scene: SceneBuilder, bid: str, pm: pymunk.Body, ref: Poses, i0: int,
               w: float, dt: float) -> None:
        """Drive a closed-form-driven (kinematic) body towards its pose between samples
        ``i0`` and ``i0 + 1`` of ``ref`` (weight ``w`` on the later) within one step."""
        th = ref.theta[bid][i0] * (1 - w) + ref.theta[bid][i0 + 1] * w
        pm.angular_velocity = (th - pm.angle) / dt

    @classmethod
    def scene_pose(cls, scene: SceneBuilder, bid: str, i: int, pos, ang) -> Poses:
        """Its pose in a scene state (row ``i`` of ``pos``, ``ang``) in the closed form's
        terms."""
        return Poses(theta={bid: np.array([ang[i]])})


Solver = Callable[[Joint, Body, Body | None, Poses, int], None]


class JointKind:
    """A joint kind: nothing solved, checked or drawn unless the kind says so."""

    name: ClassVar[str] = ""
    revolute: ClassVar[bool] = False  # the two bodies turn about one shared point (a dyad)
    one_sided: ClassVar[bool] = False  # a face pair that bounds a slider's travel
    # closed forms placing a body from this joint when the other body is known, by the
    # body's kind and its side of the joint ("a" or "b")
    solvers: ClassVar[dict[tuple[str, str], Solver]] = {}

    @classmethod
    def solve(cls, j: Joint, body: Body, other: Body | None, poses: Poses, size: int) -> bool:
        """Place ``body`` from this joint (the other side known); False if no closed form
        covers this pair."""
        f = cls.solvers.get((body.kind, "a" if j.a == body.id else "b"))
        if f is None:
            return False
        f(j, body, other, poses, size)
        return True

    @classmethod
    def slider_limit(cls, j: Joint, slider: Body, other: Body | None, poses: Poses):
        """A one-sided joint's bound on a slider's travel ``u`` as (k, rhs) with
        ``u·k >= rhs``, or None where it bounds nothing."""
        return None

    @classmethod
    def violation(cls, j: Joint, a: Body | None, b: Body | None, poses: Poses, size: int,
                  tol: float) -> np.ndarray | None:
        """States where the solved bodies break this joint (None: nothing to check)."""
        return None

    @classmethod
    def shapes(cls, j: Joint, at: Placer) -> list[Shape]:
        return []

    @classmethod
    def ground_point(cls, j: Joint) -> Point | None:
        """Its fixed point on the ground, if it is a stop (labels keep clear of it)."""
        return None

    @classmethod
    def add_to_scene(cls, scene: SceneBuilder, j: Joint) -> None:
        raise ValueError(f"unknown joint kind {j.kind}")
