"""The frame: the ground the design's fixed points stand on, as parts to cut.

The design has no ground body: fixed pivots, pins and slots to the ground, sliders' guides,
stops and springs anchored to the ground are joints to ``ground``. This module turns each into
a feature of the frame:

- a **base plate** one plate thickness under the lowest plane, covering every body's outline
  and every fixed point grown by a stroke (how far a part moves from its design pose) and
  ``MARGIN``; it has
  - a hole for every fixed pivot (lever and rotor pivots; pins and rod ends to the ground) and
    every ground spring anchor, of the pin's diameter, and a slot for a groove cut in the ground;
  - a guide slot for every slider: a peg (a dowel of the design's least pin diameter) stands
    in the slider at the deepest point of its plate (shapely's pole of inaccessibility) and runs
    in a slot along the slider's axis as long as its travel (half a stroke and the overtravel
    either way from the design pose) plus the peg;
  - a screw hole under every stop block, and ``MOUNT`` holes near its corners to fix it down;
- a **stop block** for every stop (a contact with the ground): a square ``STOP_SIDE`` pin
  diameters wide on the ground's side of the stop's face, on the plane of the body it stops,
  screwed to the base plate through its centre.

Posts between the base plate and a pivot or stop on a higher plane (spacers, the pin's length)
are bought parts in the parts list; whether another plane's parts pass over a post is not
checked here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.affinity import rotate, translate
from shapely.geometry import LineString, Point, Polygon, box
from shapely.ops import polylabel, unary_union

from mechc.ir.mechanism import GROUND, Body, Mechanism
from mechc.parts.base import joint_kind

#: The base plate's border beyond where parts reach, mm (room for its mounting holes).
MARGIN = 15.0
#: Mounting holes of the base plate: clearance holes for M4 screws (ISO 273, medium: 4.5 mm),
#: centred half the margin in from each corner.
MOUNT = 4.5
#: Stop blocks: a square this many pin diameters wide, fixed by one M3 screw (ISO 273 medium
#: clearance hole 3.4 mm) through its centre into the base plate.
STOP_SIDE = 3.0
STOP_SCREW = 3.4
#: Least plate between two holes or slots of the base plate, mm.
GAP = 1.0


@dataclass(frozen=True)
class Feature:
    """One fixed point of the design as the frame makes it: ``kind`` is pivot | pin | anchor
    | slot | guide | stop | mount; ``ref`` the joint, body or spring it serves; a hole of
    ``diameter`` at ``centre`` in the base plate (a slot to ``end``)."""

    kind: str
    ref: str
    centre: tuple[float, float]
    diameter: float
    end: tuple[float, float] | None = None


@dataclass
class Frame:
    base: Polygon  # the base plate's outline, world mm
    plane: int  # the base plate's plane (one under the lowest)
    features: list[Feature]
    stops: list[tuple[str, int, Polygon, tuple[float, float]]]  # (joint, plane, block, screw)
    pegs: list[tuple[str, tuple[float, float], float]] = field(default_factory=list)
    crowded: list[str] = field(default_factory=list)  # sliders whose slot meets another hole


def _plane_of(body: Body, p: tuple[float, float]) -> int:
    """The plane of ``body``'s polygon nearest ``p``."""
    best = min(range(len(body.outline)),
               key=lambda i: (Polygon(body.outline[i]).distance(Point(p)), body.layer_of(i)))
    return body.layer_of(best)


def ground_features(mech: Mechanism) -> list[Feature]:
    """Every fixed point of ``mech`` (pivots, ground pins, slots and anchors, slider guides,
    stops), before the frame places its holes: what a frame must have."""
    ctx = mech.ctx
    out: list[Feature] = []
    S = ctx.stroke
    travel = S / 2 + ctx.overtravel * S
    for part in mech.all_parts():
        for b in part.bodies:
            if b.kind in ("lever", "rotor") and b.pivot is not None:
                out.append(Feature("pivot", f"{b.id}.pivot", tuple(b.pivot),
                                   b.pin_diameter or ctx.pin_diameter))
            elif b.kind == "slider" and b.axis is not None and b.outline:
                c = polylabel(_main_plate(b), tolerance=0.05)
                out.append(_slot(b, (c.x, c.y), travel, ctx.pin_diameter))
        for j in part.joints:
            if GROUND not in (j.a, j.b):
                continue
            d = j.pin_diameter or ctx.pin_diameter
            if j.kind == "pin":
                out.append(Feature("pin", j.id, tuple(j.pa), d))
            elif j.kind == "rod":
                out.append(Feature("pin", j.id, tuple(j.pa if j.a == GROUND else j.pb), d))
            elif j.kind == "groove":
                if j.a == GROUND:
                    out.append(Feature("slot", j.id, tuple(j.p0), d, tuple(j.p1)))
                else:
                    out.append(Feature("pin", j.id, tuple(j.q), d))
            elif joint_kind(j.kind).ground_point(j) is not None:
                out.append(Feature("stop", j.id, tuple(joint_kind(j.kind).ground_point(j)),
                                   STOP_SCREW))
        for s in part.springs:
            if GROUND in (s.a, s.b):
                out.append(Feature("anchor", s.id, tuple(s.pa if s.a == GROUND else s.pb),
                                   ctx.pin_diameter))
    return out


def _main_plate(b: Body) -> Polygon:
    """The largest connected piece of ``b``'s plate on the plane of its first polygon."""
    plane = b.layer_of(0)
    shape = unary_union([Polygon(p).buffer(0) for i, p in enumerate(b.outline)
                         if b.layer_of(i) == plane])
    return max(getattr(shape, "geoms", [shape]), key=lambda g: g.area)


