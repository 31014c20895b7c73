"""The solve order planned once per part and replayed (``mechc.physics.closed_form._Plan``),
and the proof's sweep in chunks of at most ``SOLVE_CHUNK`` states: neither may change a value.

The reference for a replayed solve is the same solve planned afresh (no plan kept); for the
chunking, the same sweep in one chunk."""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest

from mechc.bench.fourbar import mechc_rocker_pins
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.geometry.circles import circle_intersection
from mechc.ir.mechanism import Body, Joint, Part
from mechc.physics import closed_form
from mechc.physics.closed_form import position, solve
from mechc.physics.evaluate import evaluate
from mechc.physics.measures import CheckStats
from mechc.pipeline import compile_spec
from mechc.proofs import kinematic
from tests.helpers import EXAMPLES

LIB = load_library()


def _four_bar(rod: float = 40.0, rocker_pivot: float = 40.0) -> Part:
    """A crank-rocker (crank 10 at +90°, rocker 30): the rocker placed by the rod."""
    a = (0.0, 10.0)
    b = max((circle_intersection((rocker_pivot, 0.0), 30.0, a, rod, s, "four-bar")
             for s in (1, -1)), key=lambda p: p[1])  # the rocker pin above the ground
    b = (float(b[0]), float(b[1]))
    crank = Body("crank", "lever", [[(0.0, 0.0), a, (1.0, 10.0)]], 0.01, pivot=(0.0, 0.0))
    rocker = Body("rocker", "lever", [[(rocker_pivot, 0.0), b]], 0.01,
                  pivot=(rocker_pivot, 0.0))
    return Part([crank, rocker], [Joint("c", "rod", "crank", "rocker", pa=a, pb=b, length=rod)])


def _figures(poses, bodies: list[Body], size: int) -> dict:
    """Every figure a check or a reader takes from the poses, as arrays."""
    out = {f"bad {k}": np.asarray(v) for k, v in poses.bad.items()}
    out.update({f"u {k}": np.asarray(v) for k, v in poses.u.items()})
    out.update({f"theta {k}": np.asarray(poses.theta[k]) for k in poses.theta})
    for name in ("transmission", "singular_margin"):
        angles = getattr(poses, name)
        out.update({f"{name} {k}": np.broadcast_to(angles[k], (size,)) for k in angles})
    for b in bodies:
        if not poses.known(b.id):
            continue
        for poly in b.outline:
            for p in poly:
                out[f"at {b.id} {p}"] = np.stack(np.broadcast_arrays(*position(b, poses, p)))
    return out


