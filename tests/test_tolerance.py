"""mechc tolerance: the Monte Carlo yield against perturbed designs proven one by one, the
sensitivity ranking against what a stop and an outline can do, zero and huge tolerances, and
bad input."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from mechc.backends.design_json import design_from_json, design_to_json, dumps, load_design_json
from mechc.cells.sources import library_for_design
from mechc.proofs.kinematic import prove_kinematic
from mechc.tolerance.dimensions import dimensions, perturb
from mechc.tolerance.montecarlo import ToleranceSettings, draw, run, wilson

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


def _compile(spec: str, out: Path, *extra: str) -> Path:
    subprocess.run([sys.executable, "-m", "mechc", "compile", str(EXAMPLES / spec), "-o",
                    str(out), *extra], check=True, capture_output=True)
    return out


def _load(path: Path):
    d = design_from_json(load_design_json(path), str(path))
    return d, library_for_design(d.cell_sources, [], str(path))


@pytest.fixture(scope="module")
def sorter(tmp_path_factory):
    return _compile("sorter.bool", tmp_path_factory.mktemp("tol") / "sorter.json")


@pytest.fixture(scope="module")
def full_adder(tmp_path_factory):
    return _compile("full_adder.bool", tmp_path_factory.mktemp("tol") / "full_adder.json")


def test_yield_agrees_with_designs_proven_one_by_one(sorter, tmp_path):
    """The same draws written as design JSON and proven alone by the kinematic proof: pass or
    fail agrees sample by sample, and the pass fraction sits in the run's interval."""
    design, lib = _load(sorter)
    s = ToleranceSettings(tol=0.1, clearance=0.0, spring_tol=0.1, samples=400, seed=3)
    dims = dimensions(design.mechanism)
    X = draw(dims, s)
    # a design file cannot hold a net rod's length apart from its two pins (the rod is drawn
    # between them), so the nets' dimensions stay nominal in this comparison
    X[:, [k for k, d in enumerate(dims) if d.part.startswith("net:")]] = 0.0
    result = run(design, lib, s, deltas=X)
    assert 0.3 < result.yield_ < 0.95  # a mix of passes and failures to agree on
    n = 30
    alone = []
    for i in range(n):
        one = replace(design, mechanism=perturb(design.mechanism, dims, list(X[i])))
        path = tmp_path / f"sample{i}.json"
        path.write_text(dumps(design_to_json(one)))
        back, lib2 = _load(path)
        alone.append(prove_kinematic(back, back.spec, lib2, tolerance=s.proof_tolerance).passed)
    alone = np.array(alone)
    assert (alone == result.sample_pass[:n]).all(), np.flatnonzero(alone != result.sample_pass[:n])
    lo, hi = wilson(int(alone.sum()), n)
    assert lo <= result.ci[1] and result.ci[0] <= hi  # the two intervals overlap
    # and the command-line proof of one failing and one passing sample says the same
    for want in (True, False):
        i = int(np.flatnonzero(alone == want)[0])
        rc = subprocess.run([sys.executable, "-m", "mechc", "simulate",
                             str(tmp_path / f"sample{i}.json"), "--level", "kinematic"],
                            capture_output=True).returncode
        assert rc == (0 if want else 1)


def test_clearance_bound_covers_rods_at_their_play(sorter, tmp_path):
    """Pin play as lost motion: a run with clearance c loses at least the margin an exact
    design with every rod of the NOT levers c longer or shorter loses (the worst way)."""
    design, lib = _load(sorter)
    c = 0.2
    r = run(design, lib, ToleranceSettings(tol=0.0, clearance=c, spring_tol=0.0, samples=1))
    dims = dimensions(design.mechanism)
    worst = 1.0
    for sign in (-1.0, 1.0):
        delta = [sign * c if d.what == "rod length" else 0.0 for d in dims]
        one = replace(design, mechanism=perturb(design.mechanism, dims, delta))
        rep = prove_kinematic(one, one.spec, lib)
        worst = min(worst, 0.05 - rep.figures["max_deviation_fraction"])
    assert r.nominal_margin_mm["Z"] <= worst * 20.0 + 1e-6


