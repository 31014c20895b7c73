"""The nets' rods as parts: bodies of plate with mass, on planes, routed clear of each other.

Independent references: rod lengths and masses recomputed from the JSON's pin points and plate
rules; the closed-form rod pose against the posed pins of driver and load computed from those
bodies' own coordinates (slider travel along its axis); the pymunk bodies against the JSON's
masses; the routing against shapely distances between the posed outlines of every pair of
same-plane bodies (not the rectangles the router reasons with).
"""

from __future__ import annotations

import copy
import itertools
import json
import math

import numpy as np
import pymunk
import pytest
import shapely

from mechc.backends.design_json import check_design, design_from_json, design_to_json
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.ir.mechanism import GROUND
from mechc.parts import position
from mechc.parts.pushrod import net_rods
from mechc.physics.evaluate import evaluate, output_signals, settle
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import compile_spec
from mechc.proofs import prove
from tests.helpers import EXAMPLES

LIB = load_library()
CLEARANCE = 1.0  # mm, the routing's default
ALL = sorted(p.name for p in EXAMPLES.iterdir() if p.suffix in (".bool", ".pla", ".blif",
                                                                   ".fsm", ".kiss2"))


@pytest.fixture(scope="module")
def designs():
    """Every example compiled, and read back from its JSON (what simulate and draw see)."""
    out = {}
    for name in ALL:
        spec = load_spec(EXAMPLES / name)
        obj = json.loads(json.dumps(design_to_json(compile_spec(spec))))
        out[name] = (obj, design_from_json(obj, name), spec)
    return out


def _types(design) -> dict[str, str]:
    return {c.id: c.cell for c in design.netlist.cells.values()}


def _rod_bodies(obj: dict):
    for net, part in obj["mechanism"]["nets"].items():
        for b in part["bodies"]:
            yield net, part, b


@pytest.mark.parametrize("name", ALL)
def test_every_rod_is_a_body_of_plate_on_a_plane(designs, name):
    obj, design, _ = designs[name]
    rules = obj["mechanism"]["rules"]
    w, t, rho = max(5.0, 0.3 * rules["stroke"]), rules["thickness"], rules["density"]
    # a cell body's own polygons: all but those on the fan-out planes of the nets it drives
    # (the arm and bar, and a boss on the arm where the cell's plate had no room for it)
    fanout: dict[str, set[int]] = {}
    for part in obj["mechanism"]["nets"].values():
        drivers = {j["a"] for j in part["joints"] if j["id"].endswith(".driver")}
        for d in drivers:
            fanout.setdefault(d, set()).add(part["data"]["fanout_plane"])
            if "arm_plane" in part["data"]:  # an arm on a plane of its own
                fanout[d].add(part["data"]["arm_plane"])
    cell_planes = set()
    for c in obj["cells"]:
        for b in c["geometry"]["bodies"]:
            layers = b.get("poly_layers") or [b["layer"]] * len(b["outline"])
            cell_planes.update(set(layers) - fanout.get(b["id"], set()))
    n_rods = 0
    for _net, part, b in _rod_bodies(obj):
        n_rods += 1
        assert b["kind"] == "pushrod" and b["mass_kg"] > 0
        assert b["layer"] not in cell_planes  # rods may pass over any cell
        pins = {j["id"].rsplit(".", 1)[1]: j for j in part["joints"]
                if b["id"] in (j["a"], j["b"])}
        assert set(pins) == {"driver", "load"}
        assert all(j["kind"] == "pin" for j in pins.values())
        assert pins["driver"]["b"] == b["id"] and pins["load"]["a"] == b["id"]
        pa, pb = np.array(pins["driver"]["pa"]), np.array(pins["load"]["pa"])
        length = float(np.hypot(*(pb - pa)))
        # the outline: a bar of width w along the pins, square ends w/2 beyond each pin
        poly = shapely.Polygon(b["outline"][0])
        along = (pb - pa) / length
        proj = [float(np.dot(np.array(p) - pa, along)) for p in b["outline"][0]]
        normal = np.array([-along[1], along[0]])
        across = [float(np.dot(normal, np.array(p) - pa)) for p in b["outline"][0]]
        assert min(proj) == pytest.approx(-w / 2, abs=2e-3)
        assert max(proj) == pytest.approx(length + w / 2, abs=2e-3)
        assert max(across) - min(across) == pytest.approx(w, abs=2e-3)
        assert poly.area == pytest.approx((length + w) * w, rel=1e-4)
        assert b["mass_kg"] == pytest.approx(poly.area * t * rho, rel=1e-4)
        info = next(r for r in part["data"]["rods"] if r["body"] == b["id"])
        assert info["length_mm"] == pytest.approx(length, abs=1e-3)
        assert (info["width_mm"], info["thickness_mm"]) == (w, t)
        assert info["plane"] == b["layer"]
        # it ends on a body of one of the net's load cells
        owners = {ld.rsplit(".", 1)[0] for ld in part["data"]["loads"]}
        assert pins["load"]["b"].split(".")[0] in owners
    # one rod per cell load of every net (loads "out:NAME" are circuit outputs, no rod)
    assert n_rods == sum(1 for n in obj["nets"] for ld in n["loads"]
                         if not ld.startswith("out:"))
    assert n_rods > 0


