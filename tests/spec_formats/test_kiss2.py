"""The KISS2 front end: machines transcribed by hand from the .fsm examples read back as the same
flow tables (or machines with the same behaviour), every error located, and the whole
sequential pipeline (compile, logic and kinematic proofs) run from a .kiss2 file."""

from __future__ import annotations

import re

import pytest

from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm, parse_fsm_file
from mechc.frontends.kiss2 import gray_order, parse_kiss, parse_kiss_file
from mechc.ir.seqspec import (
    FlowTable,
    SeqSpec,
    allowed_changes,
    initial_total_state,
    next_stable,
    output_values,
)
from tests.helpers import EXAMPLES

# examples/speedctl.fsm (001_… Table VIII) transcribed by hand, one line per specified entry;
# the outputs of unstable lines are written '--' (transient, not part of the table)
SPEEDCTL_KISS2 = """\
.i 2
.o 2
.ilb x1 x2
.ob Z1 Z2
.s 6
.r 1
00 1 1 10
01 1 3 --
10 1 2 --
00 2 4 --
11 2 5 --
10 2 2 10
00 3 1 --
01 3 3 11
00 4 4 11
01 4 3 --
10 4 2 --
11 5 5 00
10 5 6 --
00 6 1 --
10 6 6 00
.e
"""

# examples/gated_latch.fsm written with '*' (any present state) for the two gate-on columns:
# '01 * 2' and '11 * 3' also specify 4 → 2, 5 → 2, 1 → 3 and 6 → 3, which are changes of both
# inputs at once (the .fsm leaves them '-'); every single-input change is the .fsm's
LATCH_KISS2 = """\
.i 2
.o 1
.ilb D G
.ob Q
.r 1
# D G = 00 and 10: the gate is off, Q holds
00 1 1 0
00 2 1 -
00 4 1 -
00 6 6 1
00 5 6 -
10 1 4 -
10 4 4 0
10 3 5 -
10 5 5 1
10 6 5 -
# the gate is on: Q follows D from any state
01 * 2 -
01 2 2 0
11 * 3 -
11 3 3 1
.end
"""


def entries(ft: FlowTable) -> dict[tuple[str, int], str | None]:
    """(row name, input vector) -> next row name (None for '-'), independent of row order."""
    return {(ft.rows[r], x): (None if ft.next[r][k] is None else ft.rows[ft.next[r][k]])
            for r in range(len(ft.rows)) for k, x in enumerate(ft.columns)}


def outputs(ft: FlowTable) -> dict[str, list[int | None]]:
    return {name: list(ft.out[r]) for r, name in enumerate(ft.rows)}


def start(spec: SeqSpec) -> tuple[str, int]:
    ft = spec.table
    return ft.rows[ft.initial], ft.columns[ft.start_column()]


def walk_together(a: SeqSpec, b: SeqSpec) -> int:
    """Runs both machines side by side from power-up over every single-input change either
    specifies; the same changes must be specified and the outputs must agree at every stable
    total state reached. Returns the number of (inputs, state a, state b) visited."""
    assert a.inputs == b.inputs and a.outputs == b.outputs
    (xa, sa), (xb, sb) = initial_total_state(a), initial_total_state(b)
    assert xa == xb
    seen: set[tuple[int, int, int]] = set()
    todo = [(xa, sa, sb)]
    while todo:
        x, p, q = todo.pop()
        if (x, p, q) in seen:
            continue
        seen.add((x, p, q))
        assert output_values(a, p, x) == output_values(b, q, x), (x, p, q)
        changes = allowed_changes(a, p, x)
        assert changes == allowed_changes(b, q, x), (x, p, q)
        for x2 in changes:
            todo.append((x2, next_stable(a, p, x, x2), next_stable(b, q, x, x2)))
    return len(seen)


def test_toggle_example_is_the_fsm_table():
    k = parse_kiss_file(str(EXAMPLES / "toggle.kiss2"))
    f = parse_fsm_file(str(EXAMPLES / "toggle.fsm"))
    assert (k.inputs, k.outputs) == (f.inputs, f.outputs) == (["T"], ["Q"])
    assert sorted(k.table.rows) == sorted(f.table.rows)
    assert entries(k.table) == entries(f.table)
    assert outputs(k.table) == outputs(f.table)
    assert start(k) == start(f) == ("a", 0)
    assert k.kind == "fsm" and k.form == "table"


def test_speedctl_transcription_is_the_fsm_table():
    k = parse_kiss(SPEEDCTL_KISS2, "speedctl.kiss2")
    f = parse_fsm_file(str(EXAMPLES / "speedctl.fsm"))
    assert k.inputs == ["x1", "x2"] and k.outputs == ["Z1", "Z2"]
    assert k.table.rows == f.table.rows  # states in order of first appearance as present state
    assert entries(k.table) == entries(f.table)
    assert outputs(k.table) == outputs(f.table)
    assert start(k) == start(f) == ("1", 0b00)
    assert walk_together(k, f) == 6  # the six stable states of Table VIII