def test_sensitivity_ranks_the_rest_stop_high_and_an_outline_last(sorter):
    design, lib = _load(sorter)
    s = ToleranceSettings(tol=0.1, clearance=0.05, spring_tol=0.1, samples=200)
    r = run(design, lib, s)
    names = [x.dim.name for x in r.ranked]
    effect = {x.dim.name: x.position_mm for x in r.ranked}
    # the output OR bar (c6) rests on its off stop: the frame's face of the stop whose ground
    # side is ``a`` (the bar must stay right of it)
    c6 = design.mechanism.cells["c6"]
    stop = next(j for j in c6.joints if j.kind == "contact" and j.a == "ground"
                and j.b == "c6.bar")
    key = f"{stop.id}.pa.x"
    assert effect[key] == pytest.approx(0.1, abs=1e-6)  # moves the rest 1:1
    # near the top: within 1 % of the largest effect, and only the NOT levers' rods (which
    # the levers amplify by 0.6 %) ahead of it; many dimensions tie with it (every face a bar
    # rests on moves it 1:1)
    top = max(effect.values())
    assert effect[key] >= 0.99 * top
    ahead = [n for n, v in effect.items() if v > effect[key] + 1e-9]
    assert len(ahead) < len(names) // 20 and all(n.split(".")[1].startswith("rod")
                                                  for n in ahead), ahead
    # an outline (plate beyond the pins) and a stop face's coordinate along the face move
    # nothing: ranked after every dimension that does
    for dead in ("c6.bar.outline", f"{stop.id}.pa.y"):
        assert effect[dead] == 0.0
        assert names.index(dead) >= sum(1 for v in effect.values() if v > 0)


@pytest.mark.slow
@pytest.mark.parametrize("spec,extra", [("sorter.bool", ()), ("full_adder.bool", ()),
                                        ("full_adder.bool", ("--map", "threshold")),
                                        ("comparator2.bool", ()), ("majority.pla", ())])
def test_zero_tolerance_yields_one_and_nominal_margins(spec, extra, tmp_path):
    path = _compile(spec, tmp_path / "d.json", *extra)
    design, lib = _load(path)
    r = run(design, lib, ToleranceSettings(tol=0.0, clearance=0.0, spring_tol=0.0, samples=16))
    assert r.yield_ == 1.0
    rep = prove_kinematic(design, design.spec, lib)
    stroke = design.mechanism.ctx.stroke
    assert min(r.nominal_margin_mm.values()) == pytest.approx(
        (0.05 - rep.figures["max_deviation_fraction"]) * stroke, abs=1e-6)
    huge = run(design, lib, ToleranceSettings(tol=3.0, clearance=0.5, spring_tol=0.5,
                                              samples=64))
    assert huge.yield_ < 0.2


def test_cli_report_and_chart(sorter, tmp_path, cli):
    rep, png = tmp_path / "r.json", tmp_path / "s.png"
    code, out, err = cli("tolerance", sorter, "--samples", "60", "--json", rep, "--chart", png)
    assert code in (0, 1)
    doc = json.loads(rep.read_text())
    assert doc["samples"] == 60 and doc["passed"] == round(doc["yield"] * 60)
    assert doc["yield_ci95"][0] <= doc["yield"] <= doc["yield_ci95"][1]
    assert code == (0 if doc["yield"] >= 0.99 else 1)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import matplotlib.image as mpimg
    assert mpimg.imread(png).shape[0] > 100
    code, out, _ = cli("tolerance", sorter, "--process", "cnc", "--samples", "20")
    assert "+-0.05 mm, pin clearance 0.02 mm" in out


@pytest.mark.parametrize("args,msg", [
    (("--tol", "-1"), "--tol must be"),
    (("--spring-tol", "1.5"), "--spring-tol"),
    (("--yield", "1.5"), "--yield"),
    (("--process", "wood"), "invalid choice"),
    (("--samples", "0"), "at least 1"),
])
def test_bad_options_exit_2(sorter, cli, capsys, args, msg):
    try:
        code, out, err = cli("tolerance", sorter, *args)
    except SystemExit as e:  # argparse refuses the option itself
        code, err = e.code, capsys.readouterr().err
    assert code == 2 and msg in err


def test_bad_files_exit_2(sorter, tmp_path, cli):
    code, _, err = cli("tolerance", tmp_path / "missing.json")
    assert code == 2 and "missing.json" in err
    code, _, err = cli("tolerance", EXAMPLES / "sorter.bool")
    assert code == 2 and "compiled design" in err
    code, _, err = cli("tolerance", sorter, "--json", sorter)
    assert code == 2 and "refusing to overwrite" in err
    before = sorter.read_bytes()
    assert sorter.read_bytes() == before


