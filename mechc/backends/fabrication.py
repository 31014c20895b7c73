"""What a design is made of, read off its mechanism at the rest pose: the plate pieces to cut
(each body's polygons on one plane, joined, with the holes of its pins), the links of rod
joints, the springs, the pins, the actuators and motors. The DXF, mesh and BOM writers all
read this one list, so a sheet, a model and a parts list never disagree about what a part is.

A body whose polygons sit on several planes (``poly_layers``: a bar whose far end crosses
over other parts) is several plates, one per plane; each connected piece of a plane is one
part. A pin hole is cut in every piece of the pin's body whose outline holds the whole hole
(the design gives every pin a boss: mechc/passes/bosses.py); a pin the outline does not hold
(a design written before bosses) gets no hole and is listed in ``Fabrication.unholed`` so the
writers can say so.

The link of a rod joint (a massless bar in a cell) has no plane in the design; it is put on a
plane of links above every part (``link_planes``): links that could meet go on different
planes. The frame (mechc/backends/frame.py) adds the ground's parts: the base plate under the
lowest plane and the stop blocks (kind ``frame``), and a guide peg's hole in every slider.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from shapely.geometry import LineString, Point, Polygon
from shapely.ops import unary_union

from mechc.backends.frame import Frame, build_frame
from mechc.cells.materials import MATERIALS, PIN_MATERIAL
from mechc.ir.mechanism import GROUND, Body, Mechanism, Spring
from mechc.parts.pushrod import bar_outline

#: Segments per quarter circle when a hole becomes a polygon (meshes only; the DXF keeps
#: circles): 16 keeps the polygon within 0.05 % of the hole's radius.
HOLE_RESOLUTION = 16
#: The role of a rod joint's link (its kind is "link", as a free link body's is).
ROD_LINK = "rod link"


@dataclass(frozen=True)
class Hole:
    """A pin hole (``end`` None) or a slot from ``centre`` to ``end`` (a groove), world mm."""

    centre: tuple[float, float]
    diameter: float
    joint: str
    end: tuple[float, float] | None = None

    def shape(self) -> Polygon:
        if self.end is None:
            return Point(self.centre).buffer(self.diameter / 2, quad_segs=HOLE_RESOLUTION)
        return LineString([self.centre, self.end]).buffer(self.diameter / 2,
                                                          quad_segs=HOLE_RESOLUTION)


@dataclass
class Piece:
    """One part cut from plate: ``outline`` (world mm at the rest pose; interior rings only
    where the body's own polygons enclose an opening), and the pin holes cut in it."""

    id: str
    body: str
    kind: str  # the body's kind; "link" for a rod joint's too (role ROD_LINK); "frame"
    role: str
    plane: int | None  # a link's and the frame's: given here (the design names none)
    outline: Polygon
    holes: list[Hole] = field(default_factory=list)

    def solid(self) -> Polygon:
        """The plate as cut: the outline less its holes."""
        if not self.holes:
            return self.outline
        return self.outline.difference(unary_union([h.shape() for h in self.holes]))

    def size(self) -> tuple[float, float]:
        """Length and width of its smallest enclosing rectangle, mm."""
        rect = self.outline.minimum_rotated_rectangle
        xs, ys = rect.exterior.coords.xy
        sides = [math.hypot(xs[i + 1] - xs[i], ys[i + 1] - ys[i]) for i in range(2)]
        return max(sides), min(sides)


@dataclass(frozen=True)
class PinItem:
    """A pin to buy: diameter, the plates it passes (their planes) and the joint it makes."""

    joint: str
    diameter: float
    planes: tuple[int, ...]  # of the pieces it passes; empty where no hole holds it
    to_ground: bool  # a fixed pivot: the pin stands in the frame
    unholed: int = 0  # bodies it joins whose outline holds no hole for it
    links: int = 0  # rod-joint links it passes (they have no plane)

    @property
    def plates(self) -> int:
        """Plate thicknesses its grip spans: its planes' span, plus its links."""
        return (max(self.planes) - min(self.planes) + 1 if self.planes else 0) + self.links


@dataclass
class Fabrication:
    thickness: float  # mm, every plate
    material: str  # the plate material's title
    pin_material: str
    stroke: float
    pieces: list[Piece]
    springs: list[Spring]
    pins: list[PinItem]
    actuators: dict[str, dict]
    motors: list[Body]  # rotor bodies: powered rollers
    rollers: list[tuple[str, float]]  # touch joints' rollers: (joint, diameter mm)
    unholed: list[tuple[str, str]] = field(default_factory=list)  # (joint, body): no hole cut
    frame: Frame | None = None

    @property
    def planes(self) -> list[int]:
        return sorted({p.plane for p in self.pieces if p.plane is not None})


def body_pieces(body: Body) -> list[Piece]:
    """A body's plates: its polygons joined per plane, one piece per connected part."""
    by_plane: dict[int, list[Polygon]] = {}
    for i, poly in enumerate(body.outline):
        by_plane.setdefault(body.layer_of(i), []).append(Polygon(poly))
    several = len(by_plane) > 1
    out = []
    for plane in sorted(by_plane):
        joined = unary_union([p.buffer(0) for p in by_plane[plane]])
        parts = sorted((g for g in getattr(joined, "geoms", [joined]) if g.area > 0),
                       key=lambda g: g.bounds)  # a polygon of no area is nothing to cut
        for k, g in enumerate(parts):
            name = body.id + (f"@{plane}" if several else "") + (f"#{k + 1}" if len(parts) > 1
                                                                 else "")
            out.append(Piece(name, body.id, body.kind, body.role, plane, g))
    return out


def fabrication(mech: Mechanism) -> Fabrication:
    """Every part of ``mech`` (see the module docstring)."""
    ctx = mech.ctx
    pieces: list[Piece] = []
    of_body: dict[str, list[Piece]] = {}
    springs: list[Spring] = []
    motors: list[Body] = []
    for part in mech.all_parts():
        for b in part.bodies:
            ps = body_pieces(b)
            of_body[b.id] = ps
            pieces.extend(ps)
            if b.kind == "rotor":
                motors.append(b)
        springs.extend(part.springs)
    pins: list[PinItem] = []
    rollers: list[tuple[str, float]] = []
    unholed: list[tuple[str, str]] = []
    links: list[Piece] = []  # rod joints' links

    def drill(bid: str, hole: Hole) -> tuple[int, ...] | None:
        """Cut ``hole`` in every piece of ``bid`` that holds it; the planes it went through
        (None: no piece holds it)."""
        if bid == GROUND:
            return ()
        shape = hole.shape()
        hit = [p for p in of_body.get(bid, []) if p.outline.contains(shape)]
        for p in hit:
            p.holes.append(hole)
        if not hit:
            unholed.append((hole.joint, bid))
            return None
        return tuple(p.plane for p in hit if p.plane is not None)

    def pin(joint: str, d: float, ends: list[tuple[int, ...] | None], ground: bool,
            links: int = 0) -> PinItem:
        planes = tuple(sorted({k for e in ends if e for k in e}))
        return PinItem(joint, d, planes, ground, sum(e is None for e in ends), links)

    for part in mech.all_parts():
        for b in part.bodies:
            if b.kind in ("lever", "rotor") and b.pivot is not None:
                d = b.pin_diameter or ctx.pin_diameter
                ends = [drill(b.id, Hole(b.pivot, d, f"{b.id}.pivot"))]
                pins.append(pin(f"{b.id}.pivot", d, ends, True))
        for j in part.joints:
            d = j.pin_diameter or ctx.pin_diameter
            if j.kind == "pin":
                ends = [drill(j.a, Hole(j.pa, d, j.id)), drill(j.b, Hole(j.pa, d, j.id))]
                pins.append(pin(j.id, d, ends, GROUND in (j.a, j.b)))
            elif j.kind == "groove":
                ends = [drill(j.a, Hole(j.p0, d, j.id, j.p1)), drill(j.b, Hole(j.q, d, j.id))]
                pins.append(pin(j.id, d, ends, GROUND in (j.a, j.b)))
            elif j.kind == "rod":  # a link of plate, pinned at both ends
                link = Piece(j.id, j.id, "link", ROD_LINK, None,
                             Polygon(bar_outline(j.pa, j.pb, ctx.bar)))
                pieces.append(link)
                links.append(link)
                for end, bid, at in (("a", j.a, j.pa), ("b", j.b, j.pb)):
                    hole = Hole(at, d, f"{j.id}.{end}")
                    link.holes.append(hole)
                    pins.append(pin(hole.joint, d, [drill(bid, hole)], bid == GROUND, 1))
            elif j.kind == "touch" and j.length:
                rollers.append((j.id, 2 * float(j.length)))
    planes = [p.plane for p in pieces if p.plane is not None] or [0]
    for link, plane in zip(links, link_planes(links, ctx, max(planes) + 1)):
        link.plane = plane
        pins = [q if not q.joint.startswith(link.id + ".") else
                PinItem(q.joint, q.diameter, tuple(sorted({*q.planes, plane})), q.to_ground,
                        q.unholed, 0) for q in pins]
    frame = None
    if pieces:
        extent = unary_union([p.outline for p in pieces if p.role != ROD_LINK]).bounds
        frame = build_frame(mech, extent, min(planes))
        pieces.extend(frame_pieces(frame))
        for ref, at, d in frame.pegs:  # a guide peg stands in its slider
            hole = Hole(at, d, f"{ref}.guide")
            pins.append(pin(hole.joint, d, [drill(ref, hole)], True))
    title = MATERIALS[ctx.material].title if ctx.material in MATERIALS else ctx.material
    return Fabrication(ctx.thickness, title, PIN_MATERIAL.title, ctx.stroke, pieces, springs,
                       pins, dict(mech.actuators), motors, rollers, unholed, frame)


def link_planes(links: list[Piece], ctx, base: int) -> list[int]:
    """A plane for each rod joint's link, ``base`` and up: two links go on one plane only when
    their outlines at rest are further apart than the clearance plus a stroke and its
    overtravel (each end of a link rides on a bar that moves up to half that either way from
    the design pose). Greedy, in order: each link takes the lowest plane none of the links it
    could meet has."""
    reach = ctx.clearance + ctx.stroke * (1 + 2 * ctx.overtravel)
    out: list[int] = []
    for i, p in enumerate(links):
        taken = {out[k] for k in range(i) if links[k].outline.distance(p.outline) < reach}
        c = 0
        while c in taken:
            c += 1
        out.append(base + c)
    return out


def frame_pieces(frame: Frame) -> list[Piece]:
    """The frame's plates: the base plate with a hole or slot per fixed point, and the stop
    blocks with their screw holes."""
    base = Piece("frame.base", "ground", "frame", "base plate", frame.plane, frame.base,
                 [Hole(f.centre, f.diameter, f.ref, f.end) for f in frame.features])
    out = [base]
    for jid, plane, block, screw in frame.stops:
        out.append(Piece(f"frame.stop.{jid}", "ground", "frame", "stop block", plane, block,
                         [Hole(screw, _screw(frame, jid), f"{jid}.screw")]))
    return out


def _screw(frame: Frame, jid: str) -> float:
    return next(f.diameter for f in frame.features if f.kind == "stop" and f.ref == jid)

