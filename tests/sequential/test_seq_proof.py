"""The logic-level sequential proof: it passes compiled designs, fails on every single output
mutation of the flow table, and finds races, oscillations, S·R overlaps and glitches in
netlists built by hand to have them."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm, parse_fsm_file
from mechc.ir.netlist import CellInst, Netlist
from mechc.ir.seqspec import stable_graph
from mechc.pipeline import compile_sequential
from mechc.proofs.seq_logic import expected_after, prove_sequential, transition_tour
from tests.helpers import EXAMPLES

EXAMPLE_NAMES = ["speedctl", "speedctl_sr", "toggle", "gated_latch", "sequence_detector"]


@pytest.fixture(scope="module")
def compiled():
    """Every example through the logic stages (equations, map with MEMORY cells, place)."""
    out = {}
    for name in EXAMPLE_NAMES:
        path = EXAMPLES / f"{name}.fsm"
        spec = parse_fsm_file(str(path))
        out[name] = (path, spec, compile_sequential(spec, mechanism=False))
    return out


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_examples_pass(compiled, name):
    _path, spec, design = compiled[name]
    rep = prove_sequential(design.netlist, spec)
    assert rep["passed"], rep["failures"]
    g = stable_graph(spec)
    assert rep["cases"] == len(g.nodes) and rep["transitions"] == g.transitions
    mems = [c for c in design.netlist.cells.values() if c.type == "MEMORY"]
    assert mems and all(c.params["initial"] in (0, 1) and len(c.inputs) == 2 for c in mems)


def test_dissertation_solution_meets_table_viii(compiled):
    # the set/reset equations of Appendix B, compiled, proved against the flow table itself
    _p, _s, design = compiled["speedctl_sr"]
    table = parse_fsm_file(str(EXAMPLES / "speedctl.fsm"))
    rep = prove_sequential(design.netlist, table)
    assert rep["passed"] and rep["transitions"] == 9
    # B.2: SET and RESET of y1 move together when x2 rises in state 2 (2 -> 5)
    together = [h for h in rep["sequential"]["hazards"] if h["kind"] == "set-reset-together"]
    assert any(h["memory"] == "y1" and h["input"] == "x2" for h in together)


def mutations(text: str):
    """Every flow-table row with one output value flipped."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if ":" not in line or "|" not in line or line.lstrip().startswith("#"):
            continue
        head, outs = line.split("|")
        vals = outs.split()
        for j, v in enumerate(vals):
            if v in "01":
                new = list(vals)
                new[j] = "1" if v == "0" else "0"
                yield i + 1, j, "\n".join(lines[:i] + [head + "| " + " ".join(new)]
                                          + lines[i + 1:]) + "\n"


@pytest.mark.parametrize("name", ["speedctl", "toggle", "gated_latch", "sequence_detector"])
def test_every_output_mutation_fails(compiled, name):
    path, _spec, design = compiled[name]
    count = 0
    for line, j, text in mutations(path.read_text()):
        mutated = parse_fsm(text, f"mutated line {line}")
        rep = prove_sequential(design.netlist, mutated)
        assert not rep["passed"], f"line {line} output {j}"
        assert rep["failure_kinds"].get("output", 0) >= 1
        count += 1
    assert count == sum(len(r) for r in _spec.table.out)


def _nl(inputs, cells, outputs):
    lib = load_library()
    nl = Netlist(inputs)
    for c in cells:
        cls = lib.for_type(c.type, len(c.inputs))
        nl.add_cell(c, pin_names=cls.input_names(len(c.inputs)), out_pins=list(cls.outputs))
    for o, net in outputs.items():
        nl.set_output(o, net)
    nl.check()
    return nl


TOGGLE_Q = parse_fsm("inputs x\noutputs Z\nmemory a set x reset ~x\nZ = a\n", "ref.fsm")


def test_race_detected():
    # b is set by x & ~a: whether it ends set depends on whether a or b switches first
    nl = _nl(["x"], [
        CellInst("c1", "not", "NOT", ("x",), ("nx",)),
        CellInst("c2", "and_not", "AND_NOT", ("x", "a"), ("sb",)),
        CellInst("c3", "memory", "MEMORY", ("x", "nx"), ("a",), {"initial": 0}),
        CellInst("c4", "memory", "MEMORY", ("sb", "nx"), ("b",), {"initial": 0}),
    ], {"Z": "a"})
    rep = prove_sequential(nl, TOGGLE_Q)
    assert not rep["passed"] and rep["failure_kinds"].get("race") == 1
    assert "critical race" in rep["failures"][0]["message"]


def test_oscillation_detected():
    # x on: a off sets a, a on resets a
    nl = _nl(["x"], [
        CellInst("c1", "and_not", "AND_NOT", ("x", "a"), ("s",)),
        CellInst("c2", "and", "AND", ("x", "a"), ("r",)),
        CellInst("c3", "memory", "MEMORY", ("s", "r"), ("a",), {"initial": 0}),
    ], {"Z": "a"})
    rep = prove_sequential(nl, TOGGLE_Q)
    assert not rep["passed"] and "oscillation" in rep["failure_kinds"]


def test_set_reset_overlap_detected():
    # SET and RESET both driven by x: on together as soon as x is on
    nl = _nl(["x"], [CellInst("c1", "memory", "MEMORY", ("x", "x"), ("a",), {"initial": 0})],
             {"Z": "a"})
    rep = prove_sequential(nl, TOGGLE_Q)
    assert not rep["passed"] and "overlap" in rep["failure_kinds"]


