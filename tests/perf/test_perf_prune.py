"""Pruned scenes: the cone on the netlist against brute-force reachability, the moving set
against logic evaluation, and pruned against whole-scene dynamics on real circuits."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from mechc.bench.circuits import random_netlist
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.ir.netlist import CellInst, Netlist
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import compile_spec
from mechc.proofs.dynamic import plan, prove_dynamic
from mechc.proofs.prune import blocker, cone, plan_case, run_case
from mechc.proofs.settings import dyn_settings
from tests.helpers import EXAMPLES

LIB = load_library()


def with_amplifiers(nl: Netlist, rng) -> Netlist:
    """The same graph with about a fifth of the cells typed AMPLIFIER."""
    out = Netlist(nl.inputs)
    for c in nl.topo_cells():
        t = "AMPLIFIER" if rng.random() < 0.2 else c.type
        out.add_cell(CellInst(c.id, c.cell, t, c.inputs, c.outputs))
    for o, net in nl.outputs.items():
        out.set_output(o, net)
    return out


def brute_cone(nl: Netlist, observed_outputs: list[str], moving: set[str]) -> set[str]:
    """A cell is in the cone iff a path leads from it to an observed output node without
    passing through another AMPLIFIER, and one of its input nets moves."""
    g = nl.graph
    amps = {c for c, x in nl.cells.items() if x.type == "AMPLIFIER"}
    outs = [f"out:{o}" for o in observed_outputs]
    keep = set()
    for c in nl.cells:
        h = g.subgraph([v for v in g.nodes if v == c or v not in amps])
        if any(nx.has_path(h, c, o) for o in outs) and any(
                n in moving for n in nl.cells[c].inputs):
            keep.add(c)
    return keep


@pytest.mark.parametrize("seed", range(6))
def test_cone_matches_brute_force_reachability(seed):
    rng = np.random.default_rng(seed)
    nl = with_amplifiers(random_netlist(25, n_inputs=5, seed=seed), rng)
    nets = list(nl.driver)
    for _ in range(5):
        moving = {n for n in nets if rng.random() < 0.3}
        observed = [o for o in nl.outputs if rng.random() < 0.6] or list(nl.outputs)[:1]
        got = cone(nl, [nl.outputs[o] for o in observed], moving)
        assert got == brute_cone(nl, observed, moving)


def test_an_amplifier_cuts_the_cone():
    """x -> c1 -> amp -> c2 -> z: with everything moving, the cone from z stops at the
    amplifier (upstream of it is driven by the closed form)."""
    nl = Netlist(["x", "y"])
    nl.add_cell(CellInst("c1", "or", "OR", ("x", "y"), ("n1",)))
    nl.add_cell(CellInst("a1", "amplifier", "AMPLIFIER", ("n1",), ("n2",)))
    nl.add_cell(CellInst("c2", "and", "AND", ("n2", "y"), ("z",)))
    nl.set_output("z", "z")
    assert cone(nl, ["z"], {"x", "y", "n1", "n2", "z"}) == {"a1", "c2"}
    nl.set_output("w", "n1")  # observing the amplifier's input net brings c1 back
    assert cone(nl, ["z", "n1"], {"x", "y", "n1", "n2"}) == {"c1", "a1", "c2"}


@pytest.fixture(scope="module", params=["sorter", "full_adder"])
def design(request):
    return compile_spec(load_spec(EXAMPLES / f"{request.param}.bool"))


def _cases(d, count):
    names = list(d.spec.inputs)
    n = len(names)
    cur, state = 0, {k: 0.0 for k in names}
    for vec in plan(n, 0, 0)[:count]:
        k = n - (cur ^ vec).bit_length()
        target = float((vec >> (n - 1 - k)) & 1)
        yield dict(state), names[k], target
        state[names[k]] = target
        cur = vec


def test_moving_nets_are_the_nets_whose_logic_value_changes(design):
    """For these hazard-free designs a net moves during a single-input change exactly when its
    Boolean value differs before and after (netlist evaluation, no geometry)."""
    nl, types = design.netlist, {c.id: c.cell for c in design.netlist.cells.values()}
    for state, name, target in _cases(design, 15):
        pc = plan_case(nl, design.mechanism, LIB, types, state, name, target)
        after = dict(state, **{name: target})
        v0 = nl.evaluate({k: np.array([bool(v)]) for k, v in state.items()})
        v1 = nl.evaluate({k: np.array([bool(v)]) for k, v in after.items()})
        changed = {net for net in nl.driver if bool(v0[net][0]) != bool(v1[net][0])}
        assert pc.moving_nets == changed


@pytest.mark.parametrize("freeze, agree", [("none", 0.002), ("inner", 0.005)])
def test_pruned_scene_gives_the_whole_scenes_outputs(design, freeze, agree):
    """Each change run on its pruned scene and on a fresh scene of the whole mechanism from the
    same rest state: final outputs agree (cells kept whole and free: within 0.2 % of stroke;
    still bodies frozen rigid: within the 0.5 % band inside which ``Scene.move`` stops holding),
    both within 1 % of the closed form, the pruned scene is smaller for most changes and a
    frozen scene has fewer constraints than the same cells kept free."""
    nl, mech = design.netlist, design.mechanism
    types = {c.id: c.cell for c in nl.cells.values()}
    st = dyn_settings(design)
    smaller = 0
    cases = list(_cases(design, 7))
    for state, name, target in cases:
        pr = run_case(nl, mech, LIB, types, st, state, name, target, freeze=freeze)
        whole = Scene.build(mech, LIB, types, st, dict(state))
        w = whole.move(name, target)
        for o in design.spec.outputs:
            assert abs(pr.result.final[o] - w.final[o]) <= agree, (name, o)
            assert abs(pr.result.final[o] - pr.plan.end_outputs[o]) <= 0.01
        assert pr.result.max_violation <= st.violation_limit
        smaller += pr.cells < len(mech.order)
        if freeze != "none" and not pr.escalated:
            free = run_case(nl, mech, LIB, types, st, state, name, target, freeze="none")
            assert pr.constraints <= free.constraints
            assert pr.plan.static - free.plan.static  # something more was frozen
    assert smaller >= len(cases) // 2


def test_frozen_bodies_are_the_ones_the_closed_form_keeps_still(design):
    """Under the default freeze a body is static exactly when the closed form keeps it still
    over the change (brute force: its pose at the 41 samples), or it is a boundary body that
    does not move; kept cells' output terminals stay free."""
    from mechc.physics.evaluate import evaluate
    from mechc.proofs.prune import SAMPLES, build_scene

    nl, mech = design.netlist, design.mechanism
    types = {c.id: c.cell for c in nl.cells.values()}
    st = DynSettings()
    for state, name, target in _cases(design, 7):
        pc = plan_case(nl, mech, LIB, types, state, name, target)
        sc = build_scene(pc, nl, mech, LIB, types, st, state, freeze="inner")
        vals = {k: np.full(SAMPLES, v) for k, v in state.items()}
        vals[name] = np.linspace(state[name], target, SAMPLES)
        poses = evaluate(mech, LIB, types, vals)
        outs = {mech.cells[c].terminals[nl.driver[n][1]].body for c in pc.cells
                for n in nl.cells[c].outputs}
        for bid in sc.bodies:
            series = [poses.u.get(bid), poses.theta.get(bid), *poses.xy.get(bid, ())]
            still = all(np.ptp(x) < 1e-9 for x in series if x is not None)
            if bid == mech.inputs[name].terminals[name].body:
                still = False
            assert (bid in pc.static) == (still and bid not in outs), bid


