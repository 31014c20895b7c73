"""The interference check: parts on one plane keep the clearance in every state the design
checks visit. Every example passes; the vectorised measure agrees with a plain per-state,
per-pair shapely loop; designs mutated so that parts meet (at rest, or only part-way along an
input change) are rejected naming both parts; the clearance option decides a 0.7 mm gap."""

from __future__ import annotations

import dataclasses
import json
import textwrap

import numpy as np
import pytest
import shapely
from shapely.ops import nearest_points

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.boolfile import parse_bool
from mechc.ir.mechanism import Body
from mechc.parts.poses import Poses
from mechc.passes.checks import run_design_checks
from mechc.physics.closed_form import position
from mechc.physics.evaluate import evaluate
from mechc.physics.interference import Interference, exempt_pairs
from mechc.pipeline import CompileOptions, compile_spec
from mechc.proofs.kinematic import sweep
from tests.helpers import EXAMPLES

LIB = load_library()
EXAMPLE_FILES = sorted(p for p in EXAMPLES.iterdir() if p.suffix in
                       {".bool", ".pla", ".blif", ".fsm", ".kiss2"})


def failures(design) -> list:
    return [c for c in design.mechanism.checks if c.name == "interference" and not c.passed]


def add_polygon(body: Body, poly: list[tuple[float, float]], layer: int) -> None:
    """A piece on ``body`` on ``layer`` (its other pieces keep their planes)."""
    layers = body.poly_layers or [body.layer] * len(body.outline)
    body.outline.append(poly)
    body.poly_layers = layers + [layer]


def square(x: float, y: float, w: float, h: float) -> list[tuple[float, float]]:
    return [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]


# ---- every example ------------------------------------------------------------------------------

@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_every_example_has_no_interference(path):
    d = compile_spec(load_spec(path), library=LIB)
    assert not failures(d), [c.text() for c in failures(d)]
    summary = d.stats["design_checks"]["interference"]
    assert summary["failed_pairs"] == 0
    assert summary["states"] > 0 and summary["pairs_on_one_plane"] > 0


# ---- a second method: one state, one pair, one shapely call at a time -------------------------

class Keep:
    """Keeps every chunk of poses a sweep solves."""

    def __init__(self):
        self.chunks: list[Poses] = []

    def add(self, poses: Poses) -> None:
        self.chunks.append(poses)


def one_state(poses: Poses, i: int) -> Poses:
    """State ``i`` of ``poses`` alone."""
    def cut(v):
        v = np.asarray(v)
        return v[i:i + 1] if v.size > 1 else v

    return Poses(u={k: cut(v) for k, v in poses.u.items()},
                 theta={k: cut(v) for k, v in poses.theta.items()},
                 xy={k: (cut(v[0]), cut(v[1])) for k, v in poses.xy.items()})


def brute_force(mech, chunks: list[Poses], clearance: float) -> dict[tuple[str, str], float]:
    """Every state, every pair of polygons on one plane (not a pin or groove pair): the signed
    gap (distance, or minus the overlap's width), the least per pair of bodies."""
    exempt = exempt_pairs(mech)
    bodies = mech.body_index()
    best: dict[tuple[str, str], float] = {}
    for poses in chunks:
        n = max(np.size(v) for v in list(poses.u.values()) + list(poses.theta.values()))
        for i in range(n):
            p1 = one_state(poses, i)
            placed = []
            for b in bodies.values():
                if any(np.isnan(np.asarray(d.get(b.id, 0.0))).any()
                       for d in (p1.u, p1.theta)):
                    continue  # an unsolved state (counted by another check)
                static = b.id not in p1.u and b.id not in p1.theta  # nothing moves it
                for k, poly in enumerate(b.outline):
                    pts = poly if static else [tuple(float(c[0]) for c in position(b, p1, v))
                                               for v in poly]
                    placed.append((b.id, b.layer_of(k), shapely.Polygon(pts)))
            for a in range(len(placed)):
                for c in range(a + 1, len(placed)):
                    (ba, la, pa), (bb, lb, pb) = placed[a], placed[c]
                    if ba == bb or la != lb or exempt.get(frozenset((ba, bb))) == "bearing":
                        continue
                    over = pa.intersection(pb).area
                    if over > 0:
                        r = np.asarray(pa.intersection(pb).minimum_rotated_rectangle
                                       .exterior.coords)
                        g = -min(np.hypot(*(r[1] - r[0])), np.hypot(*(r[2] - r[1])))
                    else:
                        g = pa.distance(pb)
                    key = (min(ba, bb), max(ba, bb))
                    best[key] = min(best.get(key, np.inf), g)
    return best


