"""The speed controller as a mechanism: `mechc simulate` passes at every level, and the
kinematic proof, like the logic one, fails on every single output mutation of the table."""

from __future__ import annotations

import json

import pytest

from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm, parse_fsm_file
from mechc.pipeline import compile_sequential
from mechc.proofs.seq_mechanism import prove_sequential_kinematic
from tests.helpers import EXAMPLES
from tests.sequential.test_seq_proof import mutations


@pytest.mark.parametrize("level", ["logic", "kinematic", "dynamic"])
def test_speed_controller_passes_every_level(cli, tmp_path, level):
    rep = tmp_path / "r.json"
    code, stdout, err = cli("simulate", EXAMPLES / "speedctl.fsm", "--level", level,
                            "--report", rep)
    assert code == 0, stdout + err
    r = json.loads(rep.read_text())
    assert r["passed"] and r["failure_count"] == 0
    if level == "dynamic":  # the covering tour and the random walks, all of them run
        assert r["cases"] >= 9 and r["max_position_error_fraction"] <= 0.05


def test_kinematic_proof_fails_on_every_output_mutation():
    lib = load_library()
    path = EXAMPLES / "speedctl.fsm"
    spec = parse_fsm_file(str(path))
    design = compile_sequential(spec, library=lib)
    assert prove_sequential_kinematic(design, spec, lib)["passed"]
    count = 0
    for line, j, text in mutations(path.read_text()):
        rep = prove_sequential_kinematic(design, parse_fsm(text, f"mutated line {line}"), lib)
        assert not rep["passed"], f"line {line} output {j}"
        assert rep["failure_kinds"].get("rest", 0) >= 1
        count += 1
    assert count == 12


@pytest.mark.parametrize("level", ["logic", "kinematic", "dynamic"])
def test_textbook_starter_passes_every_level(cli, tmp_path, level):
    # the motor starter of test_seq_cli (not an example): compiled and proved from the .fsm
    from tests.sequential.test_seq_cli import STARTER

    spec = tmp_path / "starter.fsm"
    spec.write_text(STARTER)
    code, stdout, err = cli("simulate", spec, "--level", level)
    assert code == 0 and "PASSED" in stdout, stdout + err


@pytest.mark.parametrize("level", ["kinematic", "dynamic"])
def test_three_variable_table_passes_mechanism_levels(cli, tmp_path, level):
    # the four-state table that needs a third state variable: three memories feeding one
    # another, so their outputs go behind force AMPLIFIERs (at most 2 loads each)
    from tests.sequential.test_seq_synthesis import FOUR_STATE

    spec = tmp_path / "four.fsm"
    spec.write_text(FOUR_STATE)
    code, stdout, err = cli("simulate", spec, "--level", level)
    assert code == 0 and "PASSED" in stdout, stdout[-2000:] + err


def test_sequential_dynamic_reports_a_too_large_time_step(cli, tmp_path):
    # the solver settings reach the sequential proof; 8x the default step breaks the contacts,
    # which must be reported as failures, never a pass
    rep = tmp_path / "r.json"
    code, stdout, _ = cli("simulate", EXAMPLES / "gated_latch.fsm", "--dt", "0.002",
                          "--report", rep)
    assert code == 1 and "FAILED" in stdout
    r = json.loads(rep.read_text())
    assert r["settings"]["dt_s"] == 0.002
    assert set(r["failure_kinds"]) & {"contact", "solver", "settle"}
