"""The screened proof (``mechc.proofs.screen``): its ternary hazard check against a textbook
hazard and a brute-force second implementation, its calibration on made-up runs, and its
verdicts against the whole-scene dynamic proof of the same changes, case by case, on
examples, held-out random specs, a forced failure and a flow table."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from mechc.bench.circuits import random_compiled, random_netlist
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.ir.logic_types import evaluate_type
from mechc.ir.netlist import CellInst, Netlist
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import Cube
from mechc.physics.scene import DynSettings
from mechc.pipeline import compile_netlist, compile_spec
from mechc.proofs import ProofSettings, prove
from mechc.proofs.dynamic import plan_changes, prove_dynamic
from mechc.proofs.screen import (
    CONTACT_HEADROOM,
    HELD_MARGIN_SHARE,
    JOINT_HEADROOM,
    MODEL_ERROR,
    SETTLE_MARGIN,
    SOLVER_FACTOR,
    calibration_failures,
    concerned,
    decide,
    held_by_logic,
    prove_screened,
)
from mechc.proofs.settings import dyn_settings
from tests.helpers import EXAMPLES, amplified_and

LIB = load_library()


def _hazard_netlist(consensus: bool) -> Netlist:
    """z = a.b + a'.c, with the consensus term b.c when asked."""
    nl = Netlist(["a", "b", "c"])
    nl.add_cell(CellInst("n", "not", "NOT", ("a",), ("na",)))
    nl.add_cell(CellInst("t1", "and", "AND", ("a", "b"), ("p",)))
    nl.add_cell(CellInst("t2", "and", "AND", ("na", "c"), ("q",)))
    ors = ["p", "q"]
    if consensus:
        nl.add_cell(CellInst("t3", "and", "AND", ("b", "c"), ("r",)))
        ors.append("r")
    nl.add_cell(CellInst("o", "or", "OR", tuple(ors), ("z",)))
    nl.set_output("z", "z")
    return nl


def test_ternary_finds_the_textbook_static_hazard_and_its_cure():
    # a moving with b = c = 1: z is 1 before and after, but a.b falls as a'.c rises
    change = [(0b011, 0b111), (0b111, 0b011)]
    assert not held_by_logic(_hazard_netlist(False), ["a", "b", "c"], change)["z"].any()
    # the consensus term b.c holds z whatever order the gates switch in
    assert held_by_logic(_hazard_netlist(True), ["a", "b", "c"], change)["z"].all()
    # b moving with a = 1, c = 0: z follows b (switches), so it is not held
    assert not held_by_logic(_hazard_netlist(True), ["a", "b", "c"], [(0b100, 0b110)])["z"][0]


def _ternary_brute(nl: Netlist, names: list[str], cur: int, vec: int) -> dict[str, bool]:
    """Second implementation: per cell, the set of values over every completion of its
    unknown inputs, by enumeration (no arrays)."""
    n = len(names)
    val: dict[str, set[bool]] = {}
    for k, nm in enumerate(names):
        val[nm] = {bool((cur >> (n - 1 - k)) & 1), bool((vec >> (n - 1 - k)) & 1)}
    for c in nl.topo_cells():
        outs = set()
        for combo in itertools.product(*[sorted(val[x]) for x in c.inputs]):
            arr = [np.array([v]) for v in combo]
            outs.add(bool(evaluate_type(c.type, arr, c.params, 1)[0]))
        for net in c.outputs:
            val[net] = outs
    return {o: len(val[net]) == 1 for o, net in nl.outputs.items()}


@pytest.mark.parametrize("seed", range(4))
def test_ternary_matches_a_brute_force_on_random_netlists(seed):
    nl = random_netlist(30, n_inputs=5, seed=seed)
    names = list(nl.inputs)
    pairs = [(a, a ^ (1 << b)) for a in range(32) for b in range(5)]
    got = held_by_logic(nl, names, pairs)
    for i, (cur, vec) in enumerate(pairs):
        ref = _ternary_brute(nl, names, cur, vec)
        for o in nl.outputs:
            assert bool(got[o][i]) == ref[o], (seed, cur, vec, o)
    # a definite output never differs between the change's two ends (a necessary condition)
    ev = nl.evaluate({nm: np.array([[(c >> (4 - k)) & 1, (v >> (4 - k)) & 1] for c, v in pairs],
                                   dtype=bool).ravel() for k, nm in enumerate(names)})
    for o, net in nl.outputs.items():
        ends = np.asarray(ev[net]).reshape(-1, 2)
        assert not np.any(got[o] & (ends[:, 0] != ends[:, 1]))


