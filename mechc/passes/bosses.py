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

A boss that would come within the clearance of a body it is not pinned to on that plane (at
the design pose) goes instead on the nearest of the cells' planes (below the nets') where it
keeps a stroke more than the clearance from every such body, a doubler plate over the body;
failing that, on the plane of the body's nearest polygon counting the arms of the nets it
drives. The interference check of the design checks then measures it in every state like any
other polygon.

Each boss adds a polygon to the body's outline (``poly_layers`` keeps its plane), before the
arm and bar of each net the body drives (assembly appends those last), and the mass of the
plate it adds (the boss less what the body already covers on that plane) to the body's mass.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely import STRtree
from shapely.geometry import Point, Polygon
from shapely.ops import nearest_points, unary_union

from mechc.ir.mechanism import GROUND, Body, Mechanism, SynthContext
from mechc.physics.interference import exempt_pairs

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


def _plane_shapes(body: Body, tail: int = 0) -> dict[int, Polygon]:
    """The body's plate per plane, leaving out its last ``tail`` polygons."""
    by_plane: dict[int, list[Polygon]] = {}
    for i, poly in enumerate(body.outline[:len(body.outline) - tail]):
        if len(poly) >= 3:
            by_plane.setdefault(body.layer_of(i), []).append(Polygon(poly).buffer(0))
    return {k: unary_union(v) for k, v in by_plane.items()}


def _prime(bodies: list[Body], cache: dict) -> None:
    """``_plane_shapes(body)`` of many bodies at once into ``cache`` (their polygons made and
    cleaned in one vectorised call: a Python object per polygon was most of the time)."""
    coords, index, keys = [], [], []
    for b in bodies:
        for i, poly in enumerate(b.outline):
            if len(poly) >= 3:
                coords += poly
                index += [len(keys)] * len(poly)
                keys.append((b.id, b.layer_of(i)))
    if not keys:
        return
    rings = shapely.linearrings(np.asarray(coords, dtype=float), indices=index)
    clean = shapely.buffer(shapely.polygons(rings), 0)
    by_plane: dict[str, dict[int, list[Polygon]]] = {b.id: {} for b in bodies}
    for (bid, plane), g in zip(keys, clean):
        by_plane[bid].setdefault(plane, []).append(g)
    for bid, shapes in by_plane.items():
        cache[(bid, 0)] = {k: unary_union(v) for k, v in shapes.items()}


def _disc(c: tuple[float, float], r: float) -> list[tuple[float, float]]:
    rc = r / math.cos(math.pi / SIDES)  # circumscribed: the disc of radius r lies inside
    return [(c[0] + rc * math.cos(2 * math.pi * (k + 0.5) / SIDES),
             c[1] + rc * math.sin(2 * math.pi * (k + 0.5) / SIDES)) for k in range(SIDES)]


def _hull(pts: list[tuple[float, float]]):
    """Convex hull of points (built from an array: shapely's MultiPoint of tuples makes a
    Point object per vertex, a third of this pass's time on a big design)."""
    return shapely.convex_hull(shapely.multipoints(np.asarray(pts, dtype=float)))


def boss(shape: Polygon, centre: tuple[float, float], r: float,
         end: tuple[float, float] | None = None) -> Polygon | None:
    """The boss ``shape`` needs to hold a hole (or a slot to ``end``) with edge distance
    ``r``, or None where it holds it already."""
    need = [centre] if end is None else [centre, end]
    hull = _hull(need)
    ring = hull.buffer(r - TOL, quad_segs=8)
    if shape.contains(ring):
        return None
    pts = [p for c in need for p in _disc(c, r)]
    near = nearest_points(shape, hull)[0]
    if not shape.contains(Point(near).buffer(TOL)):  # off the body: a neck back to it
        pts += _disc((near.x, near.y), r)
    return _hull(pts)