def test_any_state_and_cubes_expand_like_the_fsm_latch():
    k = parse_kiss(LATCH_KISS2, "latch.kiss2")
    f = parse_fsm_file(str(EXAMPLES / "gated_latch.fsm"))
    ek, ef = entries(k.table), entries(f.table)
    assert set(k.table.columns) == set(f.table.columns) == {0, 1, 2, 3}
    assert outputs(k.table) == outputs(f.table)
    # every entry the .fsm gives is the same; the only extra ones come from the '*' lines and
    # are changes of both inputs from the row's stable column (kept as written, as .fsm would)
    extra = {key: v for key, v in ek.items() if ef[key] is None and v is not None}
    assert all(ek[key] == v for key, v in ef.items() if v is not None)
    assert extra == {("4", 0b01): "2", ("5", 0b01): "2", ("1", 0b11): "3", ("6", 0b11): "3"}
    stable_col = {name: x for (name, x), v in ef.items() if v == name}
    for (name, x) in extra:
        assert bin(stable_col[name] ^ x).count("1") == 2
    assert walk_together(k, f) == 6


def test_cube_dashes_expand_to_every_column():
    # a 3-input machine: '-1-' covers 010 011 110 111
    k = parse_kiss(".i 3\n.o 1\n-00 a a 0\n-1- a b -\n-1- b b 1\n000 b a -\n", "d.kiss2")
    e = entries(k.table)
    assert {x for (r, x), v in e.items() if r == "a" and v == "b"} == {0b010, 0b011, 0b110,
                                                                      0b111}
    assert {x for (r, x), v in e.items() if r == "a" and v == "a"} == {0b000, 0b100}
    assert k.inputs == ["x0", "x1", "x2"] and k.outputs == ["f0"]  # .pla's default names
    # columns are the vectors some line covers, in Gray order
    assert k.table.columns == [x for x in gray_order(3) if x != 0b001 and x != 0b101]


def test_state_stable_in_columns_with_different_outputs_is_split():
    """KISS2 gives outputs per line (state and input); a flow-table row has one output vector,
    so a state stable under inputs with different outputs becomes one row per output vector.
    Reference: the same machine written by hand as an .fsm table with rows p, r, s."""
    k = parse_kiss(".i 2\n.o 1\n.ilb x y\n.ob z\n"
                   "0- a a 0\n11 a a 1\n10 a b -\n"
                   "10 b b 1\n00 b a -\n11 b a -\n", "split.kiss2")
    f = parse_fsm("inputs x y\noutputs z\ncolumns 00 01 11 10\nflow\n"
                  "p: (p) (p) r s | 0\n"
                  "r: p p (r) s | 1\n"
                  "s: p - r (s) | 1\n"
                  "initial p\n", "split.fsm")
    rename = {"a@00": "p", "a@11": "r", "b": "s"}
    assert sorted(k.table.rows) == sorted(rename)
    assert {(rename[r], x): v and rename[v] for (r, x), v in entries(k.table).items()} \
        == entries(f.table)
    assert {rename[r]: o for r, o in outputs(k.table).items()} == outputs(f.table)
    assert walk_together(k, f) == 4


def test_reset_state_and_its_first_stable_line():
    text = ".i 1\n.o 1\n.r b\n0 a a 0\n1 a b -\n1 b b 1\n0 b a -\n"
    k = parse_kiss(text, "r.kiss2")
    assert start(k) == ("b", 1)
    assert start(parse_kiss(text.replace(".r b\n", ""), "r.kiss2")) == ("a", 0)


def test_load_spec_dispatch():
    assert isinstance(load_spec(EXAMPLES / "toggle.kiss2"), SeqSpec)
    p = EXAMPLES / "toggle.kiss2"
    assert load_spec(p).table.rows == parse_kiss_file(str(p)).table.rows


