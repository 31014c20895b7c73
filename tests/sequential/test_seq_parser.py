"""The .fsm front end: both forms exactly as the issue writes them, every error located by file,
line and column, and the reference semantics read from the parsed spec."""

from __future__ import annotations

import pytest

from mechc.errors import SpecError
from mechc.frontends.fsm import parse_fsm, parse_fsm_file
from mechc.frontends.spec_json import seqspec_from_json
from mechc.ir.seqspec import SeqSpec, output_values, stable_graph
from tests.helpers import EXAMPLES

# the two cores of issue 4, verbatim
ISSUE_SR = """\
# set/reset form
inputs x1 x2
outputs Z1 Z2
memory y1 set x2 reset x1 & ~x2 & y2 initial 1
memory y2 set ~x1 reset x1 & x2 initial 1
Z1 = y2
Z2 = ~x1 & (x2 | ~y1)
"""

ISSUE_TABLE = """\
# primitive flow table form (fundamental mode)
inputs x1 x2
outputs Z1 Z2
columns 00 01 11 10
flow
1: (1) 3 - 2 | 1 0
2: 4 - 5 (2) | 1 0
3: 1 (3) - - | 1 1
4: (4) 3 - 2 | 1 1
5: - - (5) 6 | 0 0
6: 1 - - (6) | 0 0
initial 1
"""

# Table VIII of 001 (Appendix B), read off the scan by hand: stable state -> (x1x2, Z1Z2)
TABLE_VIII_STABLE = {"1": ("00", "10"), "2": ("10", "10"), "3": ("01", "11"),
                     "4": ("00", "11"), "5": ("11", "00"), "6": ("10", "00")}


def test_issue_table_parses_as_table_viii():
    spec = parse_fsm(ISSUE_TABLE, "t.fsm")
    ft = spec.table
    assert spec.form == "table" and ft.rows == ["1", "2", "3", "4", "5", "6"]
    assert [ft.label(k) for k in range(4)] == ["00", "01", "11", "10"]
    for r, name in enumerate(ft.rows):
        col, outs = TABLE_VIII_STABLE[name]
        k = [ft.label(j) for j in range(4)].index(col)
        assert ft.stable(r, k)
        assert "".join(map(str, ft.out[r])) == outs
    # the desired speed cycle of Appendix B.1: 1 -> 2 -> 5 -> 6 -> 1
    g = stable_graph(spec)
    succ = {(x, ft.rows[s]): [(x2, ft.rows[t[1]]) for x2, t in outs] for (x, s), outs in
            g.edges.items()}
    assert (0b10, "2") in succ[(0b00, "1")]
    assert (0b11, "5") in succ[(0b10, "2")]
    assert (0b10, "6") in succ[(0b11, "5")]
    assert (0b00, "1") in succ[(0b10, "6")]
    assert len(g.nodes) == 6


def test_issue_setreset_parses_and_follows_eq_b1():
    spec = parse_fsm(ISSUE_SR, "s.fsm")
    assert spec.form == "setreset" and spec.memory_names == ["y1", "y2"]
    assert [m.initial for m in spec.memories] == [1, 1]
    g = stable_graph(spec)
    # 001 Table IX: the six stable states and their outputs (y1 y2 from column V)
    want = {(0b00, 0b11): (1, 0), (0b10, 0b01): (1, 0), (0b01, 0b11): (1, 1),
            (0b00, 0b01): (1, 1), (0b11, 0b10): (0, 0), (0b10, 0b10): (0, 0)}
    assert set(g.nodes) == set(want)
    for (x, q), z in want.items():
        assert tuple(output_values(spec, q, x).values()) == z


def test_examples_parse():
    for name in ("speedctl", "speedctl_sr", "toggle", "gated_latch", "sequence_detector"):
        spec = parse_fsm_file(str(EXAMPLES / f"{name}.fsm"))
        assert isinstance(spec, SeqSpec) and stable_graph(spec).transitions > 0


T = ISSUE_TABLE.splitlines()  # line k of the file is T[k - 1]


def table_with(lineno: int, text: str) -> str:
    lines = list(T)
    lines[lineno - 1] = text
    return "\n".join(lines) + "\n"


S = ISSUE_SR.splitlines()


def sr_with(lineno: int, text: str) -> str:
    lines = list(S)
    lines[lineno - 1] = text
    return "\n".join(lines) + "\n"


