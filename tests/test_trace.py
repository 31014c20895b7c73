"""``mechc simulate --trace``: the pose trace validates against its shipped schema, holds every
body and every case of the proof, and its poses, applied to the outlines and terminals it
carries, agree with independent references (the spec's output values at the kinematic level,
the closed form at the dynamic level)."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import jsonschema
import numpy as np
import pytest

from mechc.backends.design_json import design_from_json, load_design_json
from mechc.cells.library import load_library
from mechc.errors import UsageError
from mechc.ir.mechanism import GROUND
from mechc.parts.base import position
from mechc.physics.evaluate import evaluate
from mechc.proofs import ProofSettings, prove
from mechc.proofs.trace import TraceRecorder, schema
from tests.helpers import EXAMPLES, ROOT

SORTER = EXAMPLES / "sorter.bool"


@pytest.fixture(scope="module")
def sorter_json(tmp_path_factory):
    from mechc.cli.main import main

    out = tmp_path_factory.mktemp("trace") / "sorter.json"
    assert main(["compile", str(SORTER), "-o", str(out)]) == 0
    return out


def posed(body: dict, pose: list, p) -> tuple[float, float]:
    """Where design point ``p`` of ``body`` stands at ``pose``: the formula of docs/trace.md,
    from the trace's own numbers."""
    dx, dy, a = pose
    rx, ry = body["ref"]
    c, s = np.cos(a), np.sin(a)
    x, y = p[0] - rx, p[1] - ry
    return c * x - s * y + rx + dx, s * x + c * y + ry + dy


def signal(trace: dict, terminal: dict, poses: list) -> float:
    """A terminal's signal (0 off, 1 on) at one sample of a trace."""
    i = next(k for k, b in enumerate(trace["bodies"]) if b["id"] == terminal["body"])
    x, y = posed(trace["bodies"][i], poses[i], terminal["point"])
    (ox, oy), (nx, ny) = terminal["off"], terminal["on"]
    dx, dy = nx - ox, ny - oy
    return ((x - ox) * dx + (y - oy) * dy) / (dx * dx + dy * dy)


def rod_stretch(trace: dict, design_json: dict, poses: list) -> float:
    """Largest change of length (mm) of any rod of the design with its ends posed by one
    sample of the trace: the geometry's own check that the poses are a rigid motion."""
    rods = [j for c in design_json["cells"] for j in c["geometry"]["joints"]]
    rods += [j for p in design_json["mechanism"]["nets"].values() for j in p["joints"]]
    rods = [j for j in rods if j["kind"] == "rod"]
    assert rods
    row = {b["id"]: k for k, b in enumerate(trace["bodies"])}

    def at(bid, p):
        if bid == GROUND:
            return p
        return posed(trace["bodies"][row[bid]], poses[row[bid]], p)

    worst = 0.0
    for j in rods:
        (ax, ay), (bx, by) = at(j["a"], j["pa"]), at(j["b"], j["pb"])
        worst = max(worst, abs(float(np.hypot(bx - ax, by - ay)) - j["length_mm"]))
    return worst


def validate(trace: dict) -> None:
    jsonschema.Draft202012Validator(schema()).validate(trace)


def design_body_ids(design_json: dict) -> set[str]:
    ids = {b["id"] for c in design_json["cells"] for b in c["geometry"]["bodies"]}
    mech = design_json["mechanism"]
    for group in ("inputs", "nets"):
        ids |= {b["id"] for part in mech[group].values() for b in part.get("bodies", [])}
    return ids


def run_trace(cli, tmp_path, design, *opts):
    trace, report = tmp_path / "trace.json", tmp_path / "report.json"
    code, out, err = cli("simulate", design, "--trace", trace, "--report", report, *opts)
    return code, json.loads(trace.read_text()), json.loads(report.read_text())


def test_kinematic_trace_rest_poses_put_outputs_where_the_spec_says(cli, tmp_path,
                                                                     sorter_json):
    code, trace, report = run_trace(cli, tmp_path, sorter_json, "--level", "kinematic")
    assert code == 0
    validate(trace)
    assert {b["id"] for b in trace["bodies"]} == design_body_ids(json.loads(
        sorter_json.read_text()))
    assert len({b["id"] for b in trace["bodies"]}) == len(trace["bodies"])
    rest = [c for c in trace["cases"] if c["kind"] == "rest"]
    changes = [c for c in trace["cases"] if c["kind"] == "change"]
    assert len(rest) == report["cases"] == 16
    assert len(changes) == report["transitions"]
    tol = report["tolerance_fraction"]
    seen = set()
    for c in rest:
        for o, want in c["expected_after"].items():
            got = signal(trace, trace["terminals"]["outputs"][o], c["poses"][-1])
            if want is not None:
                seen.add(want)
                assert abs(got - want) <= tol, (c["inputs_after"], o, got)
        for name, v in c["inputs_after"].items():  # the inputs stand where they were put
            assert signal(trace, trace["terminals"]["inputs"][name], c["poses"][0]) == \
                pytest.approx(v, abs=1e-6)
    assert seen == {0, 1}
    # every rod keeps its length in every state the trace poses (1e-3 mm: rounding)
    design = json.loads(sorter_json.read_text())
    assert max(rod_stretch(trace, design, p) for c in trace["cases"] for p in c["poses"]) < 1e-3
    # a change starts at its rest state's pose and ends at the next one's (same closed form)
    by_inputs = {tuple(sorted(c["inputs_after"].items())): c["poses"][0] for c in rest}
    for c in changes:
        assert c["frac"][0] == 0 and c["frac"][-1] == 1 and len(c["poses"]) == 21
        for pose, key in ((c["poses"][0], "inputs_before"), (c["poses"][-1], "inputs_after")):
            ref = by_inputs[tuple(sorted(c[key].items()))]
            np.testing.assert_allclose(np.array(pose, dtype=float), np.array(ref, dtype=float),
                                       atol=1e-9)


