"""Bosses (mechc/passes/bosses.py): every pin of every example has plate round it, on the
plane of the body it joins, with the edge distance of the rule; measured here from the design
JSON with shapely, not with the pass's own helpers."""

from __future__ import annotations

import json

import pytest
from shapely.geometry import LineString, Point, Polygon
from shapely.ops import unary_union

from mechc.backends.design_json import design_from_json, design_to_json
from mechc.backends.fabrication import fabrication
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.ir.mechanism import Body, Joint, Mechanism, Part, SynthContext
from mechc.passes.bosses import add_bosses, boss, boss_radius
from mechc.pipeline import compile_spec
from tests.helpers import EXAMPLES

LIB = load_library()
ALL = sorted(p.name for p in EXAMPLES.iterdir() if p.suffix in (".bool", ".pla", ".blif",
                                                                ".fsm", ".kiss2"))


@pytest.fixture(scope="module")
def designs() -> dict[str, dict]:
    """Every example compiled, as its design JSON."""
    return {n: json.loads(json.dumps(design_to_json(compile_spec(load_spec(EXAMPLES / n),
                                                                 library=LIB))))
            for n in ALL}


def pins_from_json(obj: dict) -> list[tuple[str, tuple, float, tuple | None]]:
    """(body, centre, diameter, slot end) of every pin a body takes, read off the JSON."""
    m = obj["mechanism"]
    ctx = m["rules"]
    parts = ([c["geometry"] for c in obj["cells"] if "geometry" in c]
             + list(m["inputs"].values()) + list(m["nets"].values()))
    out = []
    for part in parts:
        for b in part["bodies"]:
            if b["kind"] in ("lever", "rotor"):
                out.append((b["id"], tuple(b["pivot"]),
                            b.get("pin_diameter_mm", ctx["pin_diameter"]), None))
        for j in part["joints"]:
            d = j.get("pin_diameter_mm", ctx["pin_diameter"])
            if j["kind"] == "pin":
                out += [(j["a"], tuple(j["pa"]), d, None), (j["b"], tuple(j["pa"]), d, None)]
            elif j["kind"] == "rod":
                out += [(j["a"], tuple(j["pa"]), d, None), (j["b"], tuple(j["pb"]), d, None)]
            elif j["kind"] == "groove":
                out += [(j["a"], tuple(j["p0"]), d, tuple(j["p1"])),
                        (j["b"], tuple(j["q"]), d, None)]
    return [p for p in out if p[0] != "ground"]


def plates_by_body(obj: dict) -> dict[str, dict[int, Polygon]]:
    m = obj["mechanism"]
    parts = ([c["geometry"] for c in obj["cells"] if "geometry" in c]
             + list(m["inputs"].values()) + list(m["nets"].values()))
    out: dict[str, dict[int, Polygon]] = {}
    for part in parts:
        for b in part["bodies"]:
            layers = b.get("poly_layers") or [b["layer"]] * len(b["outline"])
            for k in set(layers):
                out.setdefault(b["id"], {})[k] = unary_union(
                    [Polygon(p).buffer(0) for p, q in zip(b["outline"], layers) if q == k])
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", ALL)
def test_every_pin_has_plate_round_it_on_one_plane(designs, name):
    """Each pin's hole, grown by the edge distance (the pin's diameter, at least the plate's
    thickness), lies inside one plane's plate of each body it joins; and the parts list cuts
    a hole for every one of them (no pin without a hole)."""
    obj = designs[name]
    t = obj["mechanism"]["rules"]["thickness"]
    plates = plates_by_body(obj)
    sites = pins_from_json(obj)
    assert sites
    short = []
    for bid, c, d, end in sites:
        need = (Point(c) if end is None else LineString([c, end])).buffer(max(d, t) - 1e-3)
        if not any(g.contains(need) for g in plates[bid].values()):
            short.append((bid, c))
    assert not short, f"{len(short)} pins without plate round them: {short[:4]}"
    fab = fabrication(design_from_json(obj).mechanism)
    assert fab.unholed == []
    holes = sum(len(p.holes) for p in fab.pieces if p.kind != "frame" and p.role != "rod link")
    assert holes >= len(sites)  # each site drilled (a pin may pass several planes of a body)


