"""THRESHOLD cell and --map threshold: all 256 functions of three inputs, through the real
mechanism (bodies, joints, the generic closed forms plus the cam follower), and the two
§3.8 examples proven at every level."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from mechc.stdlib.threshold import ThresholdCell, truth_table

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_bool
from mechc.ir.logic_types import evaluate_type
from mechc.ir.mechanism import Demand, SynthContext
from mechc.passes.map import MapOptions, map_equations
from mechc.passes.minimise import minimise
from mechc.physics.evaluate import signal_of
from mechc.threshold.functions import input_matrix, truth_table_from_fv
from tests.threshold.test_threshold_generator import (
    UNAVOIDABLE,
    min_thresholds,
)

LIB = load_library()
CTX = SynthContext()
S = CTX.stroke
MARGIN = 0.05
SAMPLES = 25
X = input_matrix(3)


def spec_text(fv: int) -> str:
    on = [m for m, v in enumerate(truth_table_from_fv(fv)) if v]
    body = f"z = minterms({', '.join(map(str, on))})" if on else "z = 0"
    return f"inputs x1 x2 x3\noutputs z\n{body}\n"


@cache
def mapped(fv: int):
    eq = minimise(parse_bool(spec_text(fv)))
    return map_equations(eq, LIB, MapOptions(target="threshold")).netlist


@cache
def part(fv: int):
    nl = mapped(fv)
    (c,) = nl.cells.values()
    return c, LIB[c.cell].synthesise("c1", CTX, len(c.inputs), c.params, Demand(0.5, 0.5))


def changes():
    """Rest states then all 24 single-input changes (SAMPLES points each), as (3, N)."""
    u = np.linspace(0.0, 1.0, SAMPLES)
    cols, meta = [X.T.astype(float)], []
    for a in range(8):
        for j in range(3):
            b = a ^ (4 >> j)
            x = np.repeat(X[a][:, None].astype(float), SAMPLES, 1)
            x[j] = X[a][j] + (X[b][j] - X[a][j]) * u
            cols.append(x)
            meta.append((a, b, j))
    return np.concatenate(cols, 1), meta


def run(fv: int):
    """Output signal of the cell's mechanism, transmission angles, bad-state count."""
    c, p = part(fv)
    x, meta = changes()
    # the cell's inputs are the function's support, in input order
    names = list(parse_bool(spec_text(fv)).inputs)
    fixed = {p.terminals[pin].body: (x[names.index(net)] - 0.5) * S
             for pin, net in zip(ThresholdCell.input_names(len(c.inputs)), c.inputs)}
    poses = ThresholdCell.kinematics(p, fixed, x.shape[1])
    t = p.terminals["Z"]
    out = signal_of(t, p.body(t.body), poses)
    mu = min(float(np.nanmin(v)) for v in poses.transmission.values())
    bad = sum(int(v.sum()) for v in poses.bad.values())
    return out, meta, mu, bad, poses, p


def test_mapping_of_all_256_functions():
    tt_rows = X.T.astype(bool)
    kinds = {"THRESHOLD": 0, "literal": 0, "constant": 0}
    for fv in range(256):
        tt = truth_table_from_fv(fv)
        nl = mapped(fv)
        got = nl.evaluate({f"x{k + 1}": tt_rows[k] for k in range(3)})[nl.outputs["z"]]
        assert tuple(int(v) for v in got) == tt, fv
        cells = list(nl.cells.values())
        if min_thresholds(fv) == 0:
            assert [c.type for c in cells] == ["CONST"]
            kinds["constant"] += 1
        elif len(cells) == 0 or cells[0].type == "NOT":
            kinds["literal"] += 1
        else:
            (c,) = cells
            assert c.type == "THRESHOLD"
            # the minimum number of thresholds (001 Table II per NPN class, independent)
            assert len(c.params["thresholds"]) == min_thresholds(fv)
            kinds["THRESHOLD"] += 1
    assert kinds == {"THRESHOLD": 248, "literal": 6, "constant": 2}


def test_cell_logic_and_mechanism_read_params_alike():
    # the params' meaning is the logic type's evaluator; the cell builds that function
    for params, want in [({"weights": [1, 1, 1], "thresholds": [1.5], "below": 0}, 23),
                         ({"weights": [-1, 1, 1], "thresholds": [-0.5, 0.5, 1.5], "below": 1},
                          105)]:
        assert truth_table(params, 3) == truth_table_from_fv(want)
        x = X.T.astype(bool)
        assert tuple(int(v) for v in evaluate_type("THRESHOLD", list(x), params, 8)) \
            == truth_table_from_fv(want)


GENERATORS = [fv for fv in range(256) if min_thresholds(fv) > 0
              and len({k for k in range(3) if any(truth_table_from_fv(fv)[m] !=
                                                  truth_table_from_fv(fv)[m ^ (4 >> k)]
                                                  for m in range(8))}) >= 2]