def test_dynamic_trace_ends_at_the_closed_form_and_leaves_the_proof_alone(cli, tmp_path,
                                                                          sorter_json):
    code, trace, report = run_trace(cli, tmp_path, sorter_json, "--cases", "2",
                                    "--level", "dynamic")
    assert code == 0
    validate(trace)
    assert trace["level"] == "dynamic" and len(trace["cases"]) == report["cases"] == 17
    assert {b["id"] for b in trace["bodies"]} == design_body_ids(json.loads(
        sorter_json.read_text()))
    plain = tmp_path / "plain.json"
    assert cli("simulate", sorter_json, "--cases", "2", "--level", "dynamic", "--report",
               plain)[0] == 0
    without = json.loads(plain.read_text())
    for r in (report, without):
        r.pop("seconds")
        r["failures"] = sorted(map(json.dumps, r["failures"]))
    assert report == without  # the same proof, to the last figure
    # independent reference: the closed form of each case's end inputs, through mechc's own
    # part kinematics, against the trace's last sample applied to every outline vertex
    design = design_from_json(load_design_json(sorter_json), str(sorter_json))
    mech, lib = design.mechanism, load_library([])
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    bodies = mech.body_index()
    def off_closed_form(c, inputs: str, sample: int) -> float:
        poses = evaluate(mech, lib, types, {k: np.array([float(v)])
                                            for k, v in c[inputs].items()})
        assert all(None not in p for p in c["poses"][sample])
        worst = 0.0
        for b, pose in zip(trace["bodies"], c["poses"][sample]):
            for poly in b["outline"]:
                for p in poly:
                    x, y = posed(b, pose, p)
                    cx, cy = position(bodies[b["id"]], poses, p)
                    worst = max(worst, float(np.hypot(x - cx[0], y - cy[0])))
        return worst

    # within the joint-stretch limit a proof allows (0.5 % of stroke): measured 0.026 mm
    assert max(off_closed_form(c, "inputs_after", -1) for c in trace["cases"]) \
        < 0.005 * trace["stroke_mm"]
    # every change is a case of its own: it starts at rest on the closed form of its inputs
    # (to the trace's rounding), where the last one's inputs ended
    assert max(off_closed_form(c, "inputs_before", 0) for c in trace["cases"]) < 1e-3
    design_json = json.loads(sorter_json.read_text())
    stretch = max(rod_stretch(trace, design_json, p) for c in trace["cases"] for p in c["poses"])
    assert stretch <= report["max_joint_violation_mm"] + 1e-3
    for a, b in zip(trace["cases"], trace["cases"][1:]):
        assert a["inputs_after"] == b["inputs_before"]
    every = trace["sampling"]["every_s"]
    for c in trace["cases"]:
        assert c["t"][0] == 0 and np.all(np.diff(c["t"]) > 0)
        assert np.all(np.diff(c["t"])[:-1] == pytest.approx(every))


def test_sequential_kinematic_trace_of_the_toggle(cli, tmp_path):
    code, trace, report = run_trace(cli, tmp_path, EXAMPLES / "toggle.fsm", "--level",
                                    "kinematic")
    assert code == 0
    validate(trace)
    assert trace["kind"] == "sequential"
    changes = [c for c in trace["cases"] if c["kind"] == "change"]
    rest = [c for c in trace["cases"] if c["kind"] == "rest"]
    assert len(changes) == report["cases"]
    assert [c["step"] for c in rest] == [0] * len(rest) and len(rest) >= 1
    # the toggle's flow table: Q is on in states b and c
    tol = report["tolerance_fraction"]
    for c in trace["cases"]:
        assert c["expected_after"]["Q"] == (1 if c["expected_state"] in "bc" else 0)
        q = signal(trace, trace["terminals"]["outputs"]["Q"], c["poses"][-1])
        assert abs(q - c["expected_after"]["Q"]) <= tol, (c["sequence"], c["step"], q)
    # each press toggles Q: the walk visits both values
    assert {c["expected_after"]["Q"] for c in changes} == {0, 1}