def _rec(**kw) -> dict:
    base = {"max_violation_mm": 0.0, "max_penetration_mm": 0.0, "settle_time_s": 0.0,
            "servo_lag_end_mm": 0.0, "held_deviation": {}}
    return {**base, **kw}


def test_calibration_flags_each_kind_of_disagreement():
    st = DynSettings()
    dec = [{"moving": "a", "to": 1}]
    timed = [{"nets_settle_s": 0.1, "closed_form_swing": {"z": 0.0}}]

    def bad(**kw) -> list[str]:
        return [f["text"] for f in calibration_failures(dec, timed, [0], [_rec(**kw)], st,
                                                         0.025, 0.05, 20.0)]

    assert bad() == []
    # a joint or contact leaving less than its headroom of the limit: just inside, outside
    assert bad(max_violation_mm=st.violation_limit * (1 - JOINT_HEADROOM) * 0.99) == []
    assert bad(max_violation_mm=st.violation_limit * (1 - JOINT_HEADROOM) * 1.01)
    assert bad(max_violation_mm=float("nan"))
    assert bad(max_penetration_mm=st.penetration_limit * (1 - CONTACT_HEADROOM) * 0.99) == []
    assert bad(max_penetration_mm=st.penetration_limit * (1 - CONTACT_HEADROOM) * 1.01)
    # the input's lag at the end keeps its factor
    assert bad(servo_lag_end_mm=0.05 * 20.0 / SOLVER_FACTOR * 1.01)
    # settled later than the prediction plus the model's error, or never
    late = 0.1 * (1 + MODEL_ERROR) - st.move_time
    assert bad(settle_time_s=late * 0.99) == []
    assert bad(settle_time_s=late * 1.01 + 1e-4)
    assert bad(settle_time_s=float("inf"))
    # a held output moved more than half the held margin beyond its closed form
    assert bad(held_deviation={"z": 0.012}) == []
    assert bad(held_deviation={"z": 0.013})
    # a heavy change is outside the model: the dynamic proof alone judges it
    dec[0]["heavy"] = True
    assert bad(max_violation_mm=st.violation_limit * 0.99,
               max_penetration_mm=st.penetration_limit * 0.99, settle_time_s=late * 1.5) == []


def test_calibration_failures_name_the_change_and_check():
    st = DynSettings()
    dec = [{"moving": "a", "to": 1}, {"moving": "b", "to": 0}]
    timed = [{"nets_settle_s": 0.1, "closed_form_swing": {"z": 0.0}}] * 2
    recs = [_rec(max_penetration_mm=st.penetration_limit), _rec(held_deviation={"z": 0.02})]
    got = calibration_failures(dec, timed, [0, 1], recs, st, 0.025, 0.05, 20.0)
    assert [(f["change"], f["check"], f.get("output")) for f in got] == \
        [(0, "contact", None), (1, "held", "z")]


def test_a_failure_concerns_what_its_change_vouched_for():
    """A failing change takes the vouching only from the cleared changes that share a (cell
    kind, direction) with it, move its input, or (a held output that moved too far) must
    hold that output; changes that ran are never listed again."""
    dec = [{"moving": "a", "route": "dynamic", "holds": []},
           {"moving": "b", "route": "timing", "holds": []},          # shares kind 0 rising
           {"moving": "a", "route": "timing", "holds": []},          # same moving input
           {"moving": "c", "route": "timing", "holds": ["z"]},       # holds z
           {"moving": "c", "route": "timing", "holds": []},          # kind 0 falling: not
           {"moving": "b", "route": "dynamic", "holds": ["z"]}]      # ran already
    keys = [{"0:1", "1:0"}, {"0:1"}, set(), {"2:1"}, {"0:0"}, {"0:1"}]
    assert concerned({"change": 0, "check": "joint"}, dec, keys) == [1, 2]
    assert concerned({"change": 0, "check": "held", "output": "z"}, dec, keys) == [1, 2, 3]


