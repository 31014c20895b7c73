"""`mechc compile` and `mechc simulate --level logic` on .fsm specs, end to end."""

from __future__ import annotations

import json

from mechc.backends.design_json import validate
from tests.helpers import EXAMPLES
from tests.sequential.test_seq_synthesis import FOUR_STATE


def test_compile_speedctl_memory_cells(cli, tmp_path):
    out = tmp_path / "s.json"
    code, stdout, err = cli("compile", EXAMPLES / "speedctl.fsm", "-o", out)
    assert code == 0, err
    assert "MEMORY y1: set =" in stdout
    obj = json.loads(out.read_text())
    validate(obj, str(out))
    mems = [c for c in obj["cells"] if c["type"] == "MEMORY"]
    assert len(mems) == 2
    loads = {ld for net in obj["nets"] for ld in net["loads"]}
    drivers = {net["driver"] for net in obj["nets"]}
    for c in mems:
        assert len(c["inputs"]) == 2 and len(c["outputs"]) == 1
        assert c["params"]["initial"] in (0, 1)
        assert {f"{c['id']}.S", f"{c['id']}.R"} <= loads  # pins S and R, in that order
        assert f"{c['id']}.Q" in drivers
    assert obj["spec"]["kind"] == "fsm" and obj["spec"]["form"] == "table"
    assert [m["name"] for m in obj["sequential"]["memories"]] == ["y1", "y2"]
    # the compiled file proves on its own, and fails against a mutated table
    code, stdout, _ = cli("simulate", out, "--level", "logic")
    assert code == 0 and "PASSED" in stdout
    text = (EXAMPLES / "speedctl.fsm").read_text().replace("3: 1 (3) - - | 1 1",
                                                           "3: 1 (3) - - | 1 0")
    bad = tmp_path / "mutated.fsm"
    bad.write_text(text)
    code, stdout, _ = cli("simulate", out, "--level", "logic", "--spec", bad)
    assert code == 1 and "FAILED" in stdout and "Z2: expected 0, got 1" in stdout


# motor starter (a classic fundamental-mode exercise): START turns the motor on, STOP turns it
# off and wins while both are held; the motor runs on when both are released
STARTER = """\
inputs start stop
outputs M
columns 00 01 11 10
flow
1: (1) 2 - 3 | 0
2: 1 (2) 4 - | 0
3: 5 - 4 (3) | 1
4: - 2 (4) 3 | 0
5: (5) 2 - 3 | 1
"""


def test_textbook_tables_not_in_examples(cli, tmp_path):
    spec = tmp_path / "starter.fsm"
    spec.write_text(STARTER)
    out = tmp_path / "starter.json"
    code, stdout, err = cli("compile", spec, "-o", out)
    assert code == 0, err
    # five rows merge into two ({1,2,4} and {3,5}, or with outputs read per total state
    # {1,2} and {3,4,5}): one memory
    obj = json.loads(out.read_text())
    assert len(obj["sequential"]["merged_rows"]) == 2
    assert len(obj["sequential"]["memories"]) == 1
    code, stdout, _ = cli("simulate", out, "--level", "logic")
    assert code == 0 and "PASSED" in stdout
    # the four-state table that needs a third variable, through the logic stages (its memories
    # feed one another; the full compile also needs the mechanism's force budget around them)
    four = tmp_path / "four.fsm"
    four.write_text(FOUR_STATE)
    code, stdout, _ = cli("simulate", four, "--level", "logic")
    # all 10 stable total states (A 1, B 2, C 3, D 4) are reachable, two changes from each
    assert code == 0 and "PASSED" in stdout and "single-input changes    20" in stdout


def test_simulate_examples_logic(cli):
    for name in ("speedctl", "speedctl_sr", "toggle", "gated_latch", "sequence_detector"):
        code, stdout, err = cli("simulate", EXAMPLES / f"{name}.fsm", "--level", "logic")
        assert code == 0, (name, stdout, err)


def test_malformed_fsm_one_line(cli, tmp_path):
    spec = tmp_path / "bad.fsm"
    spec.write_text("inputs a\noutputs z\ncolumns 0 1\nflow\n1: (1) 2 | 0\n")
    code, stdout, err = cli("compile", spec, "-o", tmp_path / "o.json")
    assert code == 2 and stdout == ""
    assert err.strip() == f"{spec}:5:8: error: unknown state 2 in row 1: no row is named 2 " \
                          "(rows: 1)"
    assert not (tmp_path / "o.json").exists()


def test_critical_race_rejected_naming_rows(cli, tmp_path):
    spec = tmp_path / "race.fsm"
    spec.write_text((EXAMPLES / "speedctl.fsm").read_text()
                    + "assign 1=00 3=00 2=11 4=11 5=01 6=01\n")
    code, _stdout, err = cli("compile", spec, "-o", tmp_path / "o.json")
    assert code == 1 and "critical race" in err and "{5,6}" in err


def test_oscillating_row_rejected_naming_rows(cli, tmp_path):
    spec = tmp_path / "osc.fsm"
    spec.write_text("inputs a\noutputs z\ncolumns 0 1\nflow\n1: (1) 2 | 0\n2: (2) 3 | 1\n"
                    "3: (3) 2 | 0\n")
    code, _stdout, err = cli("simulate", spec, "--level", "logic")
    assert code == 2 and ":5:8: error: row 1 oscillates in column 1: rows 2 → 3 → 2" in err


def test_combinational_spec_against_sequential_design(cli, tmp_path):
    spec = tmp_path / "c.bool"
    spec.write_text("inputs x1 x2\noutputs Z1 Z2\nZ1 = x1\nZ2 = x2\n")
    code, _stdout, err = cli("simulate", EXAMPLES / "toggle.fsm", "--level", "logic",
                             "--spec", spec)
    assert code == 2 and "sequential design" in err
