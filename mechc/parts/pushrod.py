"""``pushrod``: a straight bar of plate pinned at both ends, the part that carries a net from
its driver's fan-out bar to a load's input slider. Free in the plane like a ``link`` (its
``pivot`` is its midpoint, the reference point ``Poses.xy`` carries, and its centre of mass);
its pose follows from where its two pins are.

A net's rod is three things in the geometry: the ``pushrod`` body, a ``pin`` from the driver
body to it (joint ``a`` the driver, ``b`` the rod, at ``pa``) and a ``pin`` from it to the load
body (``a`` the rod, ``b`` the load). :func:`net_rods` reads them back as one
:class:`NetRod`; a net rod written before rods were bodies (a massless ``rod`` joint from
driver to load) reads as a ``NetRod`` without a body, so such files still solve and simulate.

Closed form: the load's pin is a fixed distance from the driver's pin (the rod joint's
quadratic, :func:`mechc.parts.rod.slider_from_rod` on :meth:`NetRod.as_joint`), then
:func:`pose_rod_body` turns the body onto the line between the two pins. In pymunk: a dynamic
body with the plate's mass and the moment of its outline about its centre, held by two pivot
joints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pymunk

from mechc.ir.mechanism import Body, Joint, Mechanism, Part, Point
from mechc.parts.base import position
from mechc.parts.link import Link
from mechc.parts.poses import Poses

ROLE = "net rod"


def bar_outline(pa: Point, pb: Point, width: float) -> list[Point]:
    """A bar of ``width`` along pa -> pb with square ends ``width / 2`` beyond each pin centre
    (material all round the pin hole)."""
    dx, dy = pb[0] - pa[0], pb[1] - pa[1]
    n = math.hypot(dx, dy)
    ux, uy = dx / n, dy / n
    h = width / 2
    ax, ay = pa[0] - ux * h, pa[1] - uy * h
    bx, by = pb[0] + ux * h, pb[1] + uy * h
    nx, ny = -uy * h, ux * h
    return [(ax - nx, ay - ny), (bx - nx, by - ny), (bx + nx, by + ny), (ax + nx, ay + ny)]


@dataclass(frozen=True)
class NetRod:
    """One rod of a net: driver body and pin point ``pa``, load body and pin point ``pb``."""

    id: str  # the rod body's id (or the legacy rod joint's)
    driver: str
    load: str
    pa: Point
    pb: Point
    length: float
    body: str | None  # None: a massless rod joint (a design written before rods were bodies)
    joints: tuple[Joint, ...]  # the pins (or the one legacy rod joint)

    def as_joint(self) -> Joint:
        """The constraint the pair of pins puts between driver and load: a rod of ``length``."""
        return Joint(self.id, "rod", self.driver, self.load, pa=self.pa, pb=self.pb,
                     length=self.length)


def net_rods(part: Part) -> list[NetRod]:
    """The rods of a net's part, each with its driver and load (see the module docstring)."""
    out = []
    for j in part.joints:
        if j.kind == "rod":  # a massless rod joint, from a design of an earlier version
            out.append(NetRod(j.id, j.a, j.b, j.pa, j.pb, float(j.length), None, (j,)))
    for b in part.bodies:
        if b.kind != PushRod.name:
            continue
        to_driver = [j for j in part.joints if j.kind == "pin" and j.b == b.id]
        to_load = [j for j in part.joints if j.kind == "pin" and j.a == b.id]
        if len(to_driver) != 1 or len(to_load) != 1:
            raise ValueError(f"{b.id}: a net rod needs one pin from its driver and one to its "
                             f"load (has {len(to_driver)} and {len(to_load)})")
        jd, jl = to_driver[0], to_load[0]
        length = np.hypot(jl.pa[0] - jd.pa[0], jl.pa[1] - jd.pa[1])  # arrays in a tolerance run
        length = float(length) if np.ndim(length) == 0 else length  # a number stays a number
        out.append(NetRod(b.id, jd.a, jl.b, jd.pa, jl.pa, length, b.id, (jd, jl)))
    return out


def pose_rod_body(rod: NetRod, body: Body, driver: Body, load: Body, poses: Poses,
                  size: int) -> None:
    """Turn and carry the rod body onto the line between its two posed pins (driver and load
    already solved)."""
    ax, ay = position(driver, poses, rod.pa)
    bx, by = position(load, poses, rod.pb)
    th = np.arctan2(by - ay, bx - ax) - np.arctan2(rod.pb[1] - rod.pa[1], rod.pb[0] - rod.pa[0])
    th = (th + np.pi) % (2 * np.pi) - np.pi
    th, ax, ay = (np.broadcast_to(v, (size,)) for v in (th, ax, ay))
    ok = np.isfinite(th) & np.isfinite(ax) & np.isfinite(ay)
    PushRod.set_turn(body, poses, th, ok, rod.pa, ax, ay, size)
    bad = ~ok
    for x in (driver.id, load.id):
        if x in poses.bad:
            bad = bad | poses.bad[x]
    poses.mark(body.id, bad)


class PushRod(Link):
    name = "pushrod"
    dyad = False  # placed by its net (``pose_net_rod``), not as one side of a dyad

    @classmethod
    def reach(cls, body: Body, stroke: float) -> list[Point]:
        """Its outline a stroke either way along its length (a rod follows sliders)."""
        (x0, y0), (x1, y1) = body.outline[0][0], body.outline[0][1]
        n = math.hypot(x1 - x0, y1 - y0) or 1.0
        dx, dy = (x1 - x0) / n * stroke, (y1 - y0) / n * stroke
        return [(p[0] + s * dx, p[1] + s * dy) for p in body.outline[0] for s in (-1, 1)]

    @classmethod
    def pymunk_body(cls, body: Body, ref: Point) -> pymunk.Body:
        """The plate's moment about its centre (a uniform polygon), not the vertex average a
        general link uses: a long bar's inertia is what the actuator and springs feel."""
        poly = body.outline[0]
        moment = pymunk.moment_for_poly(body.mass, [(p[0] - ref[0], p[1] - ref[1])
                                                    for p in poly])
        return pymunk.Body(body.mass, moment)


def net_loads(mech: Mechanism) -> dict[str, float]:
    """Mass (kg) each net's driver moves besides its own output: the net's rods and its
    loads' input sliders (the load axis of the cells' timing tables)."""
    index = mech.body_index()
    out: dict[str, float] = {}
    for net, part in mech.nets.items():
        m = 0.0
        for r in net_rods(part):
            if r.body is not None and r.body in index:
                m += index[r.body].mass
            if r.load in index:
                m += index[r.load].mass
        out[net] = m
    return out