def nudge_into_neighbour(mech, depth: float) -> tuple[str, str]:
    """Move the body of the closest pair of bodies on one plane (at the design pose, not a pin
    or groove pair, not touching by design) ``depth`` mm into the other; returns both ids."""
    exempt = exempt_pairs(mech)
    polys = [(b.id, b.layer_of(k), shapely.Polygon(p), k) for b in mech.body_index().values()
             for k, p in enumerate(b.outline)]
    best = None
    for i, (ba, la, pa, _) in enumerate(polys):
        for bb, lb, pb, _ in polys[i + 1:]:
            if ba != bb and la == lb and frozenset((ba, bb)) not in exempt:
                d = pa.distance(pb)
                if d > 0 and (best is None or d < best[0]):
                    best = (d, ba, bb, pa, pb)
    d, ba, bb, pa, pb = best
    p, q = nearest_points(pa, pb)
    dx, dy = (q.x - p.x) * (d + depth) / d, (q.y - p.y) * (d + depth) / d
    body = mech.body_index()[ba]
    body.outline = [[(x + dx, y + dy) for x, y in poly] for poly in body.outline]
    return ba, bb


def sweep_chunks(design) -> list[Poses]:
    keep = Keep()
    sweep(design, LIB, samples=11, stats=keep)
    return keep.chunks


@pytest.mark.parametrize("source,options", [
    ("full_adder.bool", {}),
    ("toggle.fsm", {}),  # AMPLIFIER: links and rotors, touches on one plane
    ("maj3", {"map": "threshold"}),  # THRESHOLD generator: cams, cranks, planes 10-12
    ("maj3", {"prefer": ("three_bar_and",)}),  # 3-bar gate: links joined by pins
])
def test_vectorised_distances_match_a_plain_loop(source, options):
    if source == "maj3":
        spec = parse_bool("inputs a b c\noutputs m\nm = a & b | a & c | b & c\n")
        opts = CompileOptions()
        opts.map = dataclasses.replace(opts.map, target=options.get("map", "conventional"),
                                       prefer=options.get("prefer", ()))
        d = compile_spec(spec, opts, LIB)
    else:
        d = compile_spec(load_spec(EXAMPLES / source), library=LIB)
    mech = d.mechanism
    moved = nudge_into_neighbour(mech, 2.0)  # so that overlaps are compared too
    chunks = sweep_chunks(d)
    clearance = 4.0  # wide: many pairs measured exactly
    fast = Interference(mech, clearance)
    for c in chunks:
        fast.add(c)
    ref = brute_force(mech, chunks, clearance)
    ids = tuple(sorted(moved))
    assert ref[ids] < 0 and fast.results[ids].gap < 0  # the nudged pair overlaps
    exempt = exempt_pairs(mech)
    limit = {k: (-0.01 if exempt.get(frozenset(k)) == "abut" else clearance) for k in ref}
    near = {k for k, g in ref.items() if g < clearance}
    assert near, "nothing to compare"
    for k in near:  # every pair that comes near is measured exactly
        assert k in fast.results, k
        assert fast.results[k].gap == pytest.approx(ref[k], abs=1e-6), k
    for k, r in fast.results.items():  # elsewhere the fast figure is a lower bound
        assert r.gap <= ref[k] + 1e-9
    assert {k for k, _ in fast.failing()} == {k for k, g in ref.items() if g < limit[k]}


# ---- mutations that must be rejected ------------------------------------------------------------

def test_a_body_moved_into_its_neighbour_fails_naming_both():
    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"), library=LIB)
    assert not failures(d)
    a, b = nudge_into_neighbour(d.mechanism, 1.5)
    run_design_checks(d, LIB)
    bad = failures(d)
    assert [c.where for c in bad] == [" / ".join(sorted((a, b)))]
    assert bad[0].value < 0 and "deep" in bad[0].detail and "mm²" in bad[0].detail
    assert not d.stats["design_checks"]["passed"]


def crossing_not(gap: float, width: float = 2.0):
    """``z = ~a`` with a piece on the input slider and one on the lever's output slider (plane
    0, far above the cell): the two sliders move opposite ways, so the pieces pass each other at
    half stroke — ``gap`` mm apart (negative: overlapping) there, 20 mm apart at rest."""
    d = compile_spec(parse_bool("inputs a\noutputs z\nz = ~a\n"), library=LIB)
    bodies = d.mechanism.body_index()
    a, out = bodies["c1.in_A"], bodies["c1.lever_out"]
    x0, y0 = 150.0, 300.0
    add_polygon(a, square(x0 - width / 2, y0, width, 2.0), 0)
    add_polygon(out, square(x0 - 1.0, y0 + 2.0 + gap, 2.0, 2.0), 0)
    return d