def _assert_same(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def _unplanned(monkeypatch) -> None:
    monkeypatch.setattr(closed_form, "_plan_of", lambda *args: None)


def test_a_replayed_solve_equals_a_fresh_one(monkeypatch):
    th = np.linspace(-math.pi, math.pi, 501)  # past both toggles: bad states and NaN
    part = _four_bar(rod=15.0)  # too short for the rocker to follow the crank round
    first = _figures(solve(part, {"crank": th}, th.size), part.bodies, th.size)
    assert closed_form._plan_of(part, {"crank": th}, None) is not None
    again = _figures(solve(part, {"crank": th}, th.size), part.bodies, th.size)
    with monkeypatch.context() as m:
        _unplanned(m)
        fresh = _figures(solve(part, {"crank": th}, th.size), part.bodies, th.size)
    _assert_same(first, again)
    _assert_same(again, fresh)
    assert first["bad rocker"].any() and not first["bad rocker"].all()


def test_each_given_set_has_its_plan():
    part = _four_bar()
    th = np.linspace(-0.3, 0.3, 7)
    by_crank = solve(part, {"crank": th}, th.size)
    by_rocker = solve(part, {"rocker": th}, th.size)  # the crank placed from the rocker
    assert "rocker" in by_crank.theta and "crank" in by_rocker.theta
    plans = closed_form._PLANS[id(part)][1]
    assert {k[0] for k in plans} == {("crank",), ("rocker",)}


def test_a_changed_part_is_planned_again_and_geometry_is_read_every_time():
    th = np.linspace(-1.0, 1.0, 41)
    part = _four_bar()
    before = solve(part, {"crank": th}, th.size).theta["rocker"].copy()
    # a body replaced in the list: the plan held the old one, so it must not be replayed
    moved = _four_bar(rocker_pivot=42.0)
    part.bodies[1] = moved.bodies[1]
    part.joints[0] = moved.joints[0]
    got = solve(part, {"crank": th}, th.size).theta["rocker"]
    want = solve(moved, {"crank": th}, th.size).theta["rocker"]
    np.testing.assert_array_equal(got, want)
    assert np.max(np.abs(got - before)) > 1e-3
    # a dimension changed in place: the plan keeps no geometry, the solve reads it
    part.joints[0].length += 0.5
    longer = solve(part, {"crank": th}, th.size).theta["rocker"]
    ref = _four_bar(rocker_pivot=42.0)
    ref.joints[0].length += 0.5
    np.testing.assert_array_equal(longer, solve(ref, {"crank": th}, th.size).theta["rocker"])
    assert np.max(np.abs(longer - got)) > 1e-3


def test_a_plan_goes_with_its_part():
    part = _four_bar()
    solve(part, {"crank": np.zeros(3)}, 3)
    key = id(part)
    assert key in closed_form._PLANS
    del part
    gc.collect()
    assert key not in closed_form._PLANS


@pytest.mark.parametrize("example", ["full_adder.bool", "sevenseg.bool"])
def test_replayed_cells_equal_fresh_ones(example, monkeypatch):
    """Every cell kind of an example, solved twice through its plan and once without."""
    design = compile_spec(load_spec(EXAMPLES / example))
    mech = design.mechanism
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    names = list(design.netlist.inputs)
    rng = np.random.default_rng(5)
    values = {nm: rng.random(300) for nm in names}

    def every() -> dict:
        poses = evaluate(mech, LIB, types, values)
        return _figures(poses, list(mech.body_index().values()), 300)

    planned, replayed = every(), every()
    with monkeypatch.context() as m:
        _unplanned(m)
        fresh = every()
    _assert_same(planned, replayed)
    _assert_same(replayed, fresh)


def test_the_sweep_chunk_changes_no_figure(monkeypatch):
    """The proof's sweep in chunks of 64 states against one chunk of all: the same output
    signals and the same check figures."""
    design = compile_spec(load_spec(EXAMPLES / "full_adder.bool"))

    def run(chunk: int):
        monkeypatch.setattr(kinematic, "SOLVE_CHUNK", chunk)
        stats = CheckStats(design.mechanism)
        sw = kinematic.sweep(design, LIB, stats=stats)
        return sw, [c.to_json() for c in stats.checks()]

    (small, small_checks), (whole, whole_checks) = run(64), run(10**9)
    assert small_checks == whole_checks and small_checks
    for part in ("rest", "path"):
        assert small[part].keys() == whole[part].keys()
        for o in small[part]:
            np.testing.assert_array_equal(small[part][o], whole[part][o])
    assert len(whole["path"][next(iter(whole["path"]))]) > 64  # it was cut


def test_the_four_bar_peers_solve_the_proofs_chunk():
    from mechc.bench import fourbar

    assert fourbar.CHUNK == kinematic.SOLVE_CHUNK
    th = np.linspace(0.0, 2 * math.pi, 2 * fourbar.CHUNK + 5, endpoint=False)
    whole = mechc_rocker_pins(th)
    parts = np.concatenate([mechc_rocker_pins(th[s:s + fourbar.CHUNK])
                            for s in range(0, th.size, fourbar.CHUNK)])
    np.testing.assert_array_equal(whole, parts)
