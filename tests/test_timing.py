"""Cell characterisation (``mechc.cells.characterise``) and the timing level
(``mechc.proofs.timing``): interpolation and time measures against closed forms, tables keyed
by geometry and cached on disk, the shipped tables reproduced by a new measurement, and the
timing level's predictions against the whole-scene pymunk run of the same changes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechc.cells import characterise as ch
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.ir.netlist import CellInst, Netlist
from mechc.physics.scene import Scene, min_jerk
from mechc.pipeline import compile_netlist, compile_spec
from mechc.proofs import ProofSettings, prove
from mechc.proofs.dynamic import plan
from mechc.proofs.settings import dyn_settings
from mechc.proofs.timing import cell_tables, inequality, predict_changes, sample_times
from tests.helpers import EXAMPLES, amplified_and

LIB = load_library()


@pytest.fixture(scope="module")
def full_adder():
    return compile_spec(load_spec(EXAMPLES / "full_adder.bool"))


def _table(values) -> ch.CellTable:
    return ch.CellTable("k", "and", "AND", 2, {}, 20.0, (0.04, 0.08, 0.16), (0.0, 0.03, 0.09),
                        values, 4)


def test_table_is_bilinear_and_held_at_its_edges():
    mt, ld = np.meshgrid([0.04, 0.08, 0.16], [0.0, 0.03, 0.09], indexing="ij")
    f = 2.0 * mt + 5.0 * ld + 1.0  # a plane: bilinear interpolation is exact on it
    tab = _table({"lag_s": f.tolist()})
    for x, y in ((0.05, 0.01), (0.1, 0.06), (0.16, 0.0), (0.04, 0.09)):
        assert tab.at(x, y)["lag_s"] == pytest.approx(2 * x + 5 * y + 1, rel=1e-12)
    # outside the grid: the edge's value, never an extrapolation
    assert tab.at(1.0, 5.0)["lag_s"] == pytest.approx(2 * 0.16 + 5 * 0.09 + 1)
    assert tab.at(0.0, -1.0)["lag_s"] == pytest.approx(2 * 0.04 + 1)
    assert ch.CellTable.from_json(json.loads(json.dumps(tab.to_json()))).at(0.1, 0.06) == \
        tab.at(0.1, 0.06)


def test_crossing_and_settled_on_closed_forms():
    t = np.linspace(0.0, 1.0, 1001)
    ramp = np.clip(t / 0.8, 0.0, 1.0)  # reaches 0.5 at 0.4 s, within 0.005 of 1 at 0.796 s
    assert ch.crossing(t, ramp) == pytest.approx(0.4, abs=1e-9)
    assert ch.settled_at(t, ramp) == pytest.approx(0.8 * 0.995, abs=1e-9)
    decay = 1.0 - np.exp(-t / 0.05)  # settles within 0.005 at 0.05 ln 200
    assert ch.settled_at(t, decay, end=1.0) == pytest.approx(0.05 * np.log(200), abs=1e-4)
    assert np.isnan(ch.crossing(t, np.zeros_like(t)))


def test_sample_times_invert_the_minimum_jerk_move():
    ts = sample_times(0.08, 41)
    assert ts[0] == 0.0 and ts[-1] == pytest.approx(0.08)
    assert min_jerk(ts / 0.08) == pytest.approx(np.linspace(0.0, 1.0, 41), abs=1e-6)


def test_geometry_key_ignores_placement_and_sees_a_spring():
    d, _ = ch.alone(LIB["and"], LIB, "AND", 2, {}, 20.0)
    part = d.mechanism.cells["c1"].to_json()
    moved = json.loads(json.dumps(part))
    for b in moved["bodies"]:  # the same cell placed 100 mm to the right
        b["outline"] = [[[x + 100.0, y] for x, y in poly] for poly in b["outline"]]
    key = ch.table_key(LIB["and"], "AND", 2, {}, 20.0, part)
    assert ch.table_key(LIB["and"], "AND", 2, {}, 20.0, moved) == key
    stiffer = json.loads(json.dumps(part))
    stiffer["springs"][0]["rate_N_per_mm"] *= 2
    assert ch.table_key(LIB["and"], "AND", 2, {}, 20.0, stiffer) != key
    assert ch.table_key(LIB["and"], "AND", 2, {}, 25.0, part) != key


def test_shipped_table_is_what_a_new_measurement_gives():
    """The package's table of the NOT cell is reproduced by measuring it now (same key, same
    figures): the shipped file is what ``mechc cells characterise`` writes."""
    shipped = {d["key"]: d for d in json.loads(ch.SHIPPED.read_text())["tables"]}
    tab = ch.measure(LIB["not"], LIB, "NOT", 1, {}, 20.0)
    assert tab.key in shipped
    for f in ch.FIGURES:
        assert np.allclose(shipped[tab.key]["values"][f], tab.values[f], rtol=1e-3,
                           atol=1e-6), f
    # physics, not noise: a heavier load never makes the cell faster at the fastest move
    force = np.array(tab.values["force_N"])
    assert np.all(np.diff(force[0]) > 0)


def test_shipped_tables_are_of_todays_cell_files():
    """A stdlib cell edited after its table was measured must be measured again
    (``mechc cells characterise``): the tables record the file they were measured on."""
    for d in json.loads(ch.SHIPPED.read_text())["tables"]:
        assert d["source_sha256"] == LIB[d["cell"]].source_sha256, d["cell"]
    assert {(d["cell"], d["type"], d["n"]) for d in
            json.loads(ch.SHIPPED.read_text())["tables"]} == set(ch.STANDARD)


def test_cell_not_shipped_is_measured_once_then_read_from_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path))
    nl = Netlist(["a", "b", "c", "d"])
    nl.add_cell(CellInst("g", "and", "AND", ("a", "b", "c", "d"), ("z",)),
                pin_names=LIB["and"].input_names(4))
    nl.set_output("z", "z")
    spec = load_spec_text("inputs a b c d\noutputs z\nz = a & b & c & d\n")
    d = compile_netlist(spec, nl, library=LIB)
    seen: list[tuple] = []
    first, tabs = cell_tables(d, LIB, lambda a, b, *what: seen.append((a, b, *what)))
    assert tabs.found == {"shipped": 0, "cached": 0, "measured": 1}
    assert seen[-1] == (9, 9, "measuring the timing of cell 'and' (first use)")  # named
    assert len(list(tmp_path.iterdir())) == 1  # one file
    again, tabs2 = cell_tables(d, LIB, None)
    assert tabs2.found == {"shipped": 0, "cached": 1, "measured": 0}
    assert again["g"].values == first["g"].values


def load_spec_text(text: str):
    from mechc.frontends.boolfile import parse_bool

    return parse_bool(text, "<test>")


def test_timing_level_predicts_the_whole_scene(full_adder):
    """Per switching output, the predicted settle and switching times are within 15 % of the
    whole mechanism run in pymunk from rest (what the dynamic proof runs)."""
    names = list(full_adder.spec.inputs)
    vectors = plan(len(names), 16, 0)[:5]
    changes = list(zip([0, *vectors], vectors))
    st = dyn_settings(full_adder)
    tables, tabs = cell_tables(full_adder, LIB, None)
    kinds = {(c.cell, len(c.inputs)) for c in full_adder.netlist.cells.values()}
    assert tabs.found == {"shipped": len(kinds), "cached": 0, "measured": 0}  # all shipped
    pred = predict_changes(full_adder, LIB, names, changes, st, tables)
    types = {c.id: c.cell for c in full_adder.netlist.cells.values()}
    n = len(names)
    checked = 0
    for (cur, vec), p in zip(changes, pred):
        start = {nm: float((cur >> (n - 1 - k)) & 1) for k, nm in enumerate(names)}
        k = n - (cur ^ vec).bit_length()
        sc = Scene.build(full_adder.mechanism, LIB, types, st, start)
        r = sc.move(names[k], float((vec >> (n - 1 - k)) & 1))
        t = np.concatenate([[0.0], r.t])
        assert p["outputs"], "every change of the full adder's tour switches an output"
        for o, po in p["outputs"].items():
            s = np.concatenate([[r.outputs[o][0]], r.outputs[o]])
            assert po["settle_s"] == pytest.approx(ch.settled_at(t, s), rel=0.15)
            assert po["switch_s"] == pytest.approx(ch.crossing(t, s), rel=0.15)
            checked += 1
    assert checked >= 5


def test_timing_level_report(full_adder):
    r = prove(full_adder, full_adder.spec, LIB, "timing", ProofSettings())
    assert r.passed and r.level == "timing"
    assert r.cases == len(plan(3, 16, 0))
    crit = r["critical_path"]
    assert crit["settle_s"] == max(c["settle_s"] for c in r["changes"])
    assert crit["path"] and all(c in full_adder.netlist.cells for c in crit["path"])
    assert r["min_slack_s"] == pytest.approx(r["budget_s"] - crit["settle_s"], abs=1e-5)


def test_sequential_requirements_with_stated_delays_are_the_compile_inequalities():
    """With each cell's stated delay, the timing level's inequality is the one compile wrote
    (``mechc.passes.ordering``), a second implementation of the same formula."""
    d = compile_spec(parse_fsm_file(EXAMPLES / "speedctl.fsm"))
    reqs = d.stats["sequential"]["ordering"]["requirements"]
    assert reqs
    stated = {c.id: float(getattr(LIB[c.cell], "switching_delay_s", 0.0))
              for c in d.netlist.cells.values()}
    st = dyn_settings(d, LIB)
    for req in reqs:
        mine = inequality(d.netlist, stated, req, st.move_time)
        theirs = req["timing"]
        for k in ("t_input_s", "t_memory_feedback_s", "skew_s"):
            if k in theirs:
                assert mine[k] == pytest.approx(theirs[k], abs=1e-4), k
        assert mine["slack_s"] == pytest.approx(theirs.get("slack_s", 0.0) - 0.02
                                                if "slack_s" in theirs
                                                else 0.02 - theirs["skew_s"], abs=1e-4)
    r = prove(d, d.spec, LIB, "timing", ProofSettings())
    assert r.cases == len(reqs)
    assert all("slack_s" in q for q in r["requirements"])
    # an inequality that fails is passed only where compile's dynamic walk met it
    for q, req in zip(r["requirements"], reqs):
        assert q["met_by_dynamic_walk"] == (req["met"] and not q["met"])
    assert r.passed == all(q["met"] or q["met_by_dynamic_walk"] for q in r["requirements"])


def test_cli_timing_level(cli):
    code, out, _err = cli("simulate", str(EXAMPLES / "sorter.bool"), "--level", "timing")
    assert code == 0 and "PASSED: level timing" in out
    code, _out, err = cli("simulate", str(EXAMPLES / "sorter.bool"), "--level", "timing",
                          "--trace", "/tmp/never.json")
    assert code == 2 and "timing level has none" in err


def test_cli_timing_level_shows_the_critical_path_and_each_requirement(cli, tmp_path):
    """What the terminal says is what the report holds: the critical path's output, cells and
    settle; each ordering requirement with its slack and what decided it."""
    rep = tmp_path / "r.json"
    code, out, _ = cli("simulate", str(EXAMPLES / "full_adder.bool"), "--level", "timing",
                       "--report", str(rep))
    crit = json.loads(rep.read_text())["critical_path"]
    line = next(x for x in out.splitlines() if x.startswith("critical path:"))
    assert f"{crit['output']} settles {crit['settle_s']:.4f} s" in line
    assert ", ".join(crit["path"]) in line
    code, out, _ = cli("simulate", str(EXAMPLES / "speedctl.fsm"), "--level", "timing",
                       "--report", str(rep))
    reqs = json.loads(rep.read_text())["requirements"]
    assert code == 0 and reqs
    assert f"ordering requirements as timing inequalities ({len(reqs)}):" in out
    for q in reqs:
        shown = next(x for x in out.splitlines()
                     if x.strip().startswith(f"{q['kind']} ({q['input']} ->"))
        assert f"slack {q['slack_s']:+.4f} s" in shown
        assert shown.endswith(": met") == q["met"]
        assert ("met by compile's dynamic walk" in shown) == q["met_by_dynamic_walk"]
    # the count is named for what it counts, in the table and in the verdict
    assert "ordering requirements  " in out
    assert f"PASSED: level timing, {len(reqs)} ordering requirements, 0 failures" in out


@pytest.mark.slow
def test_amplifier_is_timed_as_built_and_predicts_its_landing(tmp_path, monkeypatch):
    """An AMPLIFIER's switching delay and landing depend on what compile sized it for: it is
    timed as the design built it (a table per geometry, cached), and the settle time it
    predicts for the output behind it is within 15 % of the whole scene's."""
    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path))
    nl, spec = amplified_and(LIB)
    d = compile_netlist(spec, nl, library=LIB)
    names = ["a", "b"]
    changes = [(0b01, 0b11), (0b11, 0b01)]  # b on: a switches z on, then off
    st = dyn_settings(d)
    tables, tabs = cell_tables(d, LIB, None, names, changes)
    assert tabs.measured == ["g1"]  # the amplifier as built; the AND from the shipped table
    assert tables["g1"].values["lag_s"][1][0] > 0.02  # a delay of its own, not quasi-static
    pred = predict_changes(d, LIB, names, changes, st, tables)
    types = {c.id: c.cell for c in nl.cells.values()}
    for (cur, vec), p in zip(changes, pred):
        sc = Scene.build(d.mechanism, LIB, types, st, {"a": float(cur >> 1), "b": 1.0})
        r = sc.move("a", float(vec >> 1))
        t = np.concatenate([[0.0], r.t])
        s = np.concatenate([[r.outputs["z"][0]], r.outputs["z"]])
        assert p["outputs"]["z"]["path"] == ["g1", "g2"]
        assert p["outputs"]["z"]["settle_s"] == pytest.approx(ch.settled_at(t, s), rel=0.15)
        assert p["outputs"]["z"]["switch_s"] == pytest.approx(ch.crossing(t, s), rel=0.15)
    _again, tabs2 = cell_tables(d, LIB, None, names, changes)
    assert tabs2.found["cached"] == 1 and not tabs2.measured


