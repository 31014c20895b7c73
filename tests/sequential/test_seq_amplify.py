"""Automatic AMPLIFIERs (mechc.passes.amplify): where an output must snap, where forces fail.

The ternary prediction of which outputs move partway (``outputs_needing_snap``) is checked
against an independent method, the kinematic sequential proof of the design built without
amplifiers; the force rule against the synthesis checks it answers, and the measured fan-out.
"""

from __future__ import annotations

import pytest

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm, parse_fsm_file
from mechc.passes.amplify import fanout_limit
from mechc.passes.assemble import MechOptions
from mechc.pipeline import CompileOptions, compile_sequential, compile_spec
from mechc.proofs.kinematic import prove_kinematic
from mechc.proofs.seq_logic import outputs_needing_snap, prove_sequential
from mechc.proofs.seq_mechanism import prove_sequential_kinematic
from tests.helpers import EXAMPLES
from tests.sequential.test_seq_cli import STARTER

LIB = load_library()
NAMES = ("speedctl", "speedctl_sr", "toggle", "gated_latch", "sequence_detector")


def _spec(name):
    if name == "starter":
        return parse_fsm(STARTER, "starter.fsm")
    return parse_fsm_file(str(EXAMPLES / f"{name}.fsm"))


def _loads(nl):
    out: dict[str, list[str]] = {}
    for c in nl.cells.values():
        for net in c.inputs:
            out.setdefault(net, []).append(c.id)
    return out


@pytest.mark.parametrize("name", NAMES + ("starter",))
def test_snap_prediction_matches_the_kinematic_glitches(name):
    spec = _spec(name)
    bare = compile_sequential(spec, CompileOptions(amplify=False), LIB)
    predicted = set(outputs_needing_snap(bare.netlist, spec))
    kin = prove_sequential_kinematic(bare, spec, LIB)
    glitched = {f["output"] for f in kin["failures"] if f["kind"] == "glitch"}
    assert predicted == glitched
    design = compile_sequential(spec, library=LIB)
    for o in predicted:  # each such output is driven through an AMPLIFIER of its own
        node, _ = design.netlist.driver[design.netlist.outputs[o]]
        assert design.netlist.cells[node].type == "AMPLIFIER"
    assert prove_sequential(design.netlist, spec)["passed"]
    kin = prove_sequential_kinematic(design, spec, LIB)
    assert kin["passed"], kin["failures"][:3]


def test_speed_controller_z2_needs_the_snap():
    spec = _spec("speedctl")
    bare = compile_sequential(spec, CompileOptions(amplify=False), LIB)
    # x1 rising in state 1: y1 sets while x1 is mid-stroke and Z2 = x̄1·(x2 + y1) rises with it
    assert set(outputs_needing_snap(bare.netlist, spec)) == {"Z2"}


def test_memory_loop_short_of_force_gets_amplifiers():
    spec = _spec("toggle")
    bare = compile_sequential(spec, CompileOptions(amplify=False), LIB)
    failed = {c.name for c in bare.mechanism.checks if not c.passed}
    assert "force budget converged" in failed  # the loop's demand grows every pass
    design = compile_sequential(spec, library=LIB)
    assert design.stats["design_checks"]["passed"], design.stats["design_checks"]["failed"]
    nl = design.netlist
    amps = [c for c in nl.cells.values() if c.type == "AMPLIFIER"]
    mems = {c.outputs[0] for c in nl.cells.values() if c.type == "MEMORY"}
    assert mems <= {c.inputs[0] for c in amps}  # every memory output is amplified
    _check_amplified_nets(nl, design.stats["amplified"])


def _check_amplified_nets(nl, amplified):
    limit = fanout_limit(LIB)
    loads = _loads(nl)
    for c in nl.cells.values():
        if c.type == "AMPLIFIER":
            assert len(loads.get(c.outputs[0], [])) <= limit
    for net, why in amplified.items():
        # sequential: nothing but amplifiers left on the net, equal delays (Appendix B.2); a
        # combinational net keeps its lightest loads direct (delays change no settled value)
        if why.startswith("force") and nl.state_nets():
            assert all(nl.cells[cid].type == "AMPLIFIER" for cid in loads[net])


def test_weak_actuators_get_input_amplifiers():
    spec = load_spec(EXAMPLES / "sorter.bool")
    weak = CompileOptions(mech=MechOptions(actuator_force=3.0))
    bare = compile_spec(spec, CompileOptions(mech=MechOptions(actuator_force=3.0),
                                             amplify=False), LIB)
    assert not bare.stats["design_checks"]["passed"]
    design = compile_spec(spec, weak, LIB)
    assert design.stats["design_checks"]["passed"], design.stats["design_checks"]["failed"]
    assert any(why.startswith("force") for why in design.stats["amplified"].values())
    _check_amplified_nets(design.netlist, design.stats["amplified"])
    for a in design.mechanism.actuators.values():
        assert max(a["required_right_N"], a["required_left_N"]) <= 3.0
    assert prove_kinematic(design, spec, LIB)["passed"]