def _held(sites: list, bodies: dict[str, Body], ctx: SynthContext,
          shapes_of) -> np.ndarray:
    """Which pin sites the body's outline already holds on one of its planes, all sites in
    one vectorised test (shapely on arrays, each body's plates prepared once): the ring
    ``boss`` tests, contained by a plate. A body with no plate holds them all (nothing to
    add a boss to)."""
    n = len(sites)
    held = np.zeros(n, dtype=bool)
    if not n:
        return held
    coords, index = [], []
    for k, (_, centre, _, end) in enumerate(sites):
        coords.append(centre)
        index.append(k)
        if end is not None:
            coords += [end]
            index.append(k)
    radii = np.array([boss_radius(d, ctx) - TOL for _, _, d, _ in sites])
    rings = shapely.buffer(shapely.convex_hull(shapely.multipoints(np.asarray(coords, float),
                                                                 indices=index)),
                           radii, quad_segs=8)
    pair_site, pair_shape = [], []
    _prime([bodies[b] for b in dict.fromkeys(s[0] for s in sites)], shapes_of.cache)
    for k, (bid, _, _, _) in enumerate(sites):
        every = shapes_of(bodies[bid], 0)
        if not every:
            held[k] = True
        for g in every.values():
            pair_site.append(k)
            pair_shape.append(g)
    if pair_site:
        shapes = np.asarray(pair_shape, dtype=object)
        shapely.prepare(shapes)
        inside = shapely.contains(shapes, rings[pair_site])
        held[np.asarray(pair_site)[inside]] = True
    return held


