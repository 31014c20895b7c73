"""Rows a flow table can never reach from power-up are not built, and say so; a table that never
leaves power-up says its proof had nothing to check; no MEMORY is built that never switches.
References are independent: a plain search over the table (seqref.visited_rows), brute-force
merging (seqref.min_reduction_size), and the same table with the row deleted by hand."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechc.bench.circuits import random_flow_table
from mechc.frontends.fsm import parse_fsm
from mechc.ir.seqspec import SeqSpec
from mechc.pipeline import compile_sequential
from mechc.proofs.seq_logic import prove_sequential
from tests.sequential.seqref import min_reduction_size, visited_rows
from tests.sequential.test_seq_synthesis import check_against_table

HEAD = """inputs x1 x2
outputs z
columns 00 01 11 10
flow
a: (a) b - c | 0
b: a (b) d - | 1
c: a - d (c) | 0
d: - b (d) c | 1
"""
ROW_E = "e: (e) b d (e) | 1\n"  # line 9: nothing goes to e
WITH_E = HEAD + ROW_E + "initial a\n"
WITHOUT_E = HEAD + "initial a\n"
# the initial state a has no specified single-input change (01 and 10 are '-')
STUCK = """inputs x1 x2
outputs z
columns 00 01 11 10
flow
a: (a) - b - | 0
b: - (b) (b) - | 1
initial a
"""
# a given assignment whose first variable only separates the unreachable row c
ASSIGNED = """inputs x1 x2
outputs z
columns 00 01 11 10
flow
a: (a) b - - | 0
b: a (b) - - | 1
c: (c) - - (c) | 1
initial a
assign a=00 b=01 c=10
"""


def memories(design) -> int:
    return sum(1 for c in design.netlist.cells.values() if c.type == "MEMORY")


def test_unreachable_row_is_dropped_same_netlist_as_without_it():
    full = parse_fsm(WITH_E, "t.fsm")
    cut = parse_fsm(WITHOUT_E, "u.fsm")
    assert visited_rows(full.table) == {0, 1, 2, 3}
    # kept, e would cost a memory: e and a are both stable at 00 with different outputs
    assert min_reduction_size(full.table) == 2 and min_reduction_size(cut.table) == 1
    d_full = compile_sequential(full, mechanism=False)
    d_cut = compile_sequential(cut, mechanism=False)
    assert memories(d_full) == memories(d_cut) == 0
    assert d_full.netlist.to_text() == d_cut.netlist.to_text()
    assert d_full.sequential.cover["unreachable_rows"] == ["e"]
    assert d_full.sequential.cover["rows"] == 5
    assert any("e (t.fsm:9)" in w for w in d_full.sequential.warnings)
    assert not d_cut.sequential.warnings
    # the logic proof runs against the table as written, over its reachable part, and says so
    rep = prove_sequential(d_full.netlist, full)
    assert rep.passed and rep.figures["sequential"]["rows_never_stable"] == ["e"]
    assert "reachable from power-up" in rep.figures["sequential"]["scope"]


def test_compile_warns_on_stderr_with_file_and_line(cli, tmp_path):
    spec = tmp_path / "t.fsm"
    spec.write_text(WITH_E)
    out = tmp_path / "t.json"
    code, stdout, err = cli("compile", spec, "-o", out)
    assert code == 0, err
    assert "warning: 1 row(s) of the flow table cannot be reached" in err
    assert f"e ({spec}:9)" in err
    assert "unreachable, not built: e" in stdout
    obj = json.loads(out.read_text())
    assert obj["sequential"]["cover"]["unreachable_rows"] == ["e"]


def _random_with_unreachable(count: int) -> list[SeqSpec]:
    found = []
    for seed in range(400):
        rng = np.random.default_rng(7000 + seed)
        ft = random_flow_table(rng, int(rng.integers(3, 8)), int(rng.integers(1, 3)),
                               int(rng.integers(1, 3)), p_entry=0.5)
        if len(visited_rows(ft)) < len(ft.rows):
            found.append(SeqSpec("<random>", ft.inputs, ft.outputs, table=ft))
        if len(found) == count:
            break
    return found


@pytest.mark.parametrize("spec", _random_with_unreachable(8))
def test_random_tables_with_unreachable_rows_prove(spec):
    ft = spec.table
    kept = visited_rows(ft)
    design = compile_sequential(spec, mechanism=False)
    se = design.sequential
    assert sorted(se.cover["unreachable_rows"]) == sorted(
        ft.rows[r] for r in range(len(ft.rows)) if r not in kept)
    assert len(se.classes) <= len(kept)
    rep = prove_sequential(design.netlist, spec)
    assert rep.passed, rep.failures[:2]
    assert check_against_table(spec) >= 0
    for m in se.memories:  # every memory built can switch
        assert (se.text(se.set_names[m]), se.text(se.reset_names[m])) != ("0", "0")


def test_no_change_from_power_up_says_nothing_was_checked(cli, tmp_path):
    spec = parse_fsm(STUCK, "s.fsm")
    design = compile_sequential(spec, mechanism=False)
    assert any("no specified single-input change" in w for w in design.sequential.warnings)
    rep = prove_sequential(design.netlist, spec)
    assert rep.passed and rep.coverage["transitions"] == 0
    assert "power-up state only" in rep.nothing_moved()
    assert "power-up state" in rep.figures["sequential"]["note"]
    path = tmp_path / "s.fsm"
    path.write_text(STUCK)
    code, stdout, err = cli("compile", path, "-o", tmp_path / "s.json")
    assert code == 0, err
    assert "no specified single-input change" in err
    assert "logic proof: proved, 1 cases, 0 failures" in stdout
    assert "(no input change to check: power-up state only)" in stdout


def test_a_table_that_moves_claims_its_transitions():
    design = compile_sequential(parse_fsm(WITHOUT_E, "u.fsm"), mechanism=False)
    rep = prove_sequential(design.netlist, design.spec)
    assert rep.coverage["transitions"] > 0 and rep.nothing_moved() == ""
    assert "note" not in rep.figures["sequential"]


def test_constant_state_variable_is_not_built():
    spec = parse_fsm(ASSIGNED, "a.fsm")
    design = compile_sequential(spec, mechanism=False)
    se = design.sequential
    assert memories(design) == len(se.memories) == 1
    assert (se.text(se.set_names[se.memories[0]]),
            se.text(se.reset_names[se.memories[0]])) != ("0", "0")
    assert any("never set or reset" in w for w in se.warnings)
    assert prove_sequential(design.netlist, spec).passed


def test_kiss2_unreachable_state_named_at_its_first_line():
    from mechc.frontends.kiss2 import parse_kiss
    text = (".i 1\n.o 1\n.s 3\n.r a\n0 a a 0\n1 a b 0\n1 b b 1\n0 b a 1\n"
            "0 c c 1\n1 c c 0\n.e\n")  # nothing goes to c (line 9)
    spec = parse_kiss(text, "m.kiss2")
    design = compile_sequential(spec, mechanism=False)
    gone = design.sequential.cover["unreachable_rows"]
    assert gone and all(r.split("@")[0] == "c" for r in gone)
    assert "(m.kiss2:9)" in design.sequential.warnings[0]
    assert memories(design) == 0 and prove_sequential(design.netlist, spec).passed