@pytest.mark.parametrize("name", ["sorter.bool", "speedctl.fsm", "full_adder.bool",
                                  "toggle.kiss2"])
def test_rod_pose_puts_its_ends_on_the_posed_pins(designs, name):
    """The rod's closed-form pose (theta, xy about its midpoint) against the pins placed from
    the driver's and the load's own travel: slider design point + u * axis."""
    _, design, spec = designs[name]
    mech = design.mechanism
    names = list(design.netlist.inputs)
    rows = np.array(list(itertools.product((0.0, 1.0), repeat=len(names))))
    if getattr(spec, "kind", "") != "fsm":
        # and states between: a combinational design has no memory read from a previous state
        # (a feedback rod's load is placed from its MEMORY's state, so between rest states the
        # closed form does not hold that rod's length)
        rows = np.vstack([rows, np.full(len(names), 0.5),
                          np.random.default_rng(3).uniform(0, 1, (7, len(names)))])
    vals = {k: rows[:, i] for i, k in enumerate(names)}
    # fundamental mode: a MEMORY's loads stand where its settled state puts them
    poses, _, moving = settle(mech, LIB, _types(design), vals)
    assert not moving.any()
    bodies = mech.body_index()
    assert set(bodies) <= set(poses.u) | set(poses.theta)  # every body posed
    for part in mech.nets.values():
        for r in net_rods(part):
            rod = bodies[r.body]
            th = poses.theta[rod.id]
            tx, ty = poses.xy[rod.id]
            c, s = np.cos(th), np.sin(th)
            for end, owner in ((r.pa, bodies[r.driver]), (r.pb, bodies[r.load])):
                ex, ey = end[0] - rod.pivot[0], end[1] - rod.pivot[1]
                rx = rod.pivot[0] + tx + ex * c - ey * s
                ry = rod.pivot[1] + ty + ex * s + ey * c
                assert owner.kind == "slider"
                u = poses.u[owner.id]
                assert np.allclose(rx, end[0] + u * owner.axis[0], atol=1e-9)
                assert np.allclose(ry, end[1] + u * owner.axis[1], atol=1e-9)
            assert not poses.bad[rod.id].any()


@pytest.mark.parametrize("name", ["sorter.bool", "speedctl.fsm"])
def test_scene_rods_are_bodies_with_the_json_mass(designs, name):
    obj, design, _ = designs[name]
    mech = design.mechanism
    start = {k: 0.0 for k in design.netlist.inputs}
    sc = Scene.build(mech, LIB, _types(design), DynSettings(), start)
    masses = {b["id"]: b["mass_kg"] for _, _, b in _rod_bodies(obj)}
    assert masses
    for bid, m in masses.items():
        pm = sc.bodies[bid]
        assert pm.body_type == pymunk.Body.DYNAMIC
        assert pm.mass == pytest.approx(m, rel=1e-9)
        # the moment of a w x (L + w) plate about its centre
        b = mech.body_index()[bid]
        xs = [p[0] for p in b.outline[0]]
        lx, w = max(xs) - min(xs), mech.ctx.bar
        assert pm.moment == pytest.approx(m * (lx * lx + w * w) / 12, rel=1e-6)
        pivots = [c for c in pm.constraints if isinstance(c, pymunk.PivotJoint)]
        assert len(pivots) == 2  # pinned at both ends
    # no massless rod constraint is left between drivers and loads
    rod_ids = {j.id for p in mech.nets.values() for j in p.joints}
    assert not any(j.kind == "rod" and j.id in rod_ids for j in sc.joints)


def _joined(mech) -> set[frozenset]:
    pairs = set()
    for part in mech.all_parts():
        for j in part.joints:
            if GROUND not in (j.a, j.b):
                pairs.add(frozenset((j.a, j.b)))
    return pairs