def test_prove_dynamic_pruned_and_whole_agree(design):
    """Whole proof (one scene carried through the tour) against pruned (each change from its
    closed-form rest pose): same verdict, errors within the 0.5 %-of-stroke band inside which
    ``Scene.move`` counts an output as settled (where a hold stops inside it is not
    information; the test above shows the pruned scene itself adds under 0.2 %)."""
    w = prove_dynamic(design, design.spec, LIB, extra=2, prune=False)
    p = prove_dynamic(design, design.spec, LIB, extra=2, prune=True)
    assert w["passed"] and p["passed"]
    assert abs(w["max_position_error_fraction"] - p["max_position_error_fraction"]) <= 0.005
    assert set(w) == set(p)  # the same report keys
    assert p["pruning"]["enabled"] and not w["pruning"]["enabled"]


def test_a_spec_mismatch_outside_the_pruned_scene_still_fails():
    """An output the change does not move is not simulated, but its closed-form position is
    still checked against the spec: a flipped minterm fails the pruned proof too."""
    from mechc.frontends.boolfile import parse_bool

    d = compile_spec(load_spec(EXAMPLES / "sorter.bool"))
    text = (EXAMPLES / "sorter.bool").read_text()
    line = next(x for x in text.splitlines() if x.startswith("Z = minterms("))
    on = {int(v) for v in line.split("minterms(")[1].split(")")[0].split(",")} ^ {12}
    other = parse_bool(text.replace(line, f"Z = minterms({', '.join(map(str, sorted(on)))})"
                                          " dontcare(4, 7, 8, 11)"))
    r = prove_dynamic(d, other, LIB, extra=0, prune=True)
    assert not r["passed"] and r["failure_kinds"].get("rest")


def test_stateful_cells_keep_the_whole_scene():
    nl = Netlist(["s", "r"])
    nl.add_cell(CellInst("m1", "memory", "MEMORY", ("s", "r"), ("q",)))
    nl.set_output("q", "q")
    assert "state" in blocker(nl, LIB)
    nl2 = Netlist(["a", "b"])
    nl2.add_cell(CellInst("c1", "or", "OR", ("a", "b"), ("z",)))
    assert blocker(nl2, LIB) is None