def test_a_pin_past_the_end_of_a_bar_gets_a_boss_joined_to_it():
    """A slider 30 x 6 mm with a pin 4 mm past its end and one at its edge: two bosses, each
    holding the hole with the edge distance, joined to the bar (one piece per plane), and the
    mass grows by the plate the bosses add."""
    ctx = SynthContext()
    bar = [(0.0, 0.0), (30.0, 0.0), (30.0, 6.0), (0.0, 6.0)]
    b = Body("s", "slider", [bar], ctx.mass([bar]), axis=(1.0, 0.0), layer=2)
    lever = Body("l", "lever", [[(40.0, 0.0), (80.0, 0.0), (80.0, 6.0), (40.0, 6.0)]], 0.0,
                 pivot=(41.0, 3.0), layer=3)
    part = Part(bodies=[b, lever], joints=[Joint("j1", "pin", "ground", "s", pa=(34.0, 3.0)),
                                            Joint("j2", "pin", "ground", "s", pa=(15.0, 6.0))])
    mech = Mechanism(ctx, {"c": part}, {}, {}, {}, {}, ["c"], [])
    m0 = b.mass
    added = add_bosses(mech)
    assert sorted(added) == [("l", 3), ("s", 2), ("s", 2)]
    whole = unary_union([Polygon(p) for p in b.outline])
    assert whole.geom_type == "Polygon"  # joined: one piece
    r = boss_radius(ctx.pin_diameter, ctx)
    assert r == max(ctx.pin_diameter, ctx.thickness)
    for c in ((34.0, 3.0), (15.0, 6.0)):
        assert whole.contains(Point(c).buffer(r - 1e-6))
    assert b.poly_layers is None  # all on its one plane
    extra = whole.area - Polygon(bar).area
    assert b.mass == pytest.approx(m0 + extra * ctx.thickness * ctx.density, rel=1e-6)
    lv = unary_union([Polygon(p) for p in lever.outline])
    assert lv.contains(Point(41.0, 3.0).buffer(r - 1e-6))
    assert add_bosses(mech) == []  # held now: a second run adds nothing


def test_a_pin_held_already_gets_no_boss():
    ctx = SynthContext()
    g = Polygon([(0, 0), (30, 0), (30, 6), (0, 6)])
    assert boss(g, (15.0, 3.0), boss_radius(3.0, ctx)) is None
    assert boss(g, (15.0, 2.0), boss_radius(3.0, ctx)) is not None  # 2 mm from the edge


def test_a_boss_that_would_hit_a_neighbour_goes_on_another_plane():
    """A pin 4 mm past a slider's end where another slider lies on the same plane: the boss
    would overlap it, so it goes on the plane where nothing comes within a stroke (a doubler
    plate), and the slider's first polygon keeps its plane."""
    ctx = SynthContext()
    bar = [(0.0, 0.0), (30.0, 0.0), (30.0, 6.0), (0.0, 6.0)]
    s = Body("s", "slider", [bar], ctx.mass([bar]), axis=(1.0, 0.0), layer=0)
    n = Body("n", "slider", [[(33.0, -10.0), (40.0, -10.0), (40.0, 20.0), (33.0, 20.0)]], 0.0,
             axis=(1.0, 0.0), layer=0)
    far = Body("f", "slider", [[(200.0, 0.0), (230.0, 0.0), (230.0, 6.0), (200.0, 6.0)]], 0.0,
               axis=(1.0, 0.0), layer=1)
    part = Part(bodies=[s, n, far], joints=[Joint("j", "pin", "ground", "s", pa=(34.0, 3.0))])
    mech = Mechanism(ctx, {"c": part}, {}, {}, {}, {}, ["c"], [])
    assert add_bosses(mech) == [("s", 1)]
    assert s.poly_layers == [0, 1]
    g = Polygon(s.outline[1])
    assert g.contains(Point(34.0, 3.0).buffer(boss_radius(ctx.pin_diameter, ctx) - 1e-6))
    assert g.intersects(Polygon(bar))  # it lies over the slider's plate, fastened to it