@pytest.mark.slow
def test_an_internal_net_settles_from_its_own_closed_form():
    """The screened proof reads the latest settle of any switching net. An amplifier's input
    switches mid-move; timing its landing from the move's end put the 2-bit adder's carry
    changes 20-40 % late (every one sent to pymunk for want of slack). From the net's own
    closed form the latest net settles within 15 % of the whole scene's outputs."""
    from mechc.bench.circuits import adder2_spec

    d = compile_spec(adder2_spec())
    names = list(d.spec.inputs)
    st = dyn_settings(d)
    amps = {c.id for c in d.netlist.cells.values() if c.type == "AMPLIFIER"}
    assert amps, "the adder's carry goes through AMPLIFIERs"
    walk = plan(len(names), 16, 0)
    changes = list(zip([0, *walk], walk))
    tables, _ = cell_tables(d, LIB, None, names, changes)
    pred = predict_changes(d, LIB, names, changes, st, tables, detail=True)
    behind = [(ch_, p) for ch_, p in zip(changes, pred)
              if "s1" in p["outputs"] and amps & set(p["outputs"]["s1"]["path"])][:2]
    assert behind, "some change switches s1 through an amplifier"
    types = {c.id: c.cell for c in d.netlist.cells.values()}
    n = len(names)
    for (cur, vec), p in behind:
        start = {nm: float((cur >> (n - 1 - k)) & 1) for k, nm in enumerate(names)}
        k = n - (cur ^ vec).bit_length()
        r = Scene.build(d.mechanism, LIB, types, st, start).move(
            names[k], float((vec >> (n - 1 - k)) & 1))
        measured = r.settle_time + st.move_time
        assert 0.85 * measured <= p["nets_settle_s"] <= 1.15 * measured


