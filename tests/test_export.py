"""``mechc export``: every file re-read with its own library (ezdxf, trimesh, csv) and compared
with what the design JSON says, counted and measured here from the JSON alone."""

from __future__ import annotations

import csv
import errno
import json
import math
import os
import subprocess
import sys
from collections import Counter
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import trimesh
from shapely.affinity import rotate, translate
from shapely.geometry import Point, Polygon
from shapely.ops import unary_union

from mechc.backends.frame import MARGIN
from mechc.backends.nest import nest
from mechc.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ["sorter.bool", "majority.pla", "full_adder_net.blif", "sequence_detector.fsm"]
TOL = 0.01  # mm


@pytest.fixture(scope="module")
def designs(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("designs")
    out = {}
    for ex in EXAMPLES:
        path = d / (ex.replace(".", "_") + ".json")
        assert main(["compile", str(ROOT / "examples" / ex), "-o", str(path)]) == 0
        out[ex] = path
    return out


# ---- the reference, from the JSON alone ---------------------------------------------------

def all_parts(obj: dict) -> list[dict]:
    m = obj["mechanism"]
    return ([c["geometry"] for c in obj["cells"] if "geometry" in c] + list(m["inputs"].values())
            + list(m["nets"].values()))


def plates(obj: dict) -> list[tuple[str, int, Polygon]]:
    """(body, plane, outline) of every connected piece of every body on every plane."""
    out = []
    for part in all_parts(obj):
        for b in part["bodies"]:
            layers = b.get("poly_layers") or [b["layer"]] * len(b["outline"])
            for plane in sorted(set(layers)):
                u = unary_union([Polygon(p) for p, k in zip(b["outline"], layers) if k == plane])
                out += [(b["id"], plane, g) for g in getattr(u, "geoms", [u])]
    return out


def pin_points(obj: dict, ctx: dict) -> list[tuple[str, tuple[float, float], float]]:
    """(body, point, diameter) of every pin a body takes: pin joints (both bodies), rod joints
    (each end), lever and rotor pivots."""
    out = []
    for part in all_parts(obj):
        for b in part["bodies"]:
            if b["kind"] in ("lever", "rotor"):
                out.append((b["id"], tuple(b["pivot"]), b.get("pin_diameter_mm",
                                                               ctx["pin_diameter"])))
        for j in part["joints"]:
            d = j.get("pin_diameter_mm", ctx["pin_diameter"])
            if j["kind"] == "pin":
                out += [(j["a"], tuple(j["pa"]), d), (j["b"], tuple(j["pa"]), d)]
            elif j["kind"] == "rod":
                out += [(j["a"], tuple(j["pa"]), d), (j["b"], tuple(j["pb"]), d)]
    return [p for p in out if p[0] != "ground"]


def load(path: Path) -> dict:
    return json.loads(path.read_text())


def export(tmp_path: Path, design: Path, name: str, *extra: str) -> Path:
    out = tmp_path / name
    assert main(["export", str(design), "-o", str(out), *extra]) == 0
    return out


# ---- DXF ----------------------------------------------------------------------------------

def read_dxf(path: Path):
    """Parts (id, plane, layer, placed polygon, placement, sheet), circles, sheet frames."""
    doc = ezdxf.readfile(path)
    msp = doc.modelspace()
    parts, circles, frames = [], [], []
    for e in msp.query("LWPOLYLINE"):
        pts = [(x, y) for x, y, *_ in e.get_points()]
        if e.dxf.layer == "sheets":
            frames.append(Polygon(pts))
        elif e.has_xdata("MECHC"):
            x = [v for _, v in e.get_xdata("MECHC")]
            parts.append({"id": x[0], "plane": x[1], "layer": e.dxf.layer, "poly": Polygon(pts),
                          "angle": x[2], "dx": x[3], "dy": x[4], "sheet": x[5]})
    for c in msp.query("CIRCLE"):
        circles.append((c.dxf.layer, (c.dxf.center.x, c.dxf.center.y), 2 * c.dxf.radius))
    return doc, parts, circles, frames


def unplace(g, p: dict):
    return rotate(translate(g, -p["dx"], -p["dy"]), -p["angle"], origin=(0, 0))


@pytest.mark.parametrize("example", EXAMPLES)
def test_dxf_reproduces_every_outline_per_plane(designs, tmp_path, example):
    obj = load(designs[example])
    out = export(tmp_path, designs[example], "cut.dxf")
    doc, parts, circles, _ = read_dxf(out)
    assert doc.header["$INSUNITS"] == 4 and doc.header["$MEASUREMENT"] == 1  # mm, metric
    ref = plates(obj)
    rods = [j for part in all_parts(obj) for j in part["joints"] if j["kind"] == "rod"]
    rod_ids = {j["id"] for j in rods}
    placed = [p for p in parts if p["layer"] != "frame" and p["id"] not in rod_ids]
    assert Counter(p["plane"] for p in placed) == Counter(k for _, k, _ in ref)
    unused = list(ref)
    for p in placed:
        assert p["layer"] == f"plane {p['plane']}"
        back = unplace(p["poly"], p)
        hit = [r for r in unused if r[1] == p["plane"]
               and abs(r[2].area - back.area) < TOL * back.length
               and r[2].hausdorff_distance(back) < TOL]
        assert hit, f"{p['id']}: no outline of plane {p['plane']} in the design matches it"
        unused.remove(hit[0])
    assert not unused
    # rod joints' links: a bar per rod joint, on a plane above every body's
    links = [p for p in parts if p["id"] in rod_ids]
    assert len(links) == len(rods)
    top = max(k for _, k, _ in ref)
    assert all(p["layer"] == f"plane {p['plane']}" and p["plane"] > top for p in links)
    # holes: every pin a body takes has its hole (no pin without one), at its point, with
    # its diameter
    ctx = obj["mechanism"]["rules"]
    want = Counter()
    for bid, at, d in pin_points(obj, ctx):
        held = [plane for body, plane, g in ref
                if body == bid and g.contains(Point(at).buffer(d / 2))]
        assert held, f"pin at {at} in {bid}: no plate of it holds the hole"
        for plane in held:
            want[(plane, round(at[0], 2), round(at[1], 2), round(d, 3))] += 1
    got = Counter()
    pegs = Counter()
    sliders = {b["id"] for part in all_parts(obj) for b in part["bodies"]
               if b["kind"] == "slider"}
    for layer, c, d in circles:
        owner = [p for p in parts if p["poly"].contains(Point(c))]
        assert len(owner) == 1, f"hole at {c} lies in {len(owner)} parts"
        if owner[0] in links or layer == "frame":
            continue
        q = unplace(Point(c), owner[0])
        key = (owner[0]["plane"], round(q.x, 2), round(q.y, 2), round(d, 3))
        if want[key] > got[key]:
            got[key] += 1
        else:  # not a joint's: the guide peg of a slider (one each, the least pin)
            body = owner[0]["id"].split("@")[0].split("#")[0]
            assert body in sliders and d == pytest.approx(ctx["pin_diameter"]), (body, key)
            pegs[body] += 1
    assert got == want and sum(want.values()) > 0
    assert set(pegs) == sliders  # each slider's peg (twice where two of its planes hold it)


@pytest.mark.parametrize("extra", [(), ("--sheet", "300x200"), ("--by-plane", "--gap", "5")])
def test_dxf_parts_never_overlap_and_stay_on_their_sheet(designs, tmp_path, extra):
    out = export(tmp_path, designs["sequence_detector.fsm"], "cut.dxf", *extra)
    _, parts, _, frames = read_dxf(out)
    gap = float(extra[-1]) if "--gap" in extra else 3.0
    by_sheet: dict[int, list] = {}
    for p in parts:
        by_sheet.setdefault(p["sheet"], []).append(p)
    assert len(frames) == len(by_sheet)
    if "--sheet" in extra:
        assert len(frames) > 1  # a small sheet makes several
    for ps in by_sheet.values():
        frame = [f for f in frames if f.buffer(1e-6).contains(ps[0]["poly"])]
        assert len(frame) == 1
        for p in ps:
            assert frame[0].buffer(1e-6).contains(p["poly"])
        for i, p in enumerate(ps):  # all pairs: independent of the writer's own check
            for q in ps[i + 1:]:
                assert p["poly"].intersection(q["poly"]).area == 0, (p["id"], q["id"])
                assert p["poly"].distance(q["poly"]) >= gap - 1e-6, (p["id"], q["id"])
    if "--by-plane" in extra:  # every sheet holds one plane
        assert all(len({p["layer"] for p in ps}) == 1 for ps in by_sheet.values())


def test_nest_keeps_random_parts_apart():
    """Random turned rectangles and L shapes: no two placed parts within the gap (checked
    pair by pair here), every part on its sheet, each part placed once."""
    rng = np.random.default_rng(7)
    parts = {}
    for i in range(60):
        w, h = rng.uniform(5, 250), rng.uniform(4, 40)
        g = Polygon([(0, 0), (w, 0), (w, h), (0, h)])
        if i % 3 == 0:
            g = g.union(Polygon([(0, 0), (8, 0), (8, 3 * h), (0, 3 * h)]))
        parts[f"p{i}"] = rotate(translate(g, *rng.uniform(-500, 500, 2)), rng.uniform(0, 360))
    res = nest(parts, (400.0, 300.0), 2.0)
    assert set(res.placements) == set(parts)
    placed = [(res.placements[k].sheet, res.placements[k].apply(g)) for k, g in parts.items()]
    for s, g in placed:
        w, h = res.sizes[s]
        assert Polygon([(0, 0), (w, 0), (w, h), (0, h)]).buffer(1e-6).contains(g)
    for i, (s, g) in enumerate(placed):
        for t, q in placed[i + 1:]:
            if s == t:
                assert g.distance(q) >= 2.0 - 1e-6
    for k, g in parts.items():  # a rigid move: same area and same shape
        assert res.placements[k].apply(g).area == pytest.approx(g.area, rel=1e-9)


# ---- 3D ------------------------------------------------------------------------------------

def extent(obj: dict) -> np.ndarray:
    """[[x0, y0, z0], [x1, y1, z1]] mm of every body's plate, from the JSON."""
    ref = plates(obj)
    t = obj["mechanism"]["rules"]["thickness"]
    x0, y0, x1, y1 = unary_union([g for _, _, g in ref]).bounds
    planes = [k for _, k, _ in ref]
    return np.array([[x0, y0, min(planes) * t], [x1, y1, (max(planes) + 1) * t]])


def check_assembly_box(bounds: np.ndarray, obj: dict, links: int) -> None:
    """The assembly spans the layout grown by the frame's border (a stroke, for the parts'
    travel, and the frame's margin), from the base plate one plate under the lowest plane up
    to the top of the bodies' planes, or of the links' planes above them."""
    ext = extent(obj)
    rules = obj["mechanism"]["rules"]
    t = rules["thickness"]
    grow = rules["stroke"] + MARGIN
    pts = np.array([p for p, _ in fixed_points(obj)] + [ext[0][:2], ext[1][:2]])
    np.testing.assert_allclose(bounds[:, :2], [pts.min(0) - grow, pts.max(0) + grow],
                               atol=1e-3)
    assert bounds[0][2] == pytest.approx(ext[0][2] - t, abs=1e-6)
    if links:
        assert ext[1][2] + t - 1e-6 <= bounds[1][2] <= ext[1][2] + links * t + 1e-6
    else:
        assert bounds[1][2] == pytest.approx(ext[1][2], abs=1e-6)


def rod_joints(obj: dict) -> list[dict]:
    return [j for part in all_parts(obj) for j in part["joints"] if j["kind"] == "rod"]


def stops(obj: dict) -> list[dict]:
    return [j for part in all_parts(obj) for j in part["joints"]
            if j["kind"] == "contact" and "ground" in (j["a"], j["b"])]


def fixed_points(obj: dict) -> list[tuple[tuple[float, float], float]]:
    """(point, pin diameter) of every point fixed to the ground that takes a pin: lever and
    rotor pivots, pins, rod ends and groove pins to the ground, springs' ground anchors."""
    rules = obj["mechanism"]["rules"]
    parts = all_parts(obj)
    out = []
    for p in parts:
        for b in p["bodies"]:
            if b["kind"] in ("lever", "rotor"):
                out.append((tuple(b["pivot"]), b.get("pin_diameter_mm", rules["pin_diameter"])))
        for j in p["joints"]:
            if "ground" not in (j["a"], j["b"]):
                continue
            d = j.get("pin_diameter_mm", rules["pin_diameter"])
            if j["kind"] == "pin":
                out.append((tuple(j["pa"]), d))
            elif j["kind"] == "rod":
                out.append((tuple(j["pa"] if j["a"] == "ground" else j["pb"]), d))
            elif j["kind"] == "groove" and j["b"] == "ground":
                out.append((tuple(j["q"]), d))
            elif j["kind"] == "contact":  # a stop: its block's point
                out.append((tuple(j["pa"] if j["a"] == "ground" else j["pb"]), None))
        for sp in p["springs"]:
            if "ground" in (sp["a"], sp["b"]):
                out.append((tuple(sp["pa"] if sp["a"] == "ground" else sp["pb"]),
                            rules["pin_diameter"]))
    return out


@pytest.mark.parametrize("example", ["sorter.bool", "sequence_detector.fsm"])
@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_gltf_parts_are_watertight_and_fill_the_layout(designs, tmp_path, example, suffix):
    obj = load(designs[example])
    out = export(tmp_path, designs[example], "asm" + suffix)
    scene = trimesh.load(out)
    assert isinstance(scene, trimesh.Scene)
    ref = plates(obj)
    links = rod_joints(obj)
    frame = 1 + len(stops(obj))  # the base plate and a block per stop
    assert len(scene.geometry) == len(ref) + len(links) + frame
    assert all(m.is_watertight and m.volume > 0 for m in scene.geometry.values())
    assert len(scene.graph.nodes_geometry) == len(scene.geometry)
    assert sum(k.startswith("frame.") for k in scene.geometry) == frame
    check_assembly_box(scene.bounds * 1000.0, obj, len(links))  # metres
    # each body's part: its outline's area less its holes, times the plate
    t = obj["mechanism"]["rules"]["thickness"]
    rod_ids = {j["id"] for j in links}
    vol = sum(m.volume for k, m in scene.geometry.items()
              if not k.startswith("frame.") and k not in rod_ids) * 1e9
    plate = sum(g.area for _, _, g in ref) * t
    assert 0.97 * plate < vol < plate


def test_stl_assembly_matches_the_layout_and_planes(designs, tmp_path):
    obj = load(designs["sorter.bool"])
    out = export(tmp_path, designs["sorter.bool"], "asm.stl")
    m = trimesh.load(out)
    check_assembly_box(m.bounds, obj, len(rod_joints(obj)))
    glb = trimesh.load(export(tmp_path, designs["sorter.bool"], "asm.glb"))
    assert m.volume == pytest.approx(sum(g.volume for g in glb.geometry.values()) * 1e9,
                                     rel=1e-4)
    # a union of closed, consistently turned surfaces (parts may touch, so no split by
    # edges): every directed edge of a triangle is met once the other way round
    tri = trimesh.load(out, process=False).triangles.round(4)
    edges = Counter()
    for t in tri:
        for i in range(3):
            edges[(tuple(t[i]), tuple(t[(i + 1) % 3]))] += 1
    assert all(edges[(b, a)] == n for (a, b), n in edges.items())


# ---- the frame ----------------------------------------------------------------------------

def frame_dxf(path: Path):
    """The frame's parts (as read_dxf), the base plate's circles and slots put back where the
    design has them: circles (centre, diameter), slots (start, end, width)."""
    doc, parts, circles, _ = read_dxf(path)
    frame = [p for p in parts if p["layer"] == "frame"]
    base = next(p for p in frame if p["id"] == "frame.base")
    holes = []
    for layer, c, d in circles:
        if layer == "frame" and base["poly"].contains(Point(c)):
            q = unplace(Point(c), base)
            holes.append(((q.x, q.y), d))
    slots = []
    for e in doc.modelspace().query("LWPOLYLINE"):
        pts = list(e.get_points())
        if e.dxf.layer != "frame" or e.has_xdata("MECHC") or not any(p[4] for p in pts):
            continue
        (a, b, c, d) = [unplace(Point(p[0], p[1]), base) for p in pts]
        s0 = ((a.x + d.x) / 2, (a.y + d.y) / 2)
        s1 = ((b.x + c.x) / 2, (b.y + c.y) / 2)
        if base["poly"].contains(Point(pts[0][0], pts[0][1])):
            slots.append((s0, s1, a.distance(d)))
    return frame, base, holes, slots


@pytest.mark.parametrize("example", EXAMPLES)
def test_the_frame_holds_every_fixed_point_of_the_design(designs, tmp_path, example):
    """Counted from the JSON: a hole in the base plate at every fixed pivot, ground pin, ground
    rod end and ground spring anchor, with its pin's diameter; a slot per slider along its
    axis, as long as its travel plus the peg, under the slider's plate; a stop block per stop,
    touching the stop's point, clear of the body it stops at rest, screwed through the base
    plate; four mounting holes. The frame's meshes are closed solids."""
    obj = load(designs[example])
    rules = obj["mechanism"]["rules"]
    out = export(tmp_path, designs[example], "cut.dxf")
    frame, base, holes, slots = frame_dxf(out)
    bodies = {b["id"]: b for p in all_parts(obj) for b in p["bodies"]}
    need = [(p, d) for p, d in fixed_points(obj) if d is not None]
    unused = list(holes)
    for at, d in need:
        hit = [h for h in unused if math.dist(h[0], at) < TOL and abs(h[1] - d) < 1e-6]
        assert hit, f"{example}: no hole of {d} mm at {at} in the base plate"
        unused.remove(hit[0])
    # guides: one slot per slider, along its axis, its middle (the peg at rest) in the slider
    S, ot = rules["stroke"], rules["overtravel"]
    sliders = [b for b in bodies.values() if b["kind"] == "slider"]
    assert len(slots) == len(sliders)
    free = list(slots)
    for b in sliders:
        plate = unary_union([Polygon(q) for q in b["outline"]])
        hit = [sl for sl in free if plate.contains(Point((sl[0][0] + sl[1][0]) / 2,
                                                         (sl[0][1] + sl[1][1]) / 2))
               and abs(abs((sl[1][0] - sl[0][0]) * b["axis"][0]
                           + (sl[1][1] - sl[0][1]) * b["axis"][1])
                       - S * (1 + 2 * ot)) < TOL]
        assert hit, f"{example}: no guide slot under {b['id']}"
        assert hit[0][2] == pytest.approx(rules["pin_diameter"], abs=TOL)
        free.remove(hit[0])
    # stops: a block each, touching the stop's point, clear of what it stops at rest
    st = stops(obj)
    blocks = {p["id"]: p for p in frame if p["id"] != "frame.base"}
    assert len(blocks) == len(st)
    ref = plates(obj)
    for j in st:
        blk = blocks[f"frame.stop.{j['id']}"]
        g = unplace(blk["poly"], blk)
        at = j["pa"] if j["a"] == "ground" else j["pb"]
        assert g.exterior.distance(Point(at)) < TOL
        other = j["b"] if j["a"] == "ground" else j["a"]
        mine = [q for body, plane, q in ref if body == other and plane == blk["plane"]]
        # flush is clear: the JSON keeps 4 decimals, so a block flush with its body's plate
        # may overlap it by 0.0001 mm; any overlap deeper than TOL is caught
        assert mine and all(g.buffer(-TOL).intersection(q).area < 1e-6 for q in mine)
        screw = [h for h in unused if g.contains(Point(h[0]))]
        assert len(screw) == 1, j["id"]
        unused.remove(screw[0])
    assert len(unused) == 4  # the mounting holes, one near each corner
    x0, y0, x1, y1 = unplace(base["poly"], base).bounds
    for (x, y), _ in unused:
        assert min(x - x0, x1 - x) < MARGIN and min(y - y0, y1 - y) < MARGIN
    # the frame's meshes are closed solids
    glb = trimesh.load(export(tmp_path, designs[example], "asm.glb"))
    fr = {k: m for k, m in glb.geometry.items() if k.startswith("frame.")}
    assert len(fr) == len(frame) and all(m.is_watertight and m.volume > 0 for m in fr.values())


# ---- BOM -----------------------------------------------------------------------------------

@pytest.mark.parametrize("example", EXAMPLES)
def test_bom_counts_equal_the_design(designs, tmp_path, example):
    obj = load(designs[example])
    out = export(tmp_path, designs[example], "bom.csv")
    rows = list(csv.DictReader(out.open()))
    count = Counter()
    ids = Counter()
    for r in rows:
        count[r["category"]] += int(r["count"])
        assert len(r["ids"].split()) == int(r["count"])
        ids.update((r["category"], i) for i in r["ids"].split())
    assert all(v == 1 for v in ids.values())  # each part on one line, once
    parts = all_parts(obj)
    joints = [j for p in parts for j in p["joints"]]
    bodies = [b for p in parts for b in p["bodies"]]
    springs = {s["id"]: s for p in parts for s in p["springs"]}
    assert count["plate"] == len(plates(obj))
    assert count["link"] == sum(j["kind"] == "rod" for j in joints)
    assert count["spring"] == len(springs)
    assert count["pin"] == (sum(j["kind"] in ("pin", "groove") for j in joints)
                            + 2 * sum(j["kind"] == "rod" for j in joints)
                            + sum(b["kind"] in ("lever", "rotor") for b in bodies)
                            + sum(b["kind"] == "slider" for b in bodies))  # guide pegs
    n_stops = len(stops(obj))
    assert count["frame"] == 1 + n_stops  # the base plate, a block per stop
    assert count["screw"] == 4 + n_stops  # the base plate's four, one per stop block
    assert not [r for r in rows if "no hole" in r["notes"]]
    assert count["actuator"] == len(obj["inputs"])
    assert count["motor"] == sum(b["kind"] == "rotor" for b in bodies)
    assert count["roller"] == sum(j["kind"] == "touch" for j in joints)
    # each plate line: the plane of the parts it lists
    plane_of = Counter()
    for _, k, _ in plates(obj):
        plane_of[k] += 1
    per_plane = Counter()
    for r in rows:
        if r["category"] == "plate":
            per_plane[int(r["plane"])] += int(r["count"])
    assert per_plane == plane_of
    for r in rows:  # every spring line carries the design's figures
        if r["category"] != "spring":
            continue
        for sid in r["ids"].split():
            s = springs[sid]
            assert float(r["rate_N_per_mm"]) == pytest.approx(s["rate_N_per_mm"], abs=1e-6)
            assert float(r["preload_N"]) == pytest.approx(s["preload_N"], abs=1e-4)
            c = s["coil"]
            assert float(r["free_length_mm"]) == pytest.approx(c["free_length_mm"], abs=1e-3)
            assert float(r["wire_mm"]) == c["wire_mm"]
            assert float(r["active_coils"]) == pytest.approx(c["active_coils"], abs=1e-3)
    stroke = obj["mechanism"]["stroke_mm"]
    for r in rows:
        if r["category"] == "actuator":
            name = r["ids"][3:]
            assert float(r["force_N"]) == obj["mechanism"]["actuators"][name]["rated_force_N"]
            assert float(r["stroke_mm"]) == stroke


# ---- the command ---------------------------------------------------------------------------

def test_help_explains_each_format(capsys):
    with pytest.raises(SystemExit) as e:
        main(["export", "--help"])
    assert e.value.code == 0
    text = capsys.readouterr().out
    for fmt in ("dxf", "bom", "stl", "gltf", "svg", "--sheet", "one layer per plane"):
        assert fmt in text


def test_svg_is_the_drawing(designs, tmp_path):
    out = export(tmp_path, designs["sorter.bool"], "d.svg")
    text = out.read_text()
    assert text.startswith("<svg") or text.startswith("<?xml")
    assert "c1" in text


def run_cli(*args: str) -> tuple[int, str]:
    """``mechc ARGS`` in-process: exit status and stderr (argparse's own errors included)."""
    import contextlib
    import io

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(list(args))
        except SystemExit as e:
            code = e.code
    return code, err.getvalue()


BAD = ["missing", "format", "unwritable", "overwrite-input", "not-a-design", "no-format",
       "sheet"]


@pytest.mark.parametrize("case", BAD)
def test_bad_input_exits_2_with_a_clear_message(designs, tmp_path, case):
    design = str(designs["sorter.bool"])
    args = {
        "missing": [str(tmp_path / "nope.json"), "-f", "dxf", "-o", str(tmp_path / "x.dxf")],
        "format": [design, "-f", "pdf", "-o", str(tmp_path / "x.pdf")],
        "unwritable": [design, "-o", str(tmp_path / "no" / "dir" / "x.dxf")],
        "overwrite-input": [design, "-f", "dxf", "-o", design],
        "not-a-design": [str(tmp_path / "bad.json"), "-f", "bom", "-o", str(tmp_path / "x.csv")],
        "no-format": [design, "-o", str(tmp_path / "x.out")],
        "sheet": [design, "-o", str(tmp_path / "x.dxf"), "--sheet", "wide"],
    }[case]
    (tmp_path / "bad.json").write_text('{"format": "other"}')
    before = Path(design).read_bytes()
    code, err = run_cli("export", *args)
    assert code == 2, err
    assert "Traceback" not in err and "error" in err
    expect = {"missing": "nope.json: file not found", "format": "invalid choice: 'pdf'",
              "unwritable": "does not exist", "overwrite-input": "refusing to overwrite",
              "not-a-design": "not a mechc design", "no-format": "--format",
              "sheet": "expected WIDTHxHEIGHT"}[case]
    assert expect in err
    assert not list(tmp_path.glob("x.*"))
    assert Path(design).read_bytes() == before


def test_bad_input_from_the_installed_command_has_no_traceback(tmp_path):
    """The same through the real entry point (one process start: it costs seconds)."""
    p = subprocess.run([sys.executable, "-m", "mechc", "export", str(tmp_path / "nope.json"),
                        "-f", "stl"], capture_output=True, text=True, cwd=tmp_path)
    assert p.returncode == 2
    assert p.stderr.strip() == f"mechc: error: {tmp_path / 'nope.json'}: file not found"


def test_failed_write_leaves_the_old_file_whole(designs, tmp_path, monkeypatch, capsys):
    """A disk that fills while the new file is written: the old file stays as it was, no
    temporary file is left, exit 2 with the reason."""
    out = tmp_path / "cut.dxf"
    out.write_text("the old sheets\n")

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr("mechc.backends.design_json.os.fsync", full)
    for fmt in ("dxf", "stl"):
        assert main(["export", str(designs["sorter.bool"]), "-f", fmt, "-o", str(out)]) == 2
        assert "No space left" in capsys.readouterr().err
        assert out.read_text() == "the old sheets\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cut.dxf"]