def test_static_hazard_in_output_is_a_glitch():
    # Z = x·a + x'·a holds a while x moves, but as two terms the linkage dips mid-stroke
    spec = parse_fsm("inputs x s\noutputs Z\nmemory a set s reset 0\nZ = a\n", "g.fsm")
    nl = _nl(["x", "s"], [
        CellInst("c1", "memory", "MEMORY", ("s", "zero"), ("a",), {"initial": 0}),
        CellInst("c0", "const_stop", "CONST", (), ("zero",), {"value": 0}),
        CellInst("c2", "and", "AND", ("x", "a"), ("t1",)),
        CellInst("c3", "and_not", "AND_NOT", ("a", "x"), ("t2",)),
        CellInst("c4", "or", "OR", ("t1", "t2"), ("Z",)),
    ], {"Z": "Z"})
    rep = prove_sequential(nl, spec)
    # a = 1 in the stable states s x = 10, 11, 00, 01 (s may fall after setting a): x moves
    # once from each
    assert not rep["passed"] and rep["failure_kinds"] == {"glitch": 4}
    # the same function as one product term holds still
    nl2 = _nl(["x", "s"], [
        CellInst("c1", "memory", "MEMORY", ("s", "zero"), ("a",), {"initial": 0}),
        CellInst("c0", "const_stop", "CONST", (), ("zero",), {"value": 0}),
    ], {"Z": "a"})
    assert prove_sequential(nl2, spec)["passed"]


def test_wrong_initial_value_fails(compiled):
    _p, spec, design = compiled["gated_latch"]
    nl = design.netlist
    cells = [CellInst(c.id, c.cell, c.type, c.inputs, c.outputs,
                      {"initial": 1 - c.params["initial"]} if c.type == "MEMORY" else c.params)
             for c in nl.cells.values()]
    rep = prove_sequential(_nl(nl.inputs, cells, nl.outputs), spec)
    assert not rep["passed"] and "output" in rep["failure_kinds"]


@pytest.mark.parametrize("name", ["speedctl", "speedctl_sr", "toggle"])
def test_transition_tour_covers_every_transition(name):
    spec = parse_fsm_file(str(EXAMPLES / f"{name}.fsm"))
    g = stable_graph(spec)
    n = spec.n

    def vec(d):
        return sum(d[nm] << (n - 1 - k) for k, nm in enumerate(spec.inputs))

    seqs = transition_tour(spec, seed=3, random_walks=2, length=7)
    tour, walks = seqs[:-2], seqs[-2:]
    taken = set()
    for seq in seqs:
        assert vec(seq[0]) == g.initial[0]
        for a, b in zip(seq, seq[1:]):
            assert bin(vec(a) ^ vec(b)).count("1") == 1  # one input at a time
        outs = expected_after(spec, seq)
        assert len(outs) == len(seq)
    for seq in tour:  # replay on the stable graph, collecting the transitions taken
        node = g.initial
        for d in seq[1:]:
            x2 = vec(d)
            nxt = dict(g.edges[node])[x2]
            taken.add((node, x2))
            node = nxt
    assert taken == {(u, x2) for u, outs in g.edges.items() for x2, _t in outs}
    assert all(len(w) == 8 for w in walks)
    assert transition_tour(spec, seed=3, random_walks=2, length=7) == seqs  # seeded


def test_expected_after_matches_table_viii():
    spec = parse_fsm_file(str(EXAMPLES / "speedctl.fsm"))
    names = spec.inputs
    # the desired cycle of Appendix B.1: 00 -> 10 -> 11 -> 10 -> 00 visits 1, 2, 5, 6, 1
    seq = [dict(zip(names, v)) for v in [(0, 0), (1, 0), (1, 1), (1, 0), (0, 0)]]
    got = [(o["Z1"], o["Z2"]) for o in expected_after(spec, seq)]
    assert got == [(1, 0), (1, 0), (0, 0), (0, 0), (1, 0)]
    with pytest.raises(ValueError, match="not a specified"):
        expected_after(spec, [dict(zip(names, v)) for v in [(0, 0), (0, 1), (1, 1)]])


def test_netlist_loops_only_through_memory():
    # feedback through a MEMORY's Q is a sequential circuit: accepted, Q treated as a source
    nl = _nl(["x"], [
        CellInst("c1", "and_not", "AND_NOT", ("x", "a"), ("s",)),
        CellInst("c2", "memory", "MEMORY", ("s", "a"), ("a",), {"initial": 0}),
    ], {"Z": "a"})
    assert [c.id for c in nl.topo_cells()] == ["c1", "c2"]
    assert nl.depth() == {"c1": 1, "c2": 2}
    with pytest.raises(TypeError, match="stateful"):  # no combinational value for a MEMORY
        nl.evaluate({"x": np.array([True])})
    # the same loop through an OR is a combinational loop: rejected
    lib = load_library()
    bad = Netlist(["x"])
    for c in (CellInst("c1", "and_not", "AND_NOT", ("x", "b"), ("s",)),
              CellInst("c2", "or", "OR", ("s", "x"), ("b",))):
        cls = lib.for_type(c.type, 2)
        bad.add_cell(c, pin_names=cls.input_names(2), out_pins=list(cls.outputs))
    with pytest.raises(ValueError, match="combinational loop"):
        bad.check()