NO_ORDERING = """inputs x1 x2
outputs Z
columns 00 01 11 10
flow
1: (1) (1) - 2 | 0
2: 1 - 3 (2) | 0
3: - - (3) 4 | 1
4: 1 - 3 (4) | 1
initial 1
"""


def test_sequential_timing_with_no_requirement_does_not_claim_power_up_only(cli, tmp_path):
    """A flow table whose changes raise no ordering requirement has input changes all the same:
    the verdict says what the zero counts, not that only the power-up state was checked."""
    path = tmp_path / "latch.fsm"
    path.write_text(NO_ORDERING)
    rep = tmp_path / "r.json"
    code, out, err = cli("simulate", str(path), "--level", "timing", "--report", str(rep))
    assert code == 0, err
    assert json.loads(rep.read_text())["requirements"] == []
    verdict = next(x for x in out.splitlines() if x.startswith("PASSED: level timing"))
    assert "0 ordering requirements" in verdict
    assert "power-up" not in verdict
    assert "no ordering requirement to time" in verdict


def test_timing_checks_the_dynamic_proofs_changes_beyond_ten_inputs():
    """Beyond 10 inputs the dynamic proof starts with the changes that switch every cell; the
    timing level times those same changes, in the same order, not a walk of its own."""
    from mechc.frontends.boolfile import parse_bool
    from mechc.proofs.dynamic import plan_changes

    names = [f"x{i}" for i in range(11)]
    text = (f"inputs {' '.join(names)}\noutputs y\n"
            "y = x0 & x1 | x2 & x3 | x4 & x5 | x6 & x7 | x8 & x9 & x10\n")
    d = compile_spec(parse_bool(text, "<wide>"))
    rep = prove(d, d.spec, LIB, "timing", ProofSettings())
    pairs, chosen = plan_changes(d, names, 16, 0, independent=True)
    assert chosen is not None and rep.cases == len(pairs)
    n = len(names)
    for (_, vec), got in zip(pairs, rep.figures["changes"]):
        assert got["inputs"] == {nm: (vec >> (n - 1 - k)) & 1 for k, nm in enumerate(names)}


def test_an_internal_net_settling_after_the_budget_fails_the_change(full_adder, monkeypatch):
    """Every output in time is not enough: a net still moving after the move and the hold
    keeps the scene from settling, so the timing level fails that change."""
    import mechc.proofs.timing as timing

    real = timing.predict_changes

    def late_net(*a, **kw):
        out = real(*a, **kw)
        out[0]["nets_settle_s"] = 1.0  # the first change: an internal net far too late
        return out

    monkeypatch.setattr(timing, "predict_changes", late_net)
    rep = prove(full_adder, full_adder.spec, LIB, "timing", ProofSettings())
    assert not rep.passed and rep.failure_kinds == {"settle": 1}
    assert "an internal net is predicted to settle 1.0000 s" in rep.failures[0]["message"]
    assert rep.figures["changes"][0]["slack_s"] > 0  # its outputs were in time