def test_a_failed_calibration_runs_only_the_changes_it_concerns(monkeypatch):
    """One witness of the sorter made to fail its calibration: the cleared changes it vouched
    for run in pymunk too, they are checked in turn, and every other change stays cleared
    (before, every change ran)."""
    from mechc.proofs import screen

    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    _, _, dec0 = decide(d, d.spec, LIB, ProofSettings(), dyn_settings(d))
    keys = [set(x["kinds"]) for x in dec0]
    first = [i for i, x in enumerate(dec0) if x["route"] == "dynamic"]
    w = next(i for i in first if keys[i])
    fake = {"change": w, "check": "settle", "text": f"change {w}: made to fail"}
    want = set(concerned(fake, dec0, keys))
    assert want and len(want) < len(dec0) - len(first)  # the test means something
    real = screen.calibration_failures
    seen: list[list[int]] = []

    def one_failure(decisions, timed, run, record, *a):
        seen.append(list(run))
        got = real(decisions, timed, run, record, *a)
        return got + [fake] if len(seen) == 1 else got

    monkeypatch.setattr(screen, "calibration_failures", one_failure)
    ticks: list[tuple[int, int]] = []
    rep = prove_screened(d, d.spec, LIB, ProofSettings(), lambda a, b: ticks.append((a, b)))
    sc = rep.figures["screen"]
    ran = {i for i, x in enumerate(sc["decisions"]) if x["route"] == "dynamic"}
    assert ran == set(first) | want
    # the progress goes on counting through the fallback: it never goes back, and it ends
    # at every change that ran
    assert [a for a, _ in ticks] == sorted(a for a, _ in ticks)
    assert ticks[-1] == (len(ran), len(ran))
    assert seen[1] == sorted(want)  # the changes that fell back were checked in turn
    assert sc["fell_back"] == len(want) and sc["dynamic"] == len(ran)
    assert rep.cases == 31 and rep.passed
    assert all(any(w.startswith("calibration failed") for w in sc["decisions"][i]["why"])
               for i in want)


@pytest.mark.slow
def test_witnesses_failing_for_real_leave_nothing_they_vouched_for_cleared(monkeypatch):
    """No headroom at all: every change that ran fails its joint check in pymunk. The
    screened proof then agrees with the dynamic one change by change, and no change left
    cleared shares a (cell kind, direction) or a moving input with a change that ran."""
    from mechc.proofs import screen

    monkeypatch.setattr(screen, "JOINT_HEADROOM", 1.0)
    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    sc, _full = _same_as_dynamic(d)
    assert sc["calibration"] != "passed" and sc["fell_back"] > 0
    assert sc["cleared_by_timing"] > 0  # what no failing change vouched for stays cleared
    dec = sc["decisions"]
    ran = [x for x in dec if x["route"] == "dynamic" and not x["heavy"]]
    for x in dec:
        if x["route"] == "timing":
            assert not any(set(x["kinds"]) & set(r["kinds"]) or x["moving"] == r["moving"]
                           for r in ran)


def test_a_heavy_change_runs_in_pymunk_and_witnesses_nothing(monkeypatch):
    """With every net heavier than the threshold, every change that switches a cell runs
    in pymunk, says why, and none is chosen as a witness (nothing is left to clear)."""
    from mechc.proofs import screen

    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    monkeypatch.setattr(screen, "HEAVY_KG", -1.0)
    _, timed, dec = decide(d, d.spec, LIB, ProofSettings(), dyn_settings(d))
    for t, x in zip(timed, dec):
        assert x["heavy"] == bool(t["switched"])
        if t["switched"]:
            assert x["route"] == "dynamic"
            assert any(w.startswith("heavy") for w in x["why"])
        assert not any(w.startswith("witness") for w in x["why"])


def _by_change(report) -> dict[tuple, list[str]]:
    """The report's failures by (target vector, moving input, direction)."""
    out: dict[tuple, list[str]] = {}
    for f in report.failures:
        if "inputs" in f:
            key = (tuple(sorted(f["inputs"].items())), f["moving"], f["to"])
            out.setdefault(key, []).append(json.dumps(f, sort_keys=True))
    return out


def _same_as_dynamic(design, st=None, settings=None) -> tuple[dict, object]:
    """Screened and whole dynamic proof of ``design``: same verdict, and for every change the
    screen ran, the same failures; no change the dynamic proof failed was cleared."""
    settings = settings or ProofSettings()
    st = st or dyn_settings(design)
    full = prove_dynamic(design, design.spec, LIB, st, tolerance=settings.tolerance)
    scr = prove_screened(design, design.spec, LIB, settings, st=st)
    assert scr.level == "screened" and full.level == "dynamic"
    assert scr.passed == full.passed
    assert scr.cases == full.cases
    dec = scr.figures["screen"]["decisions"]
    ran = {(tuple(sorted(d["inputs"].items())), d["moving"], d["to"]) for d in dec
           if d["route"] == "dynamic"}
    cleared = {(tuple(sorted(d["inputs"].items())), d["moving"], d["to"]) for d in dec
               if d["route"] == "timing"} - ran
    f_full, f_scr = _by_change(full), _by_change(scr)
    assert not set(f_full) & cleared  # never cleared a change the dynamic proof failed
    for key in ran:
        assert f_full.get(key, []) == f_scr.get(key, []), key
    assert scr.failure_kinds == full.failure_kinds
    return scr.figures["screen"], full