def test_trace_at_logic_level_is_refused(cli, tmp_path, sorter_json):
    out = tmp_path / "t.json"
    code, _, err = cli("simulate", sorter_json, "--level", "logic", "--trace", out)
    assert code == 2 and "logic level has none" in err and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize("opts, message", [
    (["--prune"], "cannot be taken with --prune"),
    (["--level", "kinematic", "--trace-every", "0.01"], "--trace-every spaces"),
    (["--trace-every", "0"], "must be positive"),
])
def test_trace_option_misuse_is_refused(cli, tmp_path, sorter_json, opts, message):
    out = tmp_path / "t.json"
    code, _, err = cli("simulate", sorter_json, "--trace", out, *opts)
    assert code == 2 and message in err
    assert not out.exists()


def test_trace_never_overwrites_the_design_or_the_report(cli, tmp_path, sorter_json):
    design = tmp_path / "design.json"
    design.write_bytes(sorter_json.read_bytes())
    before = design.read_bytes()
    code, _, err = cli("simulate", design, "--level", "kinematic", "--trace", design)
    assert code == 2 and "refusing to overwrite the design" in err
    assert design.read_bytes() == before
    both = tmp_path / "both.json"
    code, _, err = cli("simulate", design, "--level", "kinematic", "--trace", both,
                       "--report", both)
    assert code == 2 and "refusing to overwrite the report" in err
    assert not both.exists()


@pytest.mark.parametrize("level", ["kinematic", "dynamic"])
def test_a_trace_too_large_stops_the_proof_with_a_usage_error(sorter_json, level):
    design = design_from_json(load_design_json(sorter_json), str(sorter_json))
    limit = 40 * len(design.mechanism.body_index())  # fewer samples than either proof visits
    rec = TraceRecorder(design.mechanism, max_poses=limit)
    with pytest.raises(UsageError, match=f"more than {limit:,} body poses"):
        prove(design, design.spec, load_library([]), level,
              ProofSettings(trace=rec, cases=0))


@pytest.mark.slow
def test_sequential_dynamic_trace_ends_where_the_kinematic_walk_does(cli, tmp_path):
    """The toggle's two traces walk the same sequences (the same seed): at the end of every
    step each body stands where the closed form put it. Excepted: the AMPLIFIERs' rollers,
    whose spin (and the idlers' float in their slots) the closed form does not model — it
    holds them still, the switching is dynamic only (stdlib/amplifier.py)."""
    toggle = EXAMPLES / "toggle.fsm"
    kin, dyn = tmp_path / "kin.json", tmp_path / "dyn.json"
    assert cli("simulate", toggle, "--level", "kinematic", "--trace", kin)[0] == 0
    code, _, _ = cli("simulate", toggle, "--trace", dyn, "--trace-every", "0.005")
    assert code == 0
    k, d = json.loads(kin.read_text()), json.loads(dyn.read_text())
    validate(d)
    assert d["level"] == "dynamic" and d["kind"] == "sequential"
    assert len([c for c in d["cases"] if c["kind"] == "change"]) == d["proof"]["cases"]
    by_step = {(c["sequence"], c["step"]): c for c in k["cases"]}
    spinning = {"powered roller", "friction roller"}  # roles of the AMPLIFIER's rollers
    assert any(b["role"] in spinning for b in d["bodies"])  # the exception is needed here
    worst = 0.0
    for c in d["cases"]:
        kc = by_step[c["sequence"], c["step"]]
        assert kc["inputs_after"] == c["inputs_after"]
        assert kc["expected_state"] == c["expected_state"]
        for b, pd, pk in zip(d["bodies"], c["poses"][-1], kc["poses"][-1]):
            if b["kind"] == "rotor" or b["role"] in spinning:
                continue
            for poly in b["outline"]:
                for p in poly:
                    (x1, y1), (x2, y2) = posed(b, pd, p), posed(b, pk, p)
                    worst = max(worst, float(np.hypot(x1 - x2, y1 - y2)))
    assert worst < 0.005 * d["stroke_mm"]  # measured 0.019 mm


def test_the_documented_pose_script_runs_as_printed(cli, tmp_path, sorter_json):
    """docs/trace.md's example reads a trace with nothing but the standard library: run it
    exactly as printed; its first line is the one the doc shows, every output at rest within
    the tolerance of the spec's value."""
    doc = (ROOT / "docs" / "trace.md").read_text()
    code = re.search(r"```python\n(# pose.py.*?)```", doc, re.S)
    assert code, "example block missing from docs/trace.md"
    script = tmp_path / "pose.py"
    script.write_text(code.group(1))
    trace = tmp_path / "sorter.kin.json"
    assert cli("simulate", sorter_json, "--level", "kinematic", "--trace", trace)[0] == 0
    out = subprocess.run([sys.executable, str(script), str(trace)], capture_output=True,
                         text=True, check=True).stdout.splitlines()
    assert len(out) == 16
    assert out[0] in doc
    for line in out:
        got = float(re.search(r"outputs \{'Z': ([-\d.e]+)\}", line).group(1))
        want = re.search(r"expected \{'Z': (\w+)\}", line).group(1)
        if want != "None":
            assert abs(got - int(want)) <= 0.05, line