@pytest.mark.slow
def test_robust_compile_meets_the_yield_it_reports(tmp_path, cli):
    """mechc compile --tol 0.1 --yield 0.99 on the sorter: what it writes reaches the yield in
    an independent run (another seed, more samples), and it says what it changed."""
    out = tmp_path / "robust.json"
    code, text, err = cli("compile", EXAMPLES / "sorter.bool", "-o", out, "--tol", "0.1",
                          "--yield", "0.99", "--tol-samples", "1000")
    assert code == 0, err
    assert "target met" in text and "spring margin 1.3 ->" in text
    design, lib = _load(out)
    assert design.mechanism.ctx.margin > 1.3  # written into the design's rules
    r = run(design, lib, ToleranceSettings(tol=0.1, clearance=0.05, spring_tol=0.1,
                                           samples=3000, seed=11))
    assert r.ci[1] >= 0.99 and r.yield_ >= 0.985


@pytest.mark.slow
def test_sequential_samples_agree_with_their_walks_proven_one_by_one(tmp_path):
    """A sequential design (the toggle): the samples' walks proven together agree, sample by
    sample, with each perturbed design written as JSON and proven alone by the kinematic
    sequential proof; at zero tolerance every sample passes."""
    from mechc.proofs import ProofSettings, prove

    path = _compile("toggle.fsm", tmp_path / "toggle.json")
    design, lib = _load(path)
    zero = run(design, lib, ToleranceSettings(tol=0.0, clearance=0.0, spring_tol=0.0,
                                              samples=8))
    assert zero.yield_ == 1.0
    s = ToleranceSettings(tol=0.3, clearance=0.0, spring_tol=0.0, samples=24, seed=2)
    dims = dimensions(design.mechanism)
    X = draw(dims, s)
    X[:, [k for k, d in enumerate(dims) if d.part.startswith("net:")]] = 0.0
    result = run(design, lib, s, deltas=X)
    alone = []
    for i in range(len(X)):
        one = replace(design, mechanism=perturb(design.mechanism, dims, list(X[i])))
        f = tmp_path / f"s{i}.json"
        f.write_text(dumps(design_to_json(one)))
        back, lib2 = _load(f)
        alone.append(prove(back, back.spec, lib2, "kinematic",
                           ProofSettings(tolerance=0.05)).passed)
    # the sequential proof does not measure springs: with them nominal none fails here, so
    # pass or fail is the walks' alone
    assert "spring force margin" not in result.fails
    assert (np.array(alone) == result.sample_pass).all()
    assert 0 < result.passed < len(X)  # some of each


# ---- dimensions of the cells' own kinematics: cam pairs, a MEMORY's throw, toggle stops -----

@pytest.fixture(scope="module")
def threshold_fa(tmp_path_factory):
    return _compile("full_adder.bool", tmp_path_factory.mktemp("tol") / "fa_thr.json",
                    "--map", "threshold")


def _rest_poses(design, lib, mech):
    from mechc.physics.evaluate import evaluate
    from mechc.proofs.cases import bits

    names = list(design.spec.inputs)
    x = bits(np.arange(1 << len(names), dtype=np.int64), len(names)).astype(float)
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    return evaluate(mech, lib, types, {n: x[k] for k, n in enumerate(names)})


def _angle_at(zk, arm, r):
    """The angle at Z between ZK and ZH with |KH| = r (law of cosines)."""
    return np.arccos((zk ** 2 + arm ** 2 - r ** 2) / (2 * zk * arm))