def test_screened_equals_dynamic_on_the_sorter_and_runs_few_changes():
    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    screen, full = _same_as_dynamic(d)
    assert full.passed
    assert screen["applied"] and screen["calibration"] == "passed"
    assert screen["dynamic"] + screen["cleared_by_timing"] == screen["changes"] == 31
    assert screen["dynamic"] <= 4
    assert "of 31 changes ran in pymunk" in screen["text"]


@pytest.mark.slow
def test_a_move_too_fast_fails_the_screened_proof_as_the_dynamic_one():
    d = compile_spec(load_spec(EXAMPLES / "full_adder.bool"))
    # inputs thrown in 10 ms: the dynamic proof fails (the scene does not settle)
    screen, full = _same_as_dynamic(d, settings=ProofSettings(move_time=0.01),
                                    st=dyn_settings(d, move_time=0.01))
    assert not full.passed and "settle" in full.failure_kinds  # the failure is real
    assert screen["dynamic"] > 0


def test_the_screen_routes_small_slack_to_dynamics_with_its_reason():
    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    st = dyn_settings(d)
    st.settle_time = 0.02  # budget 0.10 s: a prediction of 0.08 s x 1.4 does not fit
    pairs, timed, dec = decide(d, d.spec, LIB, ProofSettings(), st)
    names = list(d.spec.inputs)
    assert pairs == plan_changes(d, names, 16, 0, independent=True)[0]
    for t, x in zip(timed, dec):
        slack_small = t["nets_settle_s"] * (1 + SETTLE_MARGIN) > st.move_time + st.settle_time
        assert (x["route"] == "dynamic") >= slack_small
        assert any(w.startswith("slack") for w in x["why"]) == slack_small
    assert any(any(w.startswith("slack") for w in x["why"]) for x in dec)
    # a cleared change leaves the dynamics at least the held margin on its held outputs
    tol = ProofSettings().tolerance
    assert all(x["held_room"] >= tol * (1 - HELD_MARGIN_SHARE) - 1e-9 for x in dec
               if x["route"] == "timing")


def _random_spec(seed: int, n_in: int, n_out: int) -> Spec:
    rng = np.random.default_rng(seed)
    funcs = {}
    for o in range(n_out):
        t = rng.random(1 << n_in)
        funcs[f"z{o}"] = OutputSpec(
            f"z{o}", on=[Cube.minterm(int(x), n_in) for x in np.flatnonzero(t < 0.45)],
            dc=[Cube.minterm(int(x), n_in) for x in np.flatnonzero((t >= 0.45) & (t < 0.5))])
    return Spec(f"heldout{seed}", "bool", [f"x{i}" for i in range(n_in)], list(funcs), funcs)


@pytest.mark.slow
@pytest.mark.parametrize("seed,n_in,n_out", [(9200, 3, 2), (9201, 4, 1)])
def test_screened_equals_dynamic_on_held_out_random_specs(seed, n_in, n_out):
    _same_as_dynamic(compile_spec(_random_spec(seed, n_in, n_out)))


@pytest.mark.slow
def test_screened_equals_dynamic_on_a_larger_random_circuit_never_used_for_a_margin():
    """33 cells from a compiled random spec (the held-out specs above have 1-21): the screen
    clears most changes and still gives the dynamic proof's report, change by change."""
    d = random_compiled(35, seed=17)
    assert len(d.netlist.cells) >= 25
    screen, full = _same_as_dynamic(d)
    assert screen["applied"]
    assert screen["cleared_by_timing"] > screen["dynamic"]


@pytest.mark.slow
def test_a_flow_table_runs_every_transition_and_gives_the_dynamic_report():
    ft = parse_fsm_file(EXAMPLES / "gated_latch.fsm")
    d = compile_spec(ft)
    full = prove(d, ft, LIB, "dynamic")
    scr = prove(d, ft, LIB, "screened")
    assert scr.figures["screen"]["applied"] is False
    assert scr.passed == full.passed and scr.failures == full.failures
    assert scr.cases == full.cases


