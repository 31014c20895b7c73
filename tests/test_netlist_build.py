"""Netlist building: edges wait for their net's driver in any order of adding cells, and
come out in the order a plain scan of every waiting edge gives (later passes iterate the
graph's edges, so that order is part of the design); the topological order is kept until
the netlist changes."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from mechc.ir.netlist import CellInst, Netlist


def scan_reference(inputs, steps) -> nx.MultiDiGraph:
    """The graph built the plain way: after every cell or output, scan every waiting edge
    and add those whose net has a driver (nodes and edges added in the same calls)."""
    g = nx.MultiDiGraph()
    driver = {}
    for n in inputs:
        g.add_node(f"in:{n}")
        driver[n] = f"in:{n}"
    pending = []
    for kind, a in steps:
        if kind == "cell":
            g.add_node(a.id)
            for net in a.outputs:
                driver[net] = a.id
            pending += [(net, a.id, chr(ord("A") + k)) for k, net in enumerate(a.inputs)]
        else:
            name, net = a
            g.add_node(f"out:{name}")
            pending.append((net, f"out:{name}", name))
        still = []
        for net, node, pin in pending:
            if net in driver:
                g.add_edge(driver[net], node, key=(net, pin))
            else:
                still.append((net, node, pin))
        pending = still
    return g


def random_design(rng, cells=40):
    """A random acyclic netlist, its steps shuffled (cells used before they are added)."""
    inputs = [f"x{k}" for k in range(4)]
    nets = list(inputs)
    steps = []
    for k in range(cells):
        ins = tuple(rng.choice(nets, size=int(rng.integers(1, 4)), replace=True))
        outs = (f"n{k}",) if rng.random() < 0.8 else (f"n{k}", f"m{k}")
        steps.append(("cell", CellInst(f"c{k}", "and", "AND", ins, outs)))
        nets += outs
    for k in range(3):
        steps.append(("out", (f"y{k}", str(rng.choice(nets[4:])))))
    order = rng.permutation(len(steps))
    return inputs, [steps[i] for i in order]


@pytest.mark.parametrize("seed", range(8))
def test_edges_in_the_order_a_full_scan_gives(seed):
    rng = np.random.default_rng(seed)
    inputs, steps = random_design(rng)
    nl = Netlist(inputs)
    for kind, a in steps:
        if kind == "cell":
            nl.add_cell(a)
        else:
            nl.set_output(*a)
    ref = scan_reference(inputs, steps)
    assert list(nl.graph.edges(keys=True)) == list(ref.edges(keys=True))
    assert [list(nl.graph.in_edges(n, keys=True)) for n in nl.graph] == \
        [list(ref.in_edges(n, keys=True)) for n in ref]
    nl.check()
    pos = {c.id: i for i, c in enumerate(nl.topo_cells())}  # drivers first
    assert len(pos) == len(nl.cells)
    for c in nl.cells.values():
        for net in c.inputs:
            d = nl.driver[net][0]
            if d in nl.cells:
                assert pos[d] < pos[c.id]


def test_a_net_without_driver_is_named_oldest_first():
    nl = Netlist(["a"])
    nl.add_cell(CellInst("c1", "and", "AND", ("a", "p"), ("z1",)))
    nl.add_cell(CellInst("c2", "and", "AND", ("q", "z1"), ("z2",)))
    with pytest.raises(ValueError, match="net 'p' used by c1 has no driver"):
        nl.check()
    nl.add_cell(CellInst("c3", "not", "NOT", ("a",), ("p",)))
    with pytest.raises(ValueError, match="net 'q' used by c2 has no driver"):
        nl.check()


def test_the_kept_topological_order_follows_a_cell_added_later():
    nl = Netlist(["a"])
    nl.add_cell(CellInst("c2", "not", "NOT", ("m",), ("z",)))
    nl.set_output("y", "z")
    nl.add_cell(CellInst("c1", "not", "NOT", ("a",), ("m",)))
    assert [c.id for c in nl.topo_cells()] == ["c1", "c2"]
    v = nl.evaluate({"a": np.array([False, True])})
    assert list(v["z"]) == [0, 1]
    nl.add_cell(CellInst("c0", "not", "NOT", ("z",), ("w",)))  # after a topo_cells call
    assert [c.id for c in nl.topo_cells()] == ["c1", "c2", "c0"]
    assert list(nl.evaluate({"a": np.array([False, True])})["w"]) == [1, 0]