def test_spec_is_compiled_in_memory(designs, tmp_path, monkeypatch):
    """A spec instead of a design: compiled first (the same design as ``mechc compile``
    gives, so the same parts list), written to the current directory."""
    monkeypatch.chdir(tmp_path)
    assert main(["export", str(ROOT / "examples" / "majority.pla"), "-f", "bom"]) == 0
    from_json = export(tmp_path, designs["majority.pla"], "from_json.csv")
    assert (tmp_path / "majority.csv").read_text() == from_json.read_text()


def test_no_pin_without_a_hole(designs, tmp_path, capsys):
    """Every pin of every example here has its hole in every body it joins (the bosses), so
    export says nothing of pins without one (all examples: tests/test_bosses.py)."""
    for example, path in designs.items():
        obj = load(path)
        ref = plates(obj)
        missing = [(bid, at) for bid, at, d in pin_points(obj, obj["mechanism"]["rules"])
                   if not any(b == bid and g.contains(Point(at).buffer(d / 2))
                              for b, _, g in ref)]
        assert missing == [], example
    capsys.readouterr()
    export(tmp_path, designs["sorter.bool"], "bom.csv")
    assert "no hole" not in capsys.readouterr().err


def test_preview_draws_the_sheets(designs, tmp_path):
    import matplotlib.image

    out = export(tmp_path, designs["sorter.bool"], "cut.dxf", "--sheet", "1000x600",
                 "--preview", str(tmp_path / "cut.png"))
    img = matplotlib.image.imread(tmp_path / "cut.png")
    h, w = img.shape[:2]
    assert 1.3 < w / h < 2.0  # one 1000 x 600 sheet (the 969 mm base plate fits) and its title
    assert (img[..., :3].sum(axis=2) < 2.5).mean() > 0.01  # lines drawn, not a blank page
    assert out.exists()
    code, err = run_cli("export", str(designs["sorter.bool"]), "-o", str(tmp_path / "a.csv"),
                        "--preview", str(tmp_path / "a.png"))
    assert code == 2 and "goes with --format dxf, stl or gltf" in err
    assert not (tmp_path / "a.csv").exists()


