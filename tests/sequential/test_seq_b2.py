"""001 Appendix B.2: an AMPLIFIER on the AND-NOT generator feeding RESET of Y1 delays RESET going
off while x2 turns SET on; the MEMORY is pressed from both sides. The dynamic proof must see it;
the compiled default design (no amplifier on one path only) must be free of it.

The walk is the one the appendix describes: from power-up (x1 x2 = 00) the shaft speeds up
(x1 on: state 2), then x2 comes on (state 5): SET1 = x2 on, RESET1 = x1·x̄2·y2 off at once.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm_file
from mechc.passes.amplify import amplify_nets
from mechc.pipeline import compile_netlist, compile_sequential
from mechc.proofs.seq_mechanism import prove_sequential_dynamic, prove_sequential_kinematic

ROOT = Path(__file__).resolve().parents[2]
WALK = [[{"x1": 0, "x2": 0}, {"x1": 1, "x2": 0}, {"x1": 1, "x2": 1}]]


@pytest.fixture(scope="module")
def setup():
    spec = parse_fsm_file(str(ROOT / "examples" / "speedctl_sr.fsm"))
    lib = load_library()
    design = compile_sequential(spec, library=lib)
    return spec, lib, design


def _reset_net(design, memory: str) -> str:
    cell = next(c for c in design.netlist.cells.values()
                if c.type == "MEMORY" and c.outputs[0] == memory)
    return cell.inputs[1]


def test_the_reset_of_y1_is_the_and_not_generator(setup):
    spec, lib, design = setup
    net = _reset_net(design, "y1")
    node, _pin = design.netlist.driver[net]
    assert design.netlist.cells[node].type == "AND_NOT"
    # and SET of y1 is x2 itself: the two move together when x2 changes
    mem = next(c for c in design.netlist.cells.values() if c.outputs[0] == "y1")
    assert mem.inputs[0] == "x2"


def test_amplified_reset_generator_overlaps_in_the_dynamics(setup):
    spec, lib, design = setup
    nl = amplify_nets(design.netlist, lib, [_reset_net(design, "y1")])
    amped = compile_netlist(spec, nl, library=lib)
    # the quasi-static model sees it too: the amplifier holds RESET on until its input is
    # past half stroke, while SET is already pressing
    kin = prove_sequential_kinematic(amped, spec, lib)
    assert kin["failure_kinds"].get("S·R overlap", 0) > 0
    dyn = prove_sequential_dynamic(amped, spec, lib, sequences=WALK)
    assert not dyn["passed"]
    hits = [f for f in dyn["failures"] if f["kind"] == "S·R overlap"]
    assert hits, dyn["failure_kinds"]
    mem_y1 = next(c.id for c in nl.cells.values() if c.outputs[0] == "y1")
    assert {f["cell"] for f in hits} == {mem_y1}
    assert all(f["moving"] == "x2" and f["to"] == 1 for f in hits)


def test_default_design_is_free_of_it(setup):
    spec, lib, design = setup
    dyn = prove_sequential_dynamic(design, spec, lib, sequences=WALK)
    assert dyn["passed"], dyn["failures"]
    assert "S·R overlap" not in dyn["failure_kinds"]