@pytest.mark.parametrize("fv", GENERATORS)
def test_cell_kinematic_proof(fv):
    tt = truth_table_from_fv(fv)
    out, meta, mu, bad, poses, p = run(fv)
    assert bad == 0
    assert np.abs(out[:8] - np.array(tt)).max() <= MARGIN
    paths = out[8:].reshape(len(meta), SAMPLES)
    for (a, b, _j), o in zip(meta, paths):
        assert abs(o[0] - tt[a]) <= MARGIN and abs(o[-1] - tt[b]) <= MARGIN
        if tt[a] == tt[b]:
            assert np.abs(o - tt[a]).max() <= MARGIN, (a, b)
    # every joint's transmission angle >= 45 deg; the cam pair's is 90 - pressure angle,
    # and the cell's limit on the pressure angle is 30 deg
    assert mu >= 45.0
    touch = p.data["threshold"]["touch_joint"]
    assert 90.0 - float(np.nanmin(poses.transmission[touch])) <= 30.0


def test_cured_cells_are_planar_and_keep_their_params():
    # the 24 cured functions: the cell's params are still the minimum threshold realisation
    # (the logic), the mechanism is the planar generator
    for fv in sorted(UNAVOIDABLE):
        c, p = part(fv)
        assert len(c.params["thresholds"]) == min_thresholds(fv)
        assert truth_table(c.params, 3) == truth_table_from_fv(fv)
        info = p.data["threshold"]
        assert info["mechanism"] == "planar" and info["hazards"] == []


def test_part_geometry_is_consistent_at_the_design_pose():
    # rods have their length, and the design pose (all inputs at mid stroke) solves to zero
    # displacement of every body up to the cam
    _, p = part(157)
    for j in p.joints:
        if j.kind == "rod":
            assert np.hypot(j.pb[0] - j.pa[0], j.pb[1] - j.pa[1]) == pytest.approx(j.length)
    names = ThresholdCell.input_names(3)
    fixed = {p.terminals[n].body: np.zeros(1) for n in names}
    poses = ThresholdCell.kinematics(p, fixed, 1)
    for bid, th in poses.theta.items():  # the design pose solves to zero displacement
        if bid != p.data["threshold"]["follower_body"]:
            assert abs(float(th[0])) < 1e-9, bid


@pytest.mark.parametrize("example", ["full_adder.bool", "fv157.bool"])
def test_chapter_iii_examples_pass_every_level(example):
    # 001 §3.8: the full adder (sum FV 105, carry FV 23) and FV 157, compiled with
    # --map threshold, proven at the logic, kinematic and dynamic levels
    from mechc.frontends import load_spec
    from mechc.pipeline import CompileOptions, compile_spec
    from mechc.proofs.dynamic import prove_dynamic
    from mechc.proofs.kinematic import prove_kinematic
    from tests.helpers import EXAMPLES

    d = compile_spec(load_spec(EXAMPLES / example),
                     CompileOptions(map=MapOptions(target="threshold")))
    assert set(d.netlist.count_by_type()) == {"THRESHOLD"}
    assert d.stats["design_checks"]["passed"], d.stats["design_checks"]["failed"]
    assert prove_kinematic(d, d.spec, LIB)["passed"]
    r = prove_dynamic(d, d.spec, LIB, extra=0)
    assert r["passed"], r["failures"]
    assert r["max_position_error_fraction"] <= 0.01


@pytest.mark.parametrize("fv", [157, 6])
def test_contact_arc_meets_the_roller_on_every_change(fv):
    # the dynamic model's contact is only the reachable arc of the cam: at every pose of the
    # kinematic proof the roller (turned with its crank) must touch that polyline, i.e. lie
    # one roller radius from it (chord sag of 0.5 deg segments only), never off its ends
    _, _, _, _, poses, p = run(fv)
    info = p.data["threshold"]
    touch = next(j for j in p.joints if j.id == info["touch_joint"])
    cam, fol = p.body(info["cam_body"]), p.body(info["follower_body"])

    def turn(pts, pivot, th):
        """Points (N, 2) turned by th (N,) about pivot."""
        c, s = np.cos(th), np.sin(th)
        d = pts - np.asarray(pivot, float)
        return np.asarray(pivot) + np.stack([c * d[:, 0] - s * d[:, 1],
                                             s * d[:, 0] + c * d[:, 1]], -1)

    prof = np.asarray(touch.profile)
    th_f, th_c = poses.theta[fol.id], poses.theta[cam.id]
    H = turn(np.broadcast_to(np.asarray(touch.q, float), (len(th_f), 2)), fol.pivot, th_f)
    Hc = turn(H, cam.pivot, -th_c)  # the roller centre in the cam's frame
    a, b = prof[:-1], prof[1:]
    d = b - a
    t = np.clip(((Hc[:, None, :] - a) * d).sum(-1) / (d * d).sum(-1), 0, 1)
    dist = np.linalg.norm(a + t[..., None] * d - Hc[:, None, :], axis=-1).min(1)
    assert np.abs(dist - touch.length).max() < 0.02  # mm