def test_cam_profile_error_is_sampled_and_agrees_with_the_exact_dwell(threshold_fa):
    """The threshold generators' cam outlines (radial error per program segment) and rollers
    are dimensions of the sample set; a uniform radial error e turns the follower, on a dwell
    (the pitch curve a circle about K there), by what the exact meeting of the circles about K
    (radius rho + 2e: cam and roller each e larger) and Z gives, to first order."""
    design, lib = _load(threshold_fa)
    dims = dimensions(design.mechanism)
    cam = [k for k, d in enumerate(dims) if d.what in ("cam profile", "roller radius")]
    assert {dims[k].owner for k in cam} == {"t1", "t2"} and len(cam) >= 6
    X = draw(dims, ToleranceSettings(samples=4))
    assert (X[:, cam] != 0).all()
    e = 0.05
    delta = np.zeros(len(dims))
    delta[cam] = e
    nominal = _rest_poses(design, lib, design.mechanism)
    moved = _rest_poses(design, lib, perturb(design.mechanism, dims, list(delta)))
    for cid in ("t1", "t2"):
        part = design.mechanism.cells[cid]
        info = part.data["threshold"]
        fol = next(b for b in part.bodies if b.id == info["follower_body"])
        cam_b = next(b for b in part.bodies if b.id == info["cam_body"])
        touch = next(j for j in part.joints if j.id == info["touch_joint"])
        Z, K, H = (np.asarray(v) for v in (fol.pivot, cam_b.pivot, touch.q))
        th0 = nominal.theta[fol.id]
        th1 = moved.theta[fol.id]
        c, s = np.cos(th0), np.sin(th0)
        hx = Z[0] + c * (H[0] - Z[0]) - s * (H[1] - Z[1])  # the roller's centre at rest
        hy = Z[1] + s * (H[0] - Z[0]) + c * (H[1] - Z[1])
        kt = nominal.theta[cam_b.id]  # K -> roller in the cam's frame: the dwell's radius
        rho = np.hypot(hx - K[0], hy - K[1])
        arm, zk = np.hypot(*(H - Z)), np.hypot(*(K - Z))

        exact = np.abs(_angle_at(zk, arm, rho + 2 * e) - _angle_at(zk, arm, rho))
        assert np.isfinite(kt).all()
        got = np.abs(th1 - th0)
        assert (exact > 1e-3).all()
        np.testing.assert_allclose(got, exact, rtol=0.05)


def test_a_large_cam_error_fails_the_threshold_adder_and_a_tiny_one_does_not(threshold_fa):
    design, lib = _load(threshold_fa)
    dims = dimensions(design.mechanism)
    verdict = {}
    for e in (0.005, 0.3):
        delta = [e if d.what == "cam profile" else 0.0 for d in dims]
        one = replace(design, mechanism=perturb(design.mechanism, dims, delta))
        verdict[e] = prove_kinematic(one, one.spec, lib).passed
    assert verdict == {0.005: True, 0.3: False}
    r = run(design, lib, ToleranceSettings(tol=0.1, clearance=0.0, spring_tol=0.0,
                                           samples=8))
    effect = {x.dim.name: x.position_mm for x in r.ranked}
    # a cam pair's radial error reaches the output through the follower's short arm:
    # amplified (over 3 x), far above a separator link's end
    assert effect["t2.cam.r1"] > 3 * 0.1


@pytest.fixture(scope="module")
def speedctl(tmp_path_factory):
    return _compile("speedctl.fsm", tmp_path_factory.mktemp("tol") / "speedctl.json")


def _cell_output(lib, types, part, cid, fixed, out, state=None):
    poses = lib[types[cid]].kinematics(part, fixed, 1, state)
    return float(np.asarray(poses.u[part.terminals[out].body]).reshape(-1)[0])


@pytest.mark.parametrize("cell", ["memory", "amplifier"])
def test_a_stop_cut_off_moves_the_throw_it_sets(speedctl, cell):
    """A MEMORY's throw angle and an AMPLIFIER's toggle angles are set by stops on the frame:
    those stops are dimensions of the sample set, and a stop cut 0.3 mm off moves the output at
    rest by what the lever's arms give (MEMORY: the face's 0.3 mm at radius a becomes rq/a of
    it at the output pin; AMPLIFIER: the stop catches the crank pin itself, 1:1)."""
    design, lib = _load(speedctl)
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    cid = next(c for c, t in types.items() if t == cell)
    part = design.mechanism.cells[cid]
    dims = dimensions(design.mechanism)
    lever = next(b for b in part.bodies if b.kind == "lever"
                 and any(j.kind == "contact" and j.a == "ground" and j.b == b.id
                         for j in part.joints))
    stop_i, stop = next((i, j) for i, j in enumerate(part.joints)
                        if j.kind == "contact" and j.a == "ground" and j.b == lever.id
                        and j.normal[0] < 0)  # the stop of the "on" side
    name = f"{stop.id}.pa.x"
    assert name in [d.name for d in dims]
    S = design.mechanism.ctx.stroke
    ins, out = (("S", "R"), "Q") if cell == "memory" else (("A",), "Z")
    # MEMORY: S and R off, the lever on (held by its detent); AMPLIFIER: input on
    fixed = {part.terminals[n].body: np.array([S / 2 if cell == "amplifier" else -S / 2])
             for n in ins}
    state = None if cell == "amplifier" else np.array([1.0])  # on, held by the detent
    h = 0.3
    moved = perturb_one(part, stop_i, h)
    du = _cell_output(lib, types, moved, cid, fixed, out, state) - _cell_output(
        lib, types, part, cid, fixed, out, state)
    if cell == "memory":
        a = stop.pb[1] - lever.pivot[1]
        rod = next(j for j in part.joints if j.kind == "rod")
        rq = rod.pa[1] - lever.pivot[1]
        want = h * rq / a
    else:
        want = h
    assert du == pytest.approx(want, rel=0.05), (du, want)