def _slot(b: Body, c: tuple[float, float], travel: float, d: float) -> Feature:
    """The guide slot of slider ``b`` for a peg at ``c`` (design pose)."""
    ax = b.axis
    return Feature("guide", b.id, (c[0] - ax[0] * travel, c[1] - ax[1] * travel), d,
                   (c[0] + ax[0] * travel, c[1] + ax[1] * travel))


def _hole_shape(f: Feature):
    if f.end is None:
        return Point(f.centre).buffer(f.diameter / 2)
    return LineString([f.centre, f.end]).buffer(f.diameter / 2)


def place_guides(mech: Mechanism, feats: list[Feature], gap: float) -> list[str]:
    """Move each slider's peg (and so its slot) within the slider so that its slot keeps
    ``gap`` from every other hole of the base plate: candidate pegs on a 1 mm grid over the
    part of the slider's plate that holds a peg hole with the bosses' edge distance, nearest
    the deepest point first. The sliders for which no such peg exists (their slots keep the
    deepest point) are returned."""
    ctx = mech.ctx
    bodies = mech.body_index()
    travel = ctx.stroke / 2 + ctx.overtravel * ctx.stroke
    fixed = [_hole_shape(f) for f in feats if f.kind != "guide"]
    crowded = []
    for k, f in enumerate(feats):
        if f.kind != "guide":
            continue
        others = unary_union(fixed + [_hole_shape(g) for g in feats[:k] if g.kind == "guide"])
        if others.is_empty or _hole_shape(f).distance(others) >= gap:
            continue
        b = bodies[f.ref]
        plate = _main_plate(b)
        edge = max(f.diameter, ctx.thickness) - 1e-6
        mid = np.array([(f.centre[0] + f.end[0]) / 2, (f.centre[1] + f.end[1]) / 2])
        ax = np.asarray(b.axis, dtype=float)
        reach = math.dist(plate.bounds[:2], plate.bounds[2:])
        steps = np.arange(0.5, reach, 0.5)
        shifts = np.stack([steps, -steps], axis=1).ravel()  # nearest the deepest point first
        pts = mid[None, :] + shifts[:, None] * ax[None, :]
        discs = shapely.buffer(shapely.points(pts), edge)
        for q in pts[shapely.contains(plate, discs)]:
            g = _slot(b, (float(q[0]), float(q[1])), travel, f.diameter)
            if _hole_shape(g).distance(others) >= gap:
                feats[k] = g
                break
        else:
            crowded.append(f.ref)
    return crowded


def stop_block(mech: Mechanism, j, d: float) -> tuple[Polygon, tuple[float, float]]:
    """A stop's block: a square ``STOP_SIDE * d`` wide, one face on the stop's face, on the
    ground's side; and its screw's centre."""
    kind = joint_kind(j.kind)
    gp = kind.ground_point(j)
    n = j.normal
    norm = math.hypot(n[0], n[1]) or 1.0
    n = (n[0] / norm, n[1] / norm)
    into = (-n[0], -n[1]) if j.a == GROUND else n  # the ground lies this way
    s = STOP_SIDE * d
    c = (gp[0] + into[0] * s / 2, gp[1] + into[1] * s / 2)
    sq = rotate(box(-s / 2, -s / 2, s / 2, s / 2), math.degrees(math.atan2(into[1], into[0])),
                origin=(0, 0))
    return translate(sq, c[0], c[1]), c


def build_frame(mech: Mechanism, extent: tuple[float, float, float, float],
                lowest: int) -> Frame:
    """The frame of ``mech`` under parts whose outlines span ``extent`` (x0, y0, x1, y1) on
    planes from ``lowest`` up (see the module docstring)."""
    ctx = mech.ctx
    bodies = mech.body_index()
    feats = ground_features(mech)
    stops = []
    out: list[Feature] = []
    for f in feats:
        if f.kind == "stop":
            j = next(j for p in mech.all_parts() for j in p.joints if j.id == f.ref)
            block, screw = stop_block(mech, j, ctx.pin_diameter)
            other = j.b if j.a == GROUND else j.a
            plane = _plane_of(bodies[other], f.centre) if other in bodies else lowest
            stops.append((j.id, plane, block, screw))
            out.append(Feature("stop", f.ref, screw, f.diameter))
        else:
            out.append(f)
    grow = ctx.stroke + MARGIN
    x0, y0, x1, y1 = extent
    fixed = [f for f in feats if f.kind != "guide"]
    xs = [x0, x1] + [f.centre[0] for f in fixed] + [f.end[0] for f in fixed if f.end]
    ys = [y0, y1] + [f.centre[1] for f in fixed] + [f.end[1] for f in fixed if f.end]
    # the fixed points too (a spring may be anchored outside the parts); a stop block lies
    # within STOP_SIDE pin diameters of its point and a guide slot within a stroke of its
    # slider: both far inside the border
    base = box(min(xs) - grow, min(ys) - grow, max(xs) + grow, max(ys) + grow)
    bx0, by0, bx1, by1 = base.bounds
    m = MARGIN / 2
    for k, (x, y) in enumerate(((bx0 + m, by0 + m), (bx1 - m, by0 + m), (bx1 - m, by1 - m),
                                (bx0 + m, by1 - m))):
        out.append(Feature("mount", f"frame.mount{k + 1}", (x, y), MOUNT))
    crowded = place_guides(mech, out, GAP)
    pegs = [(f.ref, _peg(f), f.diameter) for f in out if f.kind == "guide"]
    return Frame(base, lowest - 1, out, stops, pegs, crowded)


def _peg(f: Feature) -> tuple[float, float]:
    """A guide's peg at the design pose: the slot's middle."""
    return ((f.centre[0] + f.end[0]) / 2, (f.centre[1] + f.end[1]) / 2)
