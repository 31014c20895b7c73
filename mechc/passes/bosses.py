"""Bosses: material round every pin, so every hole a pin needs can be cut.

A pin joins two plates through a hole in each; the hole needs a ring of plate round it. Cells
and nets draw their bars so that most pins sit inside them, but some do not: a net's rod pinned
on the end (or past the end, or at the edge) of its load's input slider, an in-cell rod joint
whose end lies off the bar it drives, a fixed pivot near a lever's edge. This pass, run once
after assembly, gives each of them a boss on the plane of the body's nearest polygon: a disc
of radius ``boss_radius(d)`` about the pin and, where the pin is off the body, a neck of the
same width from the body's nearest point to it (the disc and neck are one convex polygon). A
pin the body's outline already holds with that edge distance gets nothing.

The rule (``boss_radius``): edge distance, from the hole's centre to the plate's edge, at least
the pin's diameter and at least the plate's thickness. It is the rule the bars already follow
(a bar ``ctx.bar`` wide ends ``ctx.bar / 2`` beyond its pin, and pins are at most half the bar
width: ``mechc/passes/strength.py``), so a boss never makes a bar wider, and it leaves a ligament
of half the pin's diameter each side of the hole, the quarter bar the pin sizing assumes.
Structural steelwork asks more of bolted joints (EN 1993-1-8, Table 3.3: 1.2 hole diameters
from the centre to an edge), for loads in kilonewtons; these pins carry newtons, and their
bearing on the plate is checked by the strength pass.

Each boss adds a polygon to the body's outline (``poly_layers`` keeps its plane), and the mass
of the plate it adds (the boss less what the body already covers on that plane) to the body's
mass.
"""

from __future__ import annotations

import math

from shapely.geometry import MultiPoint, Point, Polygon
from shapely.ops import nearest_points, unary_union

from mechc.ir.mechanism import GROUND, Body, Mechanism, SynthContext

#: Sides of the polygon a boss disc is drawn with (circumscribed: it holds the whole disc).
SIDES = 12
#: A pin is held when the outline contains its disc shrunk by this much (rounding, mm).
TOL = 1e-6


def boss_radius(d: float, ctx: SynthContext) -> float:
    """Least distance from a pin's centre to the plate's edge (see the module docstring)."""
    return max(d, ctx.thickness)


def pin_sites(mech: Mechanism) -> list[tuple[str, tuple[float, float], float,
                                             tuple[float, float] | None]]:
    """Every place a body takes a pin: (body, centre, diameter, slot end or None). Pin and
    rod joints (both ends), grooves (the slot in ``a``, the pin in ``b``), fixed pivots."""
    ctx = mech.ctx
    out = []
    for part in mech.all_parts():
        for b in part.bodies:
            if b.kind in ("lever", "rotor") and b.pivot is not None:
                out.append((b.id, b.pivot, b.pin_diameter or ctx.pin_diameter, None))
        for j in part.joints:
            d = j.pin_diameter or ctx.pin_diameter
            if j.kind == "pin":
                out += [(j.a, j.pa, d, None), (j.b, j.pa, d, None)]
            elif j.kind == "rod":
                out += [(j.a, j.pa, d, None), (j.b, j.pb, d, None)]
            elif j.kind == "groove":
                out += [(j.a, j.p0, d, j.p1), (j.b, j.q, d, None)]
    return [s for s in out if s[0] != GROUND]


def _plane_shapes(body: Body) -> dict[int, Polygon]:
    by_plane: dict[int, list[Polygon]] = {}
    for i, poly in enumerate(body.outline):
        if len(poly) >= 3:
            by_plane.setdefault(body.layer_of(i), []).append(Polygon(poly).buffer(0))
    return {k: unary_union(v) for k, v in by_plane.items()}


def _disc(c: tuple[float, float], r: float) -> list[tuple[float, float]]:
    rc = r / math.cos(math.pi / SIDES)  # circumscribed: the disc of radius r lies inside
    return [(c[0] + rc * math.cos(2 * math.pi * (k + 0.5) / SIDES),
             c[1] + rc * math.sin(2 * math.pi * (k + 0.5) / SIDES)) for k in range(SIDES)]


def boss(shape: Polygon, centre: tuple[float, float], r: float,
         end: tuple[float, float] | None = None) -> Polygon | None:
    """The boss ``shape`` needs to hold a hole (or a slot to ``end``) with edge distance
    ``r``, or None where it holds it already."""
    need = [centre] if end is None else [centre, end]
    ring = MultiPoint(need).convex_hull.buffer(r - TOL, quad_segs=8)
    if shape.contains(ring):
        return None
    pts = [p for c in need for p in _disc(c, r)]
    near = nearest_points(shape, MultiPoint(need).convex_hull)[0]
    if not shape.contains(Point(near).buffer(TOL)):  # off the body: a neck back to it
        pts += _disc((near.x, near.y), r)
    return MultiPoint(pts).convex_hull


def add_bosses(mech: Mechanism) -> list[tuple[str, int]]:
    """Give every body a boss at every pin its outline does not hold (see the module
    docstring); the (body, plane) of each boss added."""
    ctx = mech.ctx
    bodies = mech.body_index()
    added = []
    for bid, centre, d, end in pin_sites(mech):
        body = bodies.get(bid)
        if body is None or not body.outline:
            continue
        shapes = _plane_shapes(body)
        if not shapes:
            continue
        target = Point(centre) if end is None else MultiPoint([centre, end]).convex_hull
        plane = min(shapes, key=lambda k: (shapes[k].distance(target), k))
        g = boss(shapes[plane], centre, boss_radius(d, ctx), end)
        if g is None:
            continue
        extra = g.difference(shapes[plane]).area
        layers = body.poly_layers or [body.layer] * len(body.outline)
        body.outline.append([(round(x, 6), round(y, 6)) for x, y in g.exterior.coords[:-1]])
        body.poly_layers = [*layers, plane]
        body.mass += extra * ctx.thickness * ctx.density
        added.append((bid, plane))
    return added