def perturb_one(part, i, h):
    """The part with joint ``i``'s ``pa`` moved by ``h`` along x."""
    joints = list(part.joints)
    j = joints[i]
    joints[i] = replace(j, pa=(j.pa[0] + h, j.pa[1]))
    return replace(part, joints=joints)


@pytest.mark.slow
def test_sequential_pin_play_covers_rods_at_their_play(tmp_path):
    """Sequential designs get pin play and structural error as combinational ones do: the
    lost motion from the finite differences along the walks covers the toggle made with every
    rod of its cells c longer and c shorter, each proven exactly by the sequential kinematic
    proof."""
    from mechc.proofs import ProofSettings, prove

    path = _compile("toggle.fsm", tmp_path / "toggle.json")
    design, lib = _load(path)
    c = 0.2
    r = run(design, lib, ToleranceSettings(tol=0.0, clearance=c, spring_tol=0.0, samples=1))
    assert r.structural and all(e.lost_mm > 0 for e in r.structural)
    dims = dimensions(design.mechanism)
    worst = 1.0
    for sign in (-1.0, 1.0):
        delta = [sign * c if d.what == "rod length" else 0.0 for d in dims]
        one = replace(design, mechanism=perturb(design.mechanism, dims, delta))
        rep = prove(one, one.spec, lib, "kinematic", ProofSettings(tolerance=0.05))
        worst = min(worst, 0.05 - rep.figures["max_deviation_fraction"])
    stroke = design.mechanism.ctx.stroke
    assert min(r.nominal_margin_mm.values()) <= worst * stroke + 1e-5
    # and the play costs margin: without it the nominal margin is larger
    r0 = run(design, lib, ToleranceSettings(tol=0.0, clearance=0.0, spring_tol=0.0, samples=1))
    assert min(r0.nominal_margin_mm.values()) > min(r.nominal_margin_mm.values()) + 0.01


def test_interference_bound_holds_on_perturbed_designs(full_adder):
    """The interference bound: for every pair held to a gap at nominal and every sample, the
    gap the interference check measures on that sample's design (its own poses in every
    proof state, its outlines cut larger or smaller) is at least the bound; and a large
    tolerance puts the pairs closest at nominal at risk (the full adder: the sorter's cells,
    placed near what they connect to, stay clear of each other at this tolerance)."""
    from mechc.physics.evaluate import evaluate
    from mechc.physics.interference import Interference
    from mechc.tolerance.clearance import Risk
    from mechc.tolerance.montecarlo import nominal_gaps, prepare

    design, lib = _load(full_adder)
    s = ToleranceSettings(tol=0.4, clearance=0.0, spring_tol=0.0, samples=24, seed=5)
    batch, _ = prepare(design, lib, s)
    X = draw(batch.dims, s)
    X[:, [k for k, d in enumerate(batch.dims) if d.part.startswith("net:")]] = 0.0
    res = batch.run(X)
    risk = Risk(design.mechanism)
    risk.add(res.moves, len(X))
    bounds = risk.bounds(nominal_gaps(batch, risk, s), s.tol, s.clearance, len(X))
    # some samples at risk (a finite bound below zero; a sample that cannot assemble in some
    # state has infinite moves: -inf, at risk, and fails its proof anyway)
    assert bounds and any((np.isfinite(b) & (b < 0)).any() for _, _, b in bounds.values())
    st = batch.states
    values = {n: st.values[k] for k, n in enumerate(st.names)}
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    checked = 0
    for i in range(len(X)):
        mech = perturb(design.mechanism, batch.dims, list(X[i]))
        poses = evaluate(mech, lib, types, values)
        inter = Interference(mech, clearance=10.0)
        inter.add(poses)
        got = inter.results
        for pair, (_, _, b) in bounds.items():
            if pair in got and np.isfinite(b[i]):
                assert got[pair].gap >= b[i] - 1e-6, (pair, got[pair].gap, b[i])
                checked += 1
    assert checked >= 3


