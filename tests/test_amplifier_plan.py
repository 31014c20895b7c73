"""Force amplifiers planned in one sweep of the force budget (``amplify.plan_force_amplifiers``):
the planned design passes every strength and actuator check when assembled, and no planned
amplifier can be left out (each one is needed: without it the assembled design fails)."""

from __future__ import annotations

import pytest

from mechc.cells.library import load_library
from mechc.ir.netlist import CellInst, Netlist
from mechc.passes.amplify import amplifier_capacity, amplify_nets, plan_force_amplifiers
from mechc.passes.assemble import MechOptions, assemble_mechanism, synth_context
from mechc.passes.place import place
from mechc.passes.strength import strength_checks

LIB = load_library()
LEVELS = 5


def chain() -> Netlist:
    """Diamonds p_k = (p_(k-1) AND x_k) OR (p_(k-1) AND y_k): an OR's input asks its spring
    (1.3 x what its output moves back, rising 30 %) plus that load, an AND's likewise the other
    way, and p feeds two ANDs, so what the first input must deliver grows about 5.7x a diamond
    and soon exceeds what a part or the actuator can take."""
    names = [f"{v}{k}" for k in range(1, LEVELS + 1) for v in "xy"]
    nl = Netlist(["a"] + names)
    and2, or2 = LIB.for_type("AND", 2), LIB.for_type("OR", 2)
    prev = "a"
    for k in range(1, LEVELS + 1):
        for v in "xy":
            nl.add_cell(CellInst(f"{v}and{k}", and2.name, "AND", (prev, f"{v}{k}"),
                                 (f"{v}n{k}",)),
                        pin_names=and2.input_names(2), out_pins=list(and2.outputs))
        nl.add_cell(CellInst(f"or{k}", or2.name, "OR", (f"xn{k}", f"yn{k}"), (f"p{k}",)),
                    pin_names=or2.input_names(2), out_pins=list(or2.outputs))
        prev = f"p{k}"
    nl.set_output("p", prev)
    return nl


def failures(nl: Netlist) -> list[str]:
    mech = assemble_mechanism(nl, place(nl), LIB, MechOptions())
    bad = [c for c in strength_checks(mech) + mech.synthesis_checks() if not c.passed]
    return [f"{c.name} {c.where}" for c in bad]


@pytest.fixture(scope="module")
def planned():
    nl = chain()
    nets, groups = plan_force_amplifiers(nl, LIB, MechOptions())
    return nl, nets, groups


def test_unamplified_chain_fails_and_the_plan_mends_it(planned):
    nl, nets, groups = planned
    assert failures(nl)  # the chain as it is overloads its first levels
    assert nets
    assert failures(amplify_nets(nl, LIB, nets, groups=groups)) == []


def test_every_planned_amplifier_is_needed(planned):
    nl, nets, groups = planned
    for net in nets:
        fewer = {n: r for n, r in nets.items() if n != net}
        assert failures(amplify_nets(nl, LIB, fewer, groups=groups)), net


def test_groups_keep_each_amplifier_within_its_capacity(planned):
    nl, nets, groups = planned
    cap = amplifier_capacity(LIB, synth_context(MechOptions()))
    assert 1.0 < cap < 1000.0
    out = amplify_nets(nl, LIB, nets, groups=groups)
    mech = assemble_mechanism(out, place(out), LIB, MechOptions())
    for cid in mech.order:
        if out.cells[cid].type == "AMPLIFIER":
            d = mech.cells[cid].data["output_demand"]
            assert max(d["right_N"], d["left_N"]) <= cap + 1e-6