def test_a_collision_only_part_way_along_a_change_is_found_by_the_sweep():
    d = crossing_not(gap=-1.0)
    run_design_checks(d, LIB)
    bad = failures(d)
    assert [c.where for c in bad] == ["c1.in_A / c1.lever_out"]
    assert "during a change" in bad[0].detail and "a at 50 % of its stroke" in bad[0].detail
    # the rest states alone do not see it: the pieces are 20 mm apart at both ends
    rest = Interference(d.mechanism, 1.0)
    types = {c.id: c.cell for c in d.netlist.cells.values()}
    rest.add(evaluate(d.mechanism, LIB, types, {"a": np.array([0.0, 1.0])}))
    assert not rest.failing()
    assert rest.results == {} or min(r.gap for r in rest.results.values()) > 15.0


def test_abutting_faces_may_touch_but_not_overlap():
    d2 = compile_spec(load_spec(EXAMPLES / "full_adder.bool"), library=LIB)
    fast = Interference(d2.mechanism, 1.0)
    for c in sweep_chunks(d2):
        fast.add(c)
    # a lug pushing a bar: the pair abuts (a contact) and their faces meet in some state
    touching = [k for k, r in fast.results.items() if r.limit < 0 and abs(r.gap) < 1e-9]
    assert touching and not fast.failing()
    # push one of them 0.5 mm into the other along the line of their contact
    ba, bb = touching[0]
    body = d2.mechanism.body_index()[ba]
    other = d2.mechanism.body_index()[bb]
    ca = shapely.MultiPolygon([shapely.Polygon(p) for p in body.outline]).centroid
    cb = shapely.MultiPolygon([shapely.Polygon(p) for p in other.outline]).centroid
    sx = 0.5 * np.sign(cb.x - ca.x)
    body.outline = [[(x + sx, y) for x, y in poly] for poly in body.outline]
    run_design_checks(d2, LIB)
    assert [c.where for c in failures(d2)] == [f"{ba} / {bb}"]
    assert "contact faces overrun" in failures(d2)[0].detail


def test_threshold_cranks_sweep_clear_of_each_other():
    """FV 27 (a·c̄ + b·c, weights 3 2 1) with --map threshold: input cranks A and B sweep
    across each other; crank B has a plane of its own. Put it back on A's plane: rejected."""
    spec = parse_bool("inputs a b c\noutputs z\nz = minterms(3, 4, 6, 7)\n")
    opts = CompileOptions()
    opts.map = dataclasses.replace(opts.map, target="threshold")
    d = compile_spec(spec, opts, LIB)
    assert not failures(d)
    bodies = d.mechanism.body_index()
    assert bodies["t1.crank_B"].layer != bodies["t1.crank_A"].layer
    bodies["t1.crank_B"].layer = bodies["t1.crank_A"].layer
    run_design_checks(d, LIB)
    bad = failures(d)
    assert [c.where for c in bad] == ["t1.crank_A / t1.crank_B"]
    assert bad[0].value < -1.0 and "during a change" in bad[0].detail


# ---- through the command line: a user cell, the clearance option -------------------------------

CELL = '''
from mechc.cells.builder import Builder, rect
from mechc.cells.cell import Cell


class CrossingNot(Cell):
    """NOT lever with two pieces that pass each other at half stroke."""

    name = "crossing_not"
    type = "NOT"
    min_inputs = 1
    max_inputs = 1
    description = "test cell: pieces {gap} mm apart at half stroke"

    @classmethod
    def cost(cls, n_inputs):
        return 2  # cheaper than the standard NOT, so the mapper takes it

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, w = ctx.stroke, ctx.bar
        a = b.input_slider("A", 0.0, 0.0, 1.0 * S)
        out, load = b.not_lever("lever", a, 1.0 * S + w, 0.0, demand, 1.2 * S)
        b.output(out, "Z")
        x0, y0 = 40.0, 60.0
        b.extend(a.body, rect(x0 - {half}, y0, x0 + {half}, y0 + 2.0))
        b.extend(out.body, rect(x0 - 1.0, y0 + 2.0 + {gap}, x0 + 1.0, y0 + 4.0 + {gap}))
        return b.finish({{"A": load}})
'''