def test_preview_draws_the_assembly(designs, tmp_path):
    """The picture of the assembly: the plane colours are in it, and its proportions are
    those of a long, flat layout seen at a slant."""
    import matplotlib.image

    from mechc.backends.mesh import COLOURS

    export(tmp_path, designs["sorter.bool"], "asm.glb", "--preview", str(tmp_path / "a.png"))
    img = (matplotlib.image.imread(tmp_path / "a.png")[..., :3] * 255).round()
    h, w = img.shape[:2]
    assert w / h > 2  # the sorter is 899 x 206 mm
    planes = {k for _, k, _ in plates(load(designs["sorter.bool"]))}
    for k in planes:  # each plane's colour shows somewhere (lit faces keep it exactly)
        assert (np.abs(img - np.array(COLOURS[k])).sum(axis=2) < 30).any(), k
    code, err = run_cli("export", str(designs["sorter.bool"]), "-o", str(tmp_path / "b.stl"),
                        "--preview", str(tmp_path / "b.svg"))
    assert code == 2 and "expected a .png file" in err


def test_files_are_reproducible_and_the_dxf_audits_clean(designs, tmp_path):
    """Two runs give the same bytes, for the DXF also across Python's string-hash seeds
    (ezdxf's CLASS order follows them unless sorted), and ezdxf's audit finds nothing."""
    design = str(designs["sorter.bool"])
    for i, seed in enumerate(("1", "4")):  # seeds that order them differently
        env = {**os.environ, "PYTHONHASHSEED": seed}
        p = subprocess.run([sys.executable, "-m", "mechc", "export", design, "-o",
                            str(tmp_path / f"{i}.dxf")], capture_output=True, text=True,
                           env=env)
        assert p.returncode == 0, p.stderr
    assert (tmp_path / "0.dxf").read_bytes() == (tmp_path / "1.dxf").read_bytes()
    doc = ezdxf.readfile(tmp_path / "0.dxf")
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes
    for name in ("a.stl", "a.glb", "a.csv"):
        one = export(tmp_path, designs["sorter.bool"], "1" + name).read_bytes()
        assert export(tmp_path, designs["sorter.bool"], "2" + name).read_bytes() == one