def _net_polygons(mech) -> set[tuple[str, int]]:
    """(body, polygon index) of the nets' pieces: rod bodies and the fan-out bars the
    routing drew onto drivers (the polygons on planes no cell body otherwise uses)."""
    out = set()
    rods = {b.id for p in mech.nets.values() for b in p.bodies}
    for bid, b in mech.body_index().items():
        for i in range(len(b.outline)):
            if bid in rods or (b.poly_layers and b.poly_layers[i] != b.layer):
                out.add((bid, i))
    return out


def same_plane_meetings(design, vals: dict[str, np.ndarray], clearance: float):
    """Pairs of bodies on one plane, not joined to each other, closer than ``clearance`` in
    some state of ``vals``, where at least one is a piece of a net (shapely distances of the
    posed outlines)."""
    mech = design.mechanism
    poses = evaluate(mech, LIB, _types(design), vals)
    joined = _joined(mech)
    net_polys = _net_polygons(mech)
    size = len(next(iter(vals.values())))
    posed = []  # (body, polygon index, plane, xs (n, size), ys (n, size))
    for bid, b in mech.body_index().items():
        for i, poly in enumerate(b.outline):
            px = np.array([p[0] for p in poly])[:, None]
            py = np.array([p[1] for p in poly])[:, None]
            xs, ys = position(b, poses, (px, py))
            posed.append((bid, i, b.layer_of(i), np.broadcast_to(xs, (len(poly), size)),
                          np.broadcast_to(ys, (len(poly), size))))
    found = []
    for k in range(size):
        by_plane: dict[int, list] = {}
        for bid, i, plane, xs, ys in posed:
            by_plane.setdefault(plane, []).append(
                (bid, i, shapely.Polygon(np.column_stack([xs[:, k], ys[:, k]]))))
        for items in by_plane.values():
            for x in range(len(items)):
                for y in range(x + 1, len(items)):
                    (ba, ia, pa), (bb, ib, pb) = items[x], items[y]
                    if ba == bb or frozenset((ba, bb)) in joined:
                        continue
                    if (ba, ia) not in net_polys and (bb, ib) not in net_polys:
                        continue
                    d = pa.distance(pb)
                    if d < clearance - 1e-6:
                        found.append((k, ba, bb, round(d, 3)))
    return found


def _stroke_ends(names: list[str]) -> dict[str, np.ndarray]:
    """The design pose (all at half stroke), then each input at each end of its stroke."""
    rows = [{n: 0.5 for n in names}]
    for n in names:
        for v in (0.0, 1.0):
            rows.append({**{m: 0.5 for m in names}, n: v})
    return {n: np.array([r[n] for r in rows]) for n in names}


@pytest.mark.parametrize("name", ALL)
def test_no_two_parts_of_one_plane_come_within_the_clearance(designs, name):
    _, design, _ = designs[name]
    vals = _stroke_ends(list(design.netlist.inputs))
    assert same_plane_meetings(design, vals, CLEARANCE) == []


def test_the_plane_check_sees_rods_put_on_one_plane(designs):
    """The check above can fail: every rod and fan-out bar of the sorter on one plane."""
    _, design, _ = designs["sorter.bool"]
    bad = copy.deepcopy(design)
    mech = bad.mechanism
    for part in mech.nets.values():
        for b in part.bodies:
            b.layer = 99
    for b in mech.body_index().values():
        if b.poly_layers:
            b.poly_layers = [99 if pl != b.layer else pl for pl in b.poly_layers]
    vals = _stroke_ends(list(bad.netlist.inputs))
    assert same_plane_meetings(bad, vals, CLEARANCE)


@pytest.mark.parametrize("name", ALL)
def test_interconnect_stats_equal_recomputation_from_the_json(designs, name):
    obj, _, _ = designs[name]
    st = obj["stats"]
    total = 0.0
    count = 0
    for _, part, b in _rod_bodies(obj):
        pins = [j for j in part["joints"] if b["id"] in (j["a"], j["b"])]
        (xa, ya), (xb, yb) = (pins[0]["pa"], pins[1]["pa"])
        total += math.hypot(xb - xa, yb - ya)
        count += 1
    assert st["rods"] == count
    assert st["rod_length_mm"] == pytest.approx(total, abs=1e-2)
    assert st["bends"] == 0
    planes = set()
    parts = [c["geometry"] for c in obj["cells"]] + list(obj["mechanism"]["inputs"].values())
    parts += list(obj["mechanism"]["nets"].values())
    for p in parts:
        for b in p["bodies"]:
            planes.update(b.get("poly_layers") or [b["layer"]])
    assert st["planes"] == {"count": len(planes), "used": sorted(planes)}