def user_cell(tmp_path, gap: float, half: float = 1.0):
    cells = tmp_path / "cells"
    cells.mkdir()
    (cells / "crossing_not.py").write_text(textwrap.dedent(CELL).format(gap=gap, half=half))
    spec = tmp_path / "inv.bool"
    spec.write_text("inputs a\noutputs z\nz = ~a\n")
    return cells, spec


@pytest.mark.parametrize("clearance,code", [(None, 1), ("1.0", 1), ("0.5", 0)])
def test_the_clearance_option_decides_a_gap_of_0_7_mm(cli, tmp_path, clearance, code):
    cells, spec = user_cell(tmp_path, gap=0.7)
    out = tmp_path / "inv.json"
    args = ["compile", spec, "--cells", cells, "-o", out]
    if clearance:
        args += ["--clearance", clearance]
    got, stdout, stderr = cli(*args)
    assert got == code, stdout + stderr
    d = json.loads(out.read_text())  # written either way
    assert d["mechanism"]["rules"]["clearance"] == float(clearance or 1.0)
    checks = [c for c in d["mechanism"]["checks"] if c["name"] == "interference"]
    if code:  # the failing pair, with its worst state
        worst = [c for c in checks if c["where"] == "c1.in_A / c1.lever_out"]
        assert len(worst) == 1 and not worst[0]["passed"]
        assert "interference at c1.in_A / c1.lever_out: 0.7 mm" in stdout + stderr
    else:  # passing pairs are one check: the closest of them
        worst = [c for c in checks if "other pairs" in c["where"]]
        assert len(worst) == 1 and worst[0]["passed"]
    assert worst[0]["value"] == pytest.approx(0.7, abs=1e-6)


def test_a_user_cell_whose_parts_overlap_at_rest_is_rejected(cli, tmp_path):
    cells, spec = user_cell(tmp_path, gap=-1.0, half=30.0)  # overlapping whatever the input
    out = tmp_path / "inv.json"
    got, stdout, stderr = cli("compile", spec, "--cells", cells, "-o", out)
    assert got == 1 and out.exists()
    text = stdout + stderr
    assert "interference at c1.in_A / c1.lever_out" in text and "at rest" in text


def test_clearance_out_of_range_is_a_usage_error(cli, tmp_path):
    out = tmp_path / "x.json"
    got, _, err = cli("compile", EXAMPLES / "sorter.bool", "--clearance", "-1", "-o", out)
    assert got == 2 and "--clearance" in err and not out.exists()


def test_pairs_sharing_a_plane_counts_without_listing_pairs():
    """The stats' count of body pairs on one plane, against listing every pair (bodies on one
    plane and bodies on several, as a driver with its fan-out bar is)."""
    import itertools

    from mechc.physics.interference import pairs_sharing_a_plane

    rng = np.random.default_rng(5)
    for _ in range(20):
        layers = [frozenset(int(x) for x in rng.choice(8, size=int(rng.choice([1, 1, 1, 2, 3])),
                                                       replace=False))
                  for _ in range(int(rng.integers(0, 40)))]
        brute = sum(1 for a, b in itertools.combinations(layers, 2) if a & b)
        assert pairs_sharing_a_plane(layers) == brute


@pytest.mark.parametrize("columns", [1, 2, 3])
def test_distinct_poses_are_numpys_unique_rows(columns):
    """A body's distinct poses found by comparing states (few poses) or by sorting (many) are
    exactly ``np.unique``'s: same order, same first state, same state-to-pose map; zeros of
    either sign, unsolved states (inf) and more poses than ``FEW_POSES`` included."""
    from mechc.physics.interference import FEW_POSES, _distinct_rows

    rng = np.random.default_rng(columns)
    for trial in range(60):
        poses = int(rng.integers(1, 2 * FEW_POSES + 2))
        table = rng.choice([-1.5, -0.0, 0.0, 0.25, 2.0, np.inf], size=(poses, columns))
        free = rng.random(table.shape) < 0.5
        table[free] = np.round(rng.normal(size=int(free.sum())), 2)
        key = table[rng.integers(0, poses, size=int(rng.integers(1, 300)))]
        first, inverse = _distinct_rows(key)
        if columns == 1:
            _, f2, i2 = np.unique(key[:, 0], return_index=True, return_inverse=True)
        else:
            _, f2, i2 = np.unique(key, axis=0, return_index=True, return_inverse=True)
        assert np.array_equal(first, f2), trial
        assert np.array_equal(inverse, i2.reshape(-1)), trial
