"""The hold after each input change (``mechc.proofs.hold``): a combinational design's static
critical path against every path enumerated, the one hold every level uses, ``--hold``, and a
deep chain that settles within its own hold and not within the default one."""

from __future__ import annotations

import networkx as nx
import pytest

from mechc.cells.characterise import Tables
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.parts.pushrod import net_loads
from mechc.physics.scene import DynSettings
from mechc.pipeline import CompileOptions, compile_spec
from mechc.proofs import ProofSettings
from mechc.proofs.dynamic import plan_changes, prove_dynamic
from mechc.proofs.hold import HOLD_FACTOR, static_path
from mechc.proofs.prune import blocker
from mechc.proofs.settings import dyn_settings
from mechc.proofs.timing import cell_tables, predict_changes, prove_timing
from tests.helpers import EXAMPLES, run_subprocess

LIB = load_library()
BASE = DynSettings().settle_time


@pytest.fixture(scope="module")
def adder4():
    """A 4-bit ripple-carry adder built multi-level: its carry chain is deeper than the
    two-level circuits' (static path above the default hold)."""
    return compile_spec(load_spec(EXAMPLES / "multilevel" / "adder4.v"),
                        CompileOptions(levels="multi"))


def _delays(design, move_time):
    """Each cell's lag and settle extra read from its table directly (the slower direction,
    or its stated delay), as a reader of the tables would."""
    tabs = Tables(LIB)
    loads = net_loads(design.mechanism)
    lag, extra = {}, {}
    for c in design.netlist.cells.values():
        tab = tabs.get(c.cell, c.type, len(c.inputs), dict(c.params),
                       design.mechanism.ctx.stroke)
        v = tab.at(move_time, loads.get(c.outputs[0], 0.0)) if tab else {}
        stated = float(getattr(LIB[c.cell], "switching_delay_s", 0.0) or 0.0)
        lag[c.id] = max(stated, v.get("lag_s", 0), v.get("lag_on_s", 0), v.get("lag_off_s", 0))
        extra[c.id] = max(0.0, v.get("settle_extra_s", 0), v.get("settle_extra_on_s", 0),
                          v.get("settle_extra_off_s", 0))
    return lag, extra


def test_static_path_is_the_longest_chain_of_every_path_enumerated(adder4):
    nl = adder4.netlist
    lag, extra = _delays(adder4, 0.08)
    cells = nx.DiGraph(nl.combinational_graph().subgraph(nl.cells))
    best, best_path = 0.0, None
    for end in cells:
        for start in (n for n in cells if cells.in_degree(n) == 0):
            for p in nx.all_simple_paths(cells, start, end) if start != end else [[end]]:
                s = sum(lag[c] for c in p) + extra[end]
                if s > best:
                    best, best_path = s, p
    got = static_path(adder4, LIB, 0.08)
    assert got.seconds == pytest.approx(best, rel=1e-12)
    assert sum(lag[c] for c in got.cells) + extra[got.cells[-1]] == pytest.approx(best)
    assert len(got.cells) == len(best_path)
    # a carry chain: more than a two-level circuit's two cells, and beyond the default hold
    assert len(got.cells) > 2 and HOLD_FACTOR * got.seconds > BASE


def test_every_level_uses_the_designs_hold_and_hold_replaces_it(adder4):
    path = static_path(adder4, LIB, 0.08)
    st = dyn_settings(adder4, LIB)
    assert st.settle_time == pytest.approx(HOLD_FACTOR * path.seconds)
    assert st.to_json()["hold_from"] == "static path"
    assert st.to_json()["static_path"]["cells"] == list(path.cells)
    timing = prove_timing(adder4, adder4.spec, LIB, ProofSettings(cases=0))
    assert timing.figures["budget_s"] == pytest.approx(0.08 + st.settle_time, abs=1e-5)
    assert "each change held" in timing.summary_text()
    # a slower input move reads the tables at another speed: the hold follows
    assert dyn_settings(adder4, LIB, move_time=0.16).settle_time != st.settle_time
    given = dyn_settings(adder4, LIB, hold=0.05)
    assert given.settle_time == 0.05 and given.hold_from == "--hold"
    # without a library (the physics harnesses at fixed settings): the default
    assert dyn_settings(adder4).settle_time == BASE


def test_small_and_sequential_designs_keep_their_holds():
    sorter = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    st = dyn_settings(sorter, LIB)
    assert st.settle_time == BASE and st.hold_from == "default"
    assert HOLD_FACTOR * st.static_path["seconds"] < BASE
    toggle = compile_spec(parse_fsm_file(EXAMPLES / "toggle.fsm"))
    assert dyn_settings(toggle, LIB).hold_from == "memories"