def _as_massless_rods(obj: dict) -> dict:
    """The design as the previous format wrote it: each net rod a massless ``rod`` joint from
    driver to load, no rod bodies, no routing figures."""
    old = copy.deepcopy(obj)
    for part in old["mechanism"]["nets"].values():
        joints = []
        for b in part["bodies"]:
            jd = next(j for j in part["joints"] if j["b"] == b["id"])
            jl = next(j for j in part["joints"] if j["a"] == b["id"])
            joints.append({"id": b["id"], "kind": "rod", "a": jd["a"], "b": jl["b"],
                           "pa": jd["pa"], "pb": jl["pa"],
                           "length_mm": round(math.dist(jd["pa"], jl["pa"]), 4)})
        part["bodies"], part["joints"] = [], joints
        part["data"].pop("rods", None)
    for k in ("planes", "rods", "rod_length_mm", "bends"):
        old["stats"].pop(k, None)
    return old


def test_a_design_of_the_previous_format_still_proves(designs):
    """Files written before rods were bodies (massless rod joints) still load, solve and
    prove: the kinematic level gives the same outputs as the design with rod bodies."""
    obj, design, spec = designs["sorter.bool"]
    old = _as_massless_rods(obj)
    check_design(old, "old.json")
    legacy = design_from_json(old, "old.json")
    vals = _stroke_ends(list(design.netlist.inputs))
    a = output_signals(design.mechanism, evaluate(design.mechanism, LIB, _types(design), vals))
    b = output_signals(legacy.mechanism, evaluate(legacy.mechanism, LIB, _types(legacy), vals))
    for k in a:
        assert np.allclose(a[k], b[k], atol=1e-9)
    assert prove(legacy, spec, LIB, "kinematic").passed


@pytest.mark.parametrize("seed", range(4))
def test_router_conflict_test_against_brute_force_shifts(seed):
    """``route.conflict`` (rectangles stretched by the sweeps) against shapely distances of the
    two rectangles at 401 relative shifts along x: it says "conflict" exactly when some shift
    brings them within the clearance (up to the grid's step)."""
    from mechc.passes.route import Piece, conflict

    rng = np.random.default_rng(seed)
    for _ in range(150):
        rects = []
        for _ in range(2):
            x0, y0 = rng.uniform(0, 60, 2)
            rects.append((x0, y0, x0 + rng.uniform(1, 30), y0 + rng.uniform(1, 10)))
        sa, sb = rng.uniform(0, 12, 2)
        p = Piece("p", "n1", (rects[0],), (sa, 0.0), True)
        q = Piece("q", "n2", (rects[1],), (sb, 0.0), True)
        a = shapely.box(*rects[0])
        shifts = np.linspace(-(sa + sb), sa + sb, 401)
        d = min(a.distance(shapely.box(rects[1][0] + s, rects[1][1], rects[1][2] + s,
                                       rects[1][3])) for s in shifts)
        step = shifts[1] - shifts[0]
        if conflict(p, q, CLEARANCE):
            assert d < CLEARANCE + step
        else:
            assert d >= CLEARANCE - 1e-9
        # one net: no relative motion, the outlines as they stand
        same = Piece("q", "n1", (rects[1],), (sb, 0.0), True)
        assert conflict(p, same, CLEARANCE) == (a.distance(shapely.box(*rects[1])) < CLEARANCE)


@pytest.mark.parametrize("seed", range(5))
def test_dsatur_colours_properly_and_two_colours_a_bipartite_graph(seed):
    """Every edge gets two colours; DSATUR is exact on bipartite graphs (two colours), and
    never uses more than the largest degree + 1."""
    import networkx as nx

    from mechc.passes.route import dsatur

    rng = np.random.default_rng(seed)
    for g in (nx.gnp_random_graph(60, 0.1, seed=seed),
              nx.bipartite.random_graph(25, 30, 0.15, seed=seed)):
        adj = {str(v): {str(u) for u in g[v]} for v in g}
        order = [str(v) for v in rng.permutation(list(g))]
        col = dsatur(adj, order)
        assert set(col) == set(adj)
        assert all(col[a] != col[b] for a in adj for b in adj[a])
        assert max(col.values()) + 1 <= max(dict(g.degree).values()) + 1
    assert max(col.values()) + 1 <= 2  # the bipartite one