def test_sequential_run_has_play_structural_error_and_ranking(tmp_path):
    """A sequential design's run (the gated latch): pin play at its outputs, a structural
    error per output, and dimensions ranked by their finite differences (the MEMORY's and
    the gates' stops move its output at rest 1:1)."""
    path = _compile("gated_latch.fsm", tmp_path / "latch.json")
    design, lib = _load(path)
    r = run(design, lib, ToleranceSettings(tol=0.1, clearance=0.05, spring_tol=0.1,
                                           samples=16))
    assert r.samples == 16 and r.structural
    assert all(e.lost_mm > 0 and e.spread_mm[0] <= 0 <= e.spread_mm[1] for e in r.structural)
    assert r.ranked[0].position_mm >= 0.09
    assert r.ranked[-1].position_mm == 0.0


@pytest.mark.slow
def test_angle_margin_gives_the_threshold_generators_their_angle():
    """What robust design asks of the threshold generators (the design rule angle_margin):
    the separators synthesised for 45 deg + the margin, so the design's transmission angle
    check reads at least that, and the rule is written with the design."""
    from mechc.cells.library import load_library
    from mechc.frontends import load_spec
    from mechc.passes.assemble import MechOptions
    from mechc.passes.map_sop import MapOptions
    from mechc.pipeline import CompileOptions, compile_spec

    spec = load_spec(EXAMPLES / "full_adder.bool")
    lib = load_library()
    angle = {}
    for margin in (0.0, 5.0):
        d = compile_spec(spec, CompileOptions(map=MapOptions(target="threshold"),
                                              mech=MechOptions(angle_margin=margin)), lib)
        gen = {c.id for c in d.netlist.cells.values() if c.cell == "threshold"}
        assert gen
        angle[margin] = min(c.value for c in d.mechanism.checks
                            if c.name == "transmission angle"
                            and c.where in gen)
        assert design_to_json(d)["mechanism"]["rules"]["angle_margin"] == margin
    assert angle[0.0] == pytest.approx(45.01, abs=0.02)
    assert angle[5.0] >= 50.0


def test_threshold_samples_agree_with_their_json_proven_one_by_one(threshold_fa, tmp_path):
    """The cam pairs' errors travel with a design written as JSON (the cell's
    ``profile_error``): perturbed threshold adders proven one by one by the kinematic proof
    pass or fail as the run's samples do."""
    design, lib = _load(threshold_fa)
    s = ToleranceSettings(tol=0.03, clearance=0.0, spring_tol=0.0, samples=16, seed=4)
    dims = dimensions(design.mechanism)
    X = draw(dims, s)
    X[:, [k for k, d in enumerate(dims) if d.part.startswith("net:")]] = 0.0
    result = run(design, lib, s, deltas=X)
    alone = []
    for i in range(len(X)):
        one = replace(design, mechanism=perturb(design.mechanism, dims, list(X[i])))
        path = tmp_path / f"t{i}.json"
        path.write_text(dumps(design_to_json(one)))
        back, lib2 = _load(path)
        assert "profile_error" in back.mechanism.cells["t1"].data["threshold"]
        alone.append(prove_kinematic(back, back.spec, lib2, tolerance=s.proof_tolerance).passed)
    alone = np.array(alone)
    assert (alone == result.sample_pass).all(), np.flatnonzero(alone != result.sample_pass)
    assert 0 < alone.sum() < len(alone)  # some of each


def test_spring_rate_and_preload_are_sampled_and_a_weak_spring_fails(sorter):
    """Springs: every spring's rate and preload are dimensions; one spring 20 % weak in both
    fails its force margin (1.3 x 0.8 x 0.8 = 0.83 < 1.15) and nothing else."""
    design, lib = _load(sorter)
    dims = dimensions(design.mechanism)
    springs = [k for k, d in enumerate(dims) if d.what in ("spring rate", "spring preload")]
    assert len(springs) == 2 * sum(len(p.springs) for p in design.mechanism.all_parts())
    k_rate = next(k for k in springs if dims[k].what == "spring rate"
                  and dims[k].owner == "c6")
    sid = dims[k_rate].name.split(" ")[0]
    k_pre = next(k for k in springs if dims[k].name == f"{sid} preload")
    X = np.zeros((2, len(dims)))
    X[1, [k_rate, k_pre]] = -0.2
    r = run(design, lib, ToleranceSettings(tol=0.0, clearance=0.0, spring_tol=0.2,
                                           samples=2), deltas=X)
    assert list(r.sample_pass) == [True, False]
    assert [f.key.where for f in r.failing] == [sid]
    assert r.failing[0].worst == pytest.approx(1.3 * 0.8 * 0.8, rel=0.1)