def test_simulate_defaults_to_the_screened_level(cli, tmp_path):
    rep = tmp_path / "r.json"
    code, out, _ = cli("simulate", EXAMPLES / "sorter.bool", "--jobs", "1", "--report", rep)
    assert code == 0
    assert "level screened" in out and "changes ran in pymunk" in out
    doc = json.loads(rep.read_text())
    assert doc["level"] == "screened" and doc["screen"]["applied"]
    code, out, err = cli("simulate", EXAMPLES / "sorter.bool", "--level", "timing",
                         "--scheduler", "tcp://127.0.0.1:1")
    assert code == 2 and "--scheduler" in err


def test_a_move_time_the_tables_never_measured_goes_to_dynamics():
    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    for move_time, outside in ((0.08, False), (0.3, True), (0.02, True)):
        st = dyn_settings(d, move_time=move_time)
        _, timed, dec = decide(d, d.spec, LIB, ProofSettings(move_time=move_time), st)
        for t, x in zip(timed, dec):
            said = any("outside their measured" in w for w in x["why"])
            assert said == (outside and bool(t["switched"])), (move_time, x)


@pytest.fixture(scope="module")
def amplified():
    """z = a & b with a powered AMPLIFIER on a (a toggle, timed as built), compiled."""
    nl, spec = amplified_and(LIB)
    return compile_netlist(spec, nl, library=LIB)


def test_a_table_measured_as_built_for_the_screen_shows_progress(amplified, tmp_path,
                                                                 monkeypatch):
    """An AMPLIFIER is timed as built, measured on its first use in the screen's timing of
    the changes (about a minute each on adder16's): the proof's progress is told so, naming
    the instance, before the first change runs; with its table cached, nothing is measured."""
    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path))
    seen: list[tuple] = []
    rep = prove(amplified, amplified.spec, LIB, "screened", ProofSettings(jobs=1),
                lambda done, total, *what: seen.append((done, total, *what)))
    assert rep.passed, rep.failures[:3]
    g1 = [s for s in seen if len(s) == 3 and "cell 'g1'" in s[2]]
    changes = [s for s in seen if len(s) == 2]
    assert g1 and changes and seen.index(g1[-1]) < seen.index(changes[0])
    assert g1[-1][0] == g1[-1][1] and "(first use)" in g1[-1][2]
    seen.clear()
    prove(amplified, amplified.spec, LIB, "screened", ProofSettings(jobs=1),
          lambda done, total, *what: seen.append((done, total, *what)))
    assert not [s for s in seen if len(s) == 3]  # cached now


@pytest.mark.slow
def test_amplifier_changes_are_cleared_by_their_as_built_table(amplified, tmp_path,
                                                               monkeypatch):
    """An AMPLIFIER switching no longer sends a change to pymunk by itself: its table as
    built times it, the changes with slack enough are cleared, and each direction the
    toggle switches in on a cleared change is switched by a change that runs (its witness)."""
    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path))
    d = amplified
    st = dyn_settings(d)
    _, timed, dec = decide(d, d.spec, LIB, ProofSettings(), st)
    budget = st.move_time + st.settle_time
    cleared = [t for t, x in zip(timed, dec) if x["route"] == "timing" and "g1" in t["switched"]]
    assert cleared  # toggle changes cleared, not all run
    assert all(t["nets_settle_s"] * (1 + SETTLE_MARGIN) <= budget for t in cleared)
    run = {t["switched"]["g1"] for t, x in zip(timed, dec)
           if x["route"] == "dynamic" and "g1" in t["switched"]}
    assert {t["switched"]["g1"] for t in cleared} <= run
    assert not any("amplifier" in w for x in dec for w in x["why"])


@pytest.mark.slow
def test_an_amplifier_change_held_too_short_is_not_cleared(amplified, tmp_path, monkeypatch):
    """The hold cut to 20 ms: the toggle lands after the time allowed, the dynamic proof
    fails those changes, and the screen clears none of them (their slack is too small)."""
    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path))
    st = dyn_settings(amplified)
    st.settle_time = 0.02
    screen, full = _same_as_dynamic(amplified, st=st)
    assert not full.passed and "settle" in full.failure_kinds  # the failure is real
    for d in screen["decisions"]:
        if d["moving"] == "a":
            assert d["route"] == "dynamic"
            assert any(w.startswith("slack") for w in d["why"])