def add_bosses(mech: Mechanism) -> list[tuple[str, int]]:
    """Give every body a boss at every pin its outline does not hold (see the module
    docstring); the (body, plane) of each boss added."""
    ctx = mech.ctx
    bodies = mech.body_index()
    exempt = exempt_pairs(mech)
    owner: list[str] = []
    plane_of: list[int] = []
    polys: list[Polygon] = []
    coords: list = []
    index: list[int] = []
    for b in bodies.values():
        for i, poly in enumerate(b.outline):
            if len(poly) >= 3:
                owner.append(b.id)
                plane_of.append(b.layer_of(i))
                coords += poly
                index += [len(owner) - 1] * len(poly)
    if owner:  # Polygon(poly).buffer(0) of each, in one vectorised call
        rings = shapely.linearrings(np.asarray(coords, dtype=float), indices=index)
        polys = list(shapely.buffer(shapely.polygons(rings), 0))
    planes = sorted(set(plane_of)) or [0]
    drives: dict[str, int] = {}
    net_planes = set()
    for part in mech.nets.values():
        for j in part.joints:
            if j.id.endswith(".driver"):
                drives[j.a] = drives.get(j.a, 0) + 1
        net_planes.update(b.layer for b in part.bodies)
        for key in ("fanout_plane", "arm_plane"):
            if key in part.data:
                net_planes.add(part.data[key])
    net_base = min(net_planes, default=max(planes) + 1)  # nets sit above every cell plane
    # one spatial index per plane over the polygons assembly drew, and the bounds of the
    # bosses added here in arrays (a scan of every polygon per pin, or of every boss added
    # per pin, was quadratic: minutes on a design of a thousand cells)
    by_plane: dict[int, list[int]] = {}
    for k, pl in enumerate(plane_of):
        by_plane.setdefault(pl, []).append(k)
    trees = {pl: STRtree([polys[k] for k in ks]) for pl, ks in by_plane.items()}
    drawn = len(polys)
    # each body's plates per plane (all, and less the arms and bars of the nets it drives),
    # made once and again only after a boss is added to it
    cache: dict[tuple[str, int], dict[int, Polygon]] = {}

    def shapes_of(body: Body, tail: int) -> dict[int, Polygon]:
        key = (body.id, tail)
        if key not in cache:
            cache[key] = _plane_shapes(body, tail)
        return cache[key]

    shapes_of.cache = cache  # type: ignore[attr-defined]

    sites = [s for s in pin_sites(mech) if bodies.get(s[0]) is not None and bodies[s[0]].outline]
    # a pin the outline holds as assembly drew it stays held as bosses are added (they only
    # add plate): one vectorised test decides those, the rest go one by one as before
    held = _held(sites, bodies, ctx, shapes_of)
    boxes = np.zeros((int(np.count_nonzero(~held)), 4))  # bounds of the bosses added
    box_plane = np.zeros(len(boxes), dtype=np.int64)
    added = []
    grown: set[str] = set()  # bodies given a boss so far: their sites are tested again
    for (bid, centre, d, end), ok in zip(sites, held):
        if ok:
            continue
        body = bodies[bid]
        r = boss_radius(d, ctx)
        every = shapes_of(body, 0)
        if bid in grown and any(boss(g, centre, r, end) is None for g in every.values()):
            continue  # held already (by a net's arm or bar too: a rod's pin on its fan-out)
        # a driver's own plate takes its bosses, not the arm and bar of the nets it drives
        tail = 2 * drives.get(bid, 0)
        shapes = shapes_of(body, tail) or every
        target = Point(centre) if end is None else _hull([centre, end])
        plane = min(shapes, key=lambda k: (shapes[k].distance(target), k))
        g = boss(shapes[plane], centre, r, end)
        if g is None:
            continue
        # the boss's plane: the body's own if the boss keeps the clearance there from every
        # body it is not pinned to; else the nearest cell plane where it keeps a stroke more
        # (a doubler plate fastened over the body); else that of the body's nearest polygon
        room = ctx.clearance + ctx.stroke * (1 + 2 * ctx.overtravel)

        def clear(k: int, margin: float, g=g, bid=bid) -> bool:
            """No polygon on plane ``k`` of a body ``bid`` is not pinned to within ``margin``
            of ``g``."""
            near = [by_plane[k][i] for i in trees[k].query(g, predicate="dwithin",
                                                            distance=margin)] if k in trees else []
            x0, y0, x1, y1 = g.bounds
            m = len(polys) - drawn
            bx = boxes[:m]
            hit = np.flatnonzero((box_plane[:m] == k) & (bx[:, 0] <= x1 + margin)
                                 & (bx[:, 2] >= x0 - margin) & (bx[:, 1] <= y1 + margin)
                                 & (bx[:, 3] >= y0 - margin))
            near += (hit + drawn).tolist()
            return all(g.distance(polys[i]) >= margin for i in near
                       if owner[i] != bid
                       and exempt.get(frozenset((bid, owner[i]))) != "bearing")

        if not clear(plane, ctx.clearance):
            ordered = sorted((k for k in planes if k != plane and k < net_base),
                             key=lambda k: (abs(k - plane), k))
            moved = next((k for k in ordered if clear(k, room)), None)
            if moved is None:  # the plane of its nearest polygon, its nets' arms included
                moved = min(every, key=lambda k: (every[k].distance(target), k))
                g = boss(every[moved], centre, r, end) or g
            plane = moved
        extra = g.difference(every.get(plane, Polygon())).area
        layers = body.poly_layers or [body.layer] * len(body.outline)
        # before the arm and bar of each net it drives, which assembly appended last: a
        # driver's own polygons stay first, its nets' last
        at = len(body.outline) - tail
        body.outline.insert(at, [(round(x, 6), round(y, 6)) for x, y in g.exterior.coords[:-1]])
        layers = [*layers[:at], plane, *layers[at:]]
        body.poly_layers = None if set(layers) == {body.layer} else layers
        body.mass += extra * ctx.thickness * ctx.density
        grown.add(bid)
        cache.pop((bid, 0), None)
        cache.pop((bid, tail), None)
        boxes[len(polys) - drawn] = g.bounds
        box_plane[len(polys) - drawn] = plane
        owner.append(bid)
        plane_of.append(plane)
        polys.append(g)
        added.append((bid, plane))
    return added