def test_a_cell_that_cannot_be_measured_counts_its_stated_delay(monkeypatch):
    """A cell too broken to switch alone (the proof after reports it) must not stop the proof
    deriving its hold: its stated delay stands in, and the report lists it."""
    from mechc.cells import characterise

    adder = compile_spec(load_spec(EXAMPLES / "full_adder.bool"))
    broken = sorted(adder.netlist.cells)[0]
    real = characterise.Tables.get

    def get(self, cell, type_name, n, params, stroke):
        if (cell, n) == (adder.netlist.cells[broken].cell,
                         len(adder.netlist.cells[broken].inputs)):
            raise KeyError("cannot be measured")
        return real(self, cell, type_name, n, params, stroke)

    monkeypatch.setattr(characterise.Tables, "get", get)
    st = dyn_settings(adder, LIB)
    assert broken in st.static_path["untabled"] and st.settle_time == BASE


def test_a_deep_chain_settles_within_its_own_hold_not_the_default(adder4):
    """The change the timing level predicts latest, run in pymunk: at the default hold it is
    still moving (or not yet at its outputs) when judged; at the design's hold it passes."""
    names = list(adder4.spec.inputs)
    own = dyn_settings(adder4, LIB)
    pairs, _ = plan_changes(adder4, names, 16, 0,
                            independent=blocker(adder4.netlist, LIB) is None)
    tables, _ = cell_tables(adder4, LIB, None, names, pairs)
    timed = predict_changes(adder4, LIB, names, pairs, own, tables)
    late = max(range(len(timed)), key=lambda k: timed[k]["settle_s"])
    assert timed[late]["settle_s"] > own.move_time + BASE  # predicted beyond the default
    short = dyn_settings(adder4, LIB, hold=BASE)
    slow = prove_dynamic(adder4, adder4.spec, LIB, short, only=[late], recheck=False)
    fine = prove_dynamic(adder4, adder4.spec, LIB, own, only=[late], recheck=False)
    assert not slow.passed and set(slow.failure_kinds) <= {"settle", "rest"}
    assert fine.passed, fine.failures


def test_a_settle_failure_names_the_hold():
    r = run_subprocess("simulate", EXAMPLES / "full_adder.bool", "--level", "dynamic",
                       "--move-time", "0.01", "--no-recheck")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "still moving when the 0.150 s hold ran out" in r.stdout
    assert "longer --hold S" in r.stdout


def test_cli_hold_option(tmp_path):
    r = run_subprocess("simulate", EXAMPLES / "sorter.bool", "--level", "logic", "--hold", "0.3")
    assert r.returncode == 2 and "--hold" in r.stderr and "Traceback" not in r.stderr
    r = run_subprocess("simulate", EXAMPLES / "sorter.bool", "--hold", "0")
    assert r.returncode == 2 and "--hold must be positive" in r.stderr
    r = run_subprocess("simulate", EXAMPLES / "full_adder.bool", "--level", "timing",
                       "--hold", "0.3")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "each change held 0.300 s after its move: as --hold asked" in r.stdout
    assert "budget 0.380 s" in r.stdout


def test_a_table_measured_for_the_hold_shows_progress(tmp_path, monkeypatch):
    """A cell with no shipped table is measured on first use before the proof's first change
    (seconds per cell, 12 s for random81's): the proof's progress is told so, naming the cell,
    and the CLI prints it; with the table cached, nothing is measured again."""
    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path))
    spec = tmp_path / "and4.bool"
    spec.write_text("inputs a b c d\noutputs z\nz = a & b & c & d\n")
    d = compile_spec(load_spec(spec))
    assert any(len(c.inputs) == 4 for c in d.netlist.cells.values())  # not shipped
    seen: list[tuple] = []
    from mechc.proofs import prove

    rep = prove(d, d.spec, LIB, "dynamic", ProofSettings(jobs=1),
                lambda done, total, *what: seen.append((done, total, *what)))
    assert rep.passed, rep.failures[:3]
    measuring = [s for s in seen if len(s) == 3]
    changes = [s for s in seen if len(s) == 2]
    assert measuring and changes and seen.index(measuring[-1]) < seen.index(changes[0])
    assert measuring[-1][0] == measuring[-1][1] and "(first use)" in measuring[-1][2]
    assert any(f"'{c.cell}'" in measuring[-1][2] for c in d.netlist.cells.values())
    seen.clear()
    dyn_settings(d, LIB, progress=lambda *a: seen.append(a))
    assert not seen  # cached now

    monkeypatch.setenv("MECHC_CACHE_DIR", str(tmp_path / "empty"))
    r = run_subprocess("simulate", spec, "--level", "dynamic", "--jobs", "1")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "measuring the timing of cell 'and' (first use)" in r.stderr
