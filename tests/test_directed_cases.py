"""Beyond 10 inputs the kinematic and dynamic proofs run a sample of single-input changes led
by changes chosen to switch every cell (mechc.proofs.cases.directed_changes). Checked here by
brute force over every single-input change of small random netlists (which cells can switch at
all), on a 32-bit adder whose long carries random states almost never switch, and end to end:
the reports say how many changes of how many were proven and how they were chosen."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.ir.netlist import CellInst
from mechc.pipeline import compile_spec
from mechc.proofs.cases import directed_changes
from mechc.proofs.dynamic import prove_dynamic
from tests.logic.test_logic_sat import adder_netlist, rand_netlist


def switched(nl, names, lo_vec: int, k: int) -> set[str]:
    """Cells whose output differs between the change's two ends, by plain evaluation."""
    n = len(names)
    ends = []
    for v in (lo_vec, lo_vec | 1 << (n - 1 - k)):
        env = {nm: np.array([(v >> (n - 1 - i)) & 1], dtype=bool) for i, nm in enumerate(names)}
        ends.append(nl.evaluate(env))
    return {c.id for c in nl.cells.values() if ends[0][c.outputs[0]][0] != ends[1][c.outputs[0]][0]}


def chosen(d, n: int) -> list[tuple[int, int]]:
    return [(sum(int(d.lo[i, j]) << (n - 1 - i) for i in range(n)), int(d.k[j]))
            for j in range(len(d.k))]


@pytest.mark.parametrize("seed", range(5))
def test_directed_changes_switch_every_cell_that_can_switch(seed):
    rng = np.random.default_rng(seed)
    for _ in range(15):
        n = int(rng.integers(3, 7))
        names = [f"x{i}" for i in range(n)]
        nl = rand_netlist(rng, names, ["f0"])
        can = set()  # brute force: every single-input change
        for v in range(1 << n):
            for k in range(n):
                if not (v >> (n - 1 - k)) & 1:
                    can |= switched(nl, names, v, k)
        d = directed_changes(nl, names, seed)
        got = set()
        for v, k in chosen(d, n):
            assert not (v >> (n - 1 - k)) & 1  # the moving input starts off
            got |= switched(nl, names, v, k)
        assert got == can
        assert d.toggled == len(can) and d.never == len(nl.cells) - len(can) and d.unknown == 0
        assert len(d.k) <= max(1, len(can))


def test_a_wide_adders_long_carries_are_switched():
    """A 32-bit adder: the carry into bit 31 switches only when 30 bits propagate, which no
    random state does; the directed changes still switch it (SAT finds the state), and a cell
    that cannot switch is reported as such."""
    nl, spec = adder_netlist(32)
    nl.add_cell(CellInst("dead", "x", "AND_NOT", ("a0", "a0"), ("dead",)))  # always 0
    d = directed_changes(nl, spec.inputs, 0)
    assert d.toggled == len(nl.cells) - 1 and d.never == 1 and d.unknown == 0
    got = set()
    for v, k in chosen(d, spec.n):
        got |= switched(nl, spec.inputs, v, k)
    assert got == set(nl.cells) - {"dead"}
    assert len(d.k) < len(nl.cells) / 2  # a few changes switch many cells each


def test_wide_design_dynamic_and_kinematic_report_the_sample(cli, tmp_path):
    names = [f"a{i}" for i in range(12)]
    src = tmp_path / "w.bool"
    src.write_text(f"inputs {' '.join(names)}\noutputs z y\n"
                   "z = a0 & a1 & a2 & a3 & a4 & a5 | a11\ny = a6 ^ a7\n")
    out = tmp_path / "w.json"
    code, stdout, err = cli("compile", src, "-o", out, "--quiet")
    assert code == 0, err
    cells = len(json.loads(out.read_text())["cells"])
    report = tmp_path / "k.json"
    assert cli("simulate", out, "--level", "kinematic", "--report", report)[0] == 0
    k = json.loads(report.read_text())
    assert k["exhaustive"] is False and k["cells_toggled"] == k["cells"] == cells
    assert k["transitions"] == 512 + k["directed_changes"]
    assert k["transitions_total"] == 12 << 11
    # the dynamic level: only the directed changes (they come first), each checked
    design = compile_spec(load_spec(src))
    rep = prove_dynamic(design, design.spec, load_library(),
                        max_cases=k["directed_changes"])
    assert rep.passed and rep["cases"] == rep["transitions"] == k["directed_changes"]
    assert rep["cells_toggled"] == cells and rep["transitions_total"] == 12 << 11
    assert "proven on" in rep.summary_text() and "sampled" in rep.summary_text()