# (content, line:col, message fragment); each must exit 2 with one located line
ERRORS = [
    ("", "1:1", "empty KISS2 file"),
    (".i 1\n.o 1\n0 a b 0\n1 b b 1\n0 b a 1\n", "3:3", "state a is never stable"),
    # b at 0 goes to c, but c has no entry at 0 (a transition into a state not stable there)
    (".i 1\n.o 1\n0 a a 0\n1 a b -\n1 b b 1\n0 b c -\n1 c c 0\n", "6:5",
     "unstable entry c in row b: column 0 has no stable state c"),
    (".i 1\n.o 1\n0 a a 0\n- a b 0\n1 b b 1\n", "4:5",
     "state a at input 0 goes to b here but to a on line 3"),
    (".i 1\n.o 2\n0 a a 01\n0 a a 00\n", "4:8", "output 2 is 0 here but 1 on line 3"),
    (".i 1\n.o 1\n0 a a 0\n1 a b 0\n0 b b 1\n1 b a 1\n", "4:5", "oscillates in column 1"),
    (".i 2\n.o 1\n0x a a 0\n", "3:2", "bad input character 'x'"),
    (".i 2\n.o 1\n0 a a 0\n", "3:1", "has 1 character(s); expected 2"),
    (".i 1\n.o 1\n0 a a 0 1\n", "3:9", "4 fields"),
    (".i 1\n.o 1\n.latch x\n", "3:1", "unknown keyword '.latch'"),
    (".i 1\n.o 1\n.r zz\n0 a a 0\n", "3:4", "reset state zz does not appear"),
    (".i 13\n.o 1\n", "1:4", "at most 12"),
    (".i 1\n.o 0\n", "2:4", "'.o' must be at least 1"),
    ("0 a a 0\n", "1:1", "before '.i' and '.o'"),
    (".i 1\n.o 1\n0 a a 0\n.e\n1 a a 0\n", "5:1", "text after '.e'"),
    (".i 1\n.o 1\n.ilb 9x\n", "3:6", "not usable as a signal name"),
    (".i 1\n.o 1\n0 a(1) a 0\n", "3:3", "not a usable state name"),
]


@pytest.mark.parametrize("content, where, fragment", ERRORS, ids=[e[2][:30] for e in ERRORS])
def test_errors_are_located_exit_2(cli, tmp_path, content, where, fragment):
    spec = tmp_path / "m.kiss2"
    spec.write_text(content)
    code, _, err = cli("compile", spec, "-o", tmp_path / "m.json")
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"{spec}:{where}: error: "), lines[0]
    assert fragment in lines[0], lines[0]
    assert not (tmp_path / "m.json").exists()


def test_kiss2_design_proves_against_the_fsm_and_fails_a_mutant(cli, tmp_path):
    spec = tmp_path / "speedctl.kiss2"
    spec.write_text(SPEEDCTL_KISS2)
    design = tmp_path / "s.json"
    code, _, err = cli("compile", spec, "-o", design)
    assert code == 0, err
    # the logic-level proof from the .kiss2 and from the .fsm walk the same machine
    runs = []
    for src in (spec, EXAMPLES / "speedctl.fsm"):
        code, out, _ = cli("simulate", src, "--level", "logic")
        assert code == 0 and "PASSED" in out
        runs.append(re.findall(r"^(input states / changes|single-input changes)\s+(\d+)", out,
                               re.M))
    assert runs[0] == runs[1] == [("input states / changes", "6"),
                                  ("single-input changes", "9")]  # Table VIII: 6 stable, 9 arrows
    code, out, _ = cli("simulate", design, "--level", "logic", "--spec",
                       EXAMPLES / "speedctl.fsm")
    assert code == 0 and "PASSED" in out
    mutant = tmp_path / "mutant.fsm"
    mutant.write_text((EXAMPLES / "speedctl.fsm").read_text().replace("3: 1 (3) - - | 1 1",
                                                                       "3: 1 (3) - - | 0 1"))
    code, out, _ = cli("simulate", design, "--level", "logic", "--spec", mutant)
    assert code == 1 and "FAILED" in out


def test_latch_with_any_state_compiles_and_proves_against_the_fsm(cli, tmp_path):
    spec = tmp_path / "latch.kiss2"
    spec.write_text(LATCH_KISS2)
    design = tmp_path / "latch.json"
    code, _, err = cli("compile", spec, "-o", design)
    assert code == 0, err
    code, out, _ = cli("simulate", design, "--level", "logic", "--spec",
                       EXAMPLES / "gated_latch.fsm")
    assert code == 0 and "PASSED" in out


def test_toggle_kiss2_end_to_end_kinematic(cli, tmp_path):
    design = tmp_path / "toggle.json"
    code, out, err = cli("compile", EXAMPLES / "toggle.kiss2", "-o", design)
    assert code == 0, err
    assert "MEMORY" in out
    code, out, _ = cli("simulate", design, "--level", "kinematic")
    assert code == 0 and "PASSED: level kinematic" in out
    code, out, _ = cli("simulate", design, "--level", "logic", "--spec", EXAMPLES / "toggle.fsm")
    assert code == 0 and "PASSED" in out


def test_documented_example_is_the_toggle():
    doc = (EXAMPLES.parent / "docs" / "spec-formats.md").read_text()
    block = re.search(r"## `\.kiss2`.*?```\n(.*?)```", doc, re.S)
    assert block, "KISS2 example missing from docs/spec-formats.md"
    d = parse_kiss(block.group(1), "doc.kiss2")
    f = parse_fsm_file(str(EXAMPLES / "toggle.fsm"))
    assert entries(d.table) == entries(f.table) and outputs(d.table) == outputs(f.table)
    assert start(d) == start(f)
