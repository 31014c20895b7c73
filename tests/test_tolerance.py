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