# (case, text, line, column, words the message must contain)
ERRORS = [
    # malformed tables
    ("row without ':'", table_with(6, "1 (1) 3 - 2 | 1 0"), 6, 3, "expected ':'"),
    ("bad entry", table_with(6, "1: (1) 3 * 2 | 1 0"), 6, 10, "unexpected character"),
    ("unclosed stable entry", table_with(6, "1: (1 3 - 2 | 1 0"), 6, 7, "expected ')'"),
    ("output not binary", table_with(6, "1: (1) 3 - 2 | 1 2"), 6, 18, "output values"),
    ("flow before columns", "inputs a\noutputs z\nflow\n1: (1) | 0\n", 3, 1, "'columns'"),
    ("duplicate row", table_with(7, "1: 4 - 5 (1) | 1 0"), 7, 1, "defined a second time"),
    ("unknown state", table_with(6, "1: (1) 9 - 2 | 1 0"), 6, 8, "no row is named 9"),
    ("self entry unbracketed", table_with(8, "3: 1 3 - - | 1 1"), 8, 6, "own row"),
    ("stable entry of another row", table_with(8, "3: 1 (4) - - | 1 1"), 8, 6,
     "must name its own row"),
    # a stable state missing from its own row
    ("stable state missing", table_with(8, "3: 1 - - - | 1 1"), 8, 1,
     "state 3 is missing from its own row"),
    # an unstable entry whose column has no stable state of that name
    ("dangling entry", table_with(6, "1: (1) 5 - 2 | 1 0"), 6, 8,
     "column 01 has no stable state 5"),
    # inconsistent widths
    ("column label width", table_with(4, "columns 00 01 11 100"), 4, 18, "3 digit(s); expected 2"),
    ("column label not binary", table_with(4, "columns 00 01 12 10"), 4, 15, "binary"),
    ("too few entries", table_with(6, "1: (1) 3 - | 1 0"), 6, 12,
     "has 3 entries; 'columns' lists 4"),
    ("too many entries", table_with(6, "1: (1) 3 - 2 2 | 1 0"), 6, 14, "more than 4 entries"),
    ("too few outputs", table_with(6, "1: (1) 3 - 2 | 1"), 6, 14, "1 output value(s); expected 2"),
    ("too many outputs", table_with(6, "1: (1) 3 - 2 | 1 0 1"), 6, 20, "more than 2 output"),
    ("initial vector width", table_with(12, "initial 1 000"), 12, 11, "expected 2"),
    # a row whose entries lead to an oscillation (1 -> 3 -> 1 in column 01)
    ("oscillation", table_with(8, "3: (3) 1 - - | 1 1"), 6, 8, "rows 1 → 3 → 1"),
    ("initial unknown", table_with(12, "initial 9"), 12, 9, "not a row"),
    ("initial not stable there", table_with(12, "initial 1 10"), 12, 11, "not stable"),
    ("both forms", ISSUE_TABLE + "Z1 = x1\n", 13, 1, "mixes the two forms"),
    ("duplicate column", table_with(4, "columns 00 01 01 10"), 4, 15, "listed twice"),
    # set/reset form
    ("unknown name", sr_with(6, "Z1 = y3"), 6, 6, "unknown name 'y3'"),
    ("output in expression", sr_with(6, "Z1 = Z2"), 6, 6, "is an output"),
    ("missing reset", sr_with(4, "memory y1 set x2 initial 1"), 4, 18, "'reset'"),
    ("initial not 0/1", sr_with(4, "memory y1 set x2 reset x1 initial 2"), 4, 35, "0 or 1"),
    ("undefined output", "\n".join(S[:6]) + "\n", 3, 12, "never defined"),
    ("memory named like input", sr_with(4, "memory x1 set x2 reset x1"), 4, 8, "duplicate"),
    ("keyword as name", "inputs set\n", 1, 8, "keyword"),
    ("assign to input", sr_with(6, "x1 = y2"), 6, 1, "is an input"),
    ("empty", "", 1, 1, "empty specification"),
]


@pytest.mark.parametrize("case, text, line, col, words", ERRORS, ids=[e[0] for e in ERRORS])
def test_errors_located(case, text, line, col, words):
    with pytest.raises(SpecError) as ei:
        parse_fsm(text, "bad.fsm")
    e = ei.value
    assert (e.path, e.line, e.col) == ("bad.fsm", line, col), str(e)
    assert words in e.message, e.message
    assert str(e).startswith(f"bad.fsm:{line}:{col}: error: ")


SR_HEAD = "inputs x\noutputs Z\n"


@pytest.mark.parametrize("body, kind", [
    # x rises: S and R of y both on (y = S + y·R' is undefined there; Fig. 9 forbids it)
    ("memory y set x reset x\nZ = y\n", "SET and RESET of y are both on"),
    # x rises: a and b both excited; b stays set only if it switches before a
    ("memory a set x reset ~x\nmemory b set x & ~a reset ~x\nZ = b\n", "critical race"),
    # x rises: a is set, which resets it, which sets it ...
    ("memory a set x & ~a reset x & a\nZ = a\n", "oscillate"),
])
def test_setreset_spec_rejected_at_its_memory(body, kind):
    with pytest.raises(SpecError) as ei:
        parse_fsm(SR_HEAD + body, "m.fsm")
    assert kind in ei.value.message
    assert ei.value.line == 3 and ei.value.col == 8  # the (first) memory's name


def test_extensions_chains_dc_outputs_assign_start():
    # a chained entry: row 1 in column 1 goes to 2, which goes on to 3 (stable there)
    text = ("inputs a\noutputs z\ncolumns 0 1\nflow\n1: (1) 2 | 0\n2: (2) 3 | -\n3: 1 (3) | 1\n"
            "assign 1=00 2=01 3=11\nsecondary p q\ninitial 1 0\n")
    spec = parse_fsm(text, "c.fsm")
    ft = spec.table
    assert ft.dest(0, 1) == 2 and ft.out[1] == [None]
    assert ft.assign == {"1": "00", "2": "01", "3": "11"} and ft.secondary == ["p", "q"]
    sr = parse_fsm("inputs a b\noutputs z\nmemory m set a & ~b reset b\nz = m\nstartup 01\n",
                   "s.fsm")
    assert sr.start_inputs == 0b01


def test_json_round_trip_keeps_behaviour():
    for text in (ISSUE_TABLE, ISSUE_SR):
        spec = parse_fsm(text, "r.fsm")
        back = seqspec_from_json(spec.to_json())
        g1, g2 = stable_graph(spec), stable_graph(back)
        assert g1.nodes == g2.nodes and g1.edges == g2.edges
