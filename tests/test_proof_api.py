"""The one proof entry: every (level, kind) has an engine, ``prove`` gives the engine's own
report, refuses what ``mechc simulate`` refuses, and a report's JSON keeps its key order."""

from __future__ import annotations

import pytest

from mechc.cells.library import load_library
from mechc.errors import UsageError
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.pipeline import compile_sequential, compile_spec
from mechc.proofs import KINDS, LEVELS, ProofReport, ProofSettings, dyn_settings, prove
from mechc.proofs.hold import settle_allowance
from mechc.proofs.logic import prove_logic
from mechc.proofs.registry import engine
from mechc.proofs.seq_logic import prove_sequential
from tests.helpers import EXAMPLES

LIB = load_library()


@pytest.fixture(scope="module")
def sorter():
    return compile_spec(load_spec(EXAMPLES / "sorter.bool"))


@pytest.fixture(scope="module")
def toggle():
    return compile_sequential(parse_fsm_file(EXAMPLES / "toggle.fsm"), mechanism=False)


def _timeless(r: ProofReport) -> dict:
    return {k: v for k, v in r.to_json().items() if k != "seconds"}


def test_every_level_and_kind_has_one_engine():
    for level in LEVELS:
        for kind in KINDS:
            with pytest.raises(ValueError, match="two engines"):
                engine(level, kind)(lambda *a: None)


def test_prove_gives_the_engines_report(sorter, toggle):
    r = prove(sorter, sorter.spec, LIB, "logic")
    assert (r.level, r.kind, r.passed, r.cases) == ("logic", "combinational", True, 16)
    assert _timeless(r) == _timeless(prove_logic(sorter.netlist, sorter.spec))
    s = prove(toggle, toggle.spec, LIB, "logic", ProofSettings(seed=3))
    assert s.kind == "sequential" and s["sequential"]["memories"] == 2
    assert _timeless(s) == _timeless(prove_sequential(toggle.netlist, toggle.spec, seed=3))


def test_prove_refuses_what_the_cli_refuses(sorter, toggle):
    with pytest.raises(UsageError, match="sequential design"):
        prove(toggle, sorter.spec, LIB, "logic")
    adder = load_spec(EXAMPLES / "full_adder.bool")
    with pytest.raises(UsageError, match="differ from the spec"):
        prove(sorter, adder, LIB, "kinematic")
    with pytest.raises(UsageError, match="no geometry"):
        prove(toggle, toggle.spec, LIB, "kinematic")


def test_report_json_order_and_reads():
    r = ProofReport(level="kinematic", kind="sequential", passed=True, cases=3,
                    failure_count=0, failures=[], seconds=0.5,
                    coverage={"steps": 3, "memories": 1}, failure_kinds={},
                    overlaps_by_cell={}, figures={"max_deviation_fraction": 0.0})
    assert list(r) == ["passed", "level", "steps", "cases", "memories", "failure_count",
                       "failure_kinds", "overlaps_by_cell", "failures",
                       "max_deviation_fraction", "seconds"]
    assert r["cases"] == 3 and r.get("accuracy") is None
    r.add_failure("accuracy", "not met")
    assert not r.passed and r["failure_kinds"] == {"accuracy": 1}
    assert r.summary_text().splitlines()[-1] == "  not met"


def test_default_dyn_settings(sorter, toggle):
    st = dyn_settings(sorter, dt=1e-4)
    assert st.violation_limit == 0.005 * sorter.mechanism.ctx.stroke and st.dt == 1e-4
    assert dyn_settings(toggle).violation_limit == 0.1  # no geometry: no stroke to scale by
    slow = dyn_settings(toggle, LIB)
    assert slow.settle_time == max(0.15, settle_allowance(toggle, LIB)) > 0.15


def test_a_sampled_proof_says_so_in_its_verdict():
    def report(exhaustive: bool) -> ProofReport:
        return ProofReport(level="kinematic", kind="combinational", passed=True, cases=512,
                           failure_count=0, failures=[], seconds=0.1,
                           coverage={"exhaustive": exhaustive})

    assert "512 sampled cases (not exhaustive)" in report(False).summary_text()
    assert "512 cases," in report(True).summary_text()
    assert "sampled" not in report(True).summary_text()
