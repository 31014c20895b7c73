"""Netlist IR: one small cell record, nets by name, the whole held in a networkx graph.

Graph nodes are cell ids plus one node per primary input (``"in:NAME"``) and output
(``"out:NAME"``); every edge runs from a net's driver to one of its loads and carries the net
name and the load pin.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from mechc.ir.logic_types import evaluate_type

#: Logic types whose output is a stored state; a netlist may loop only through these.
STATEFUL = frozenset({"MEMORY"})


@dataclass(frozen=True)
class CellInst:
    id: str
    cell: str  # library cell name
    type: str  # logic type
    inputs: tuple[str, ...]  # net names, in pin order
    outputs: tuple[str, ...]
    params: dict = field(default_factory=dict, compare=False)

    def to_json(self) -> dict:
        return {"id": self.id, "cell": self.cell, "type": self.type, "inputs": list(self.inputs),
                "outputs": list(self.outputs), "params": dict(self.params)}


def in_node(name: str) -> str:
    return f"in:{name}"


def out_node(name: str) -> str:
    return f"out:{name}"


class Netlist:
    def __init__(self, inputs: Iterable[str], outputs: dict[str, str] | None = None):
        self.inputs: list[str] = list(inputs)
        self.outputs: dict[str, str] = {}
        self.cells: dict[str, CellInst] = {}
        self.driver: dict[str, tuple[str, str]] = {}  # net -> (node, pin)
        self.graph = nx.MultiDiGraph()
        # edges whose net has no driver yet, by net, each with its place in the order edges
        # were asked for (a scan of every pending edge per cell added was quadratic: a design
        # built in any order but a topological one held thousands pending)
        self._pending: dict[str, list[tuple[int, str, str, str]]] = {}
        self._asked = 0
        self._topo: list[str] | None = None  # topo_cells' order, until the netlist changes
        for name in self.inputs:
            self.graph.add_node(in_node(name), kind="input")
            self.driver[name] = (in_node(name), name)
        for name, net in (outputs or {}).items():
            self.set_output(name, net)

    # ---- building -------------------------------------------------------------------------
    def add_cell(self, cell: CellInst, pin_names: list[str] | None = None,
                 out_pins: list[str] | None = None) -> CellInst:
        if cell.id in self.cells:
            raise ValueError(f"duplicate cell id {cell.id}")
        self.cells[cell.id] = cell
        self._topo = None
        self.graph.add_node(cell.id, kind="cell", cell=cell)
        outs = out_pins or [f"Z{k}" if k else "Z" for k in range(len(cell.outputs))]
        for net, pin in zip(cell.outputs, outs):
            if net in self.driver:
                raise ValueError(f"net {net} has two drivers")
            self.driver[net] = (cell.id, pin)
        # the edges waiting for the nets this cell drives, in the order they were asked for,
        # then the cell's own inputs in pin order (the graph's edge order, which later passes
        # iterate, is the one a scan of every pending edge would give)
        waiting = sorted(e for net in cell.outputs for e in self._pending.pop(net, ()))
        for _, node, pin, net in waiting:
            self._edge(net, node, pin)
        pins = pin_names or [chr(ord("A") + k) for k in range(len(cell.inputs))]
        for net, pin in zip(cell.inputs, pins):
            self._ask(net, cell.id, pin)
        return cell

    def _ask(self, net: str, node: str, pin: str) -> None:
        """An edge from ``net``'s driver to ``node``'s ``pin``, now or once the net has one."""
        if net in self.driver:
            self._edge(net, node, pin)
        else:
            self._pending.setdefault(net, []).append((self._asked, node, pin, net))
        self._asked += 1

    def _edge(self, net: str, node: str, pin: str) -> None:
        self.graph.add_edge(self.driver[net][0], node, key=(net, pin), net=net, pin=pin)

    def set_output(self, name: str, net: str) -> None:
        self.outputs[name] = net
        self._topo = None
        self.graph.add_node(out_node(name), kind="output")
        self._ask(net, out_node(name), name)

    def check(self) -> None:
        """Every net used has a driver; every cycle passes through a MEMORY's Q (feedback of a
        sequential circuit); any other cycle is a combinational loop and an error."""
        if self._pending:
            _, node, _pin, net = min(e for es in self._pending.values() for e in es)
            raise ValueError(f"net '{net}' used by {node} has no driver")
        comb = self.combinational_graph()
        if not nx.is_directed_acyclic_graph(comb):
            cycle = nx.find_cycle(comb)
            raise ValueError(f"combinational loop through {[e[0] for e in cycle]}")

    def state_nets(self) -> dict[str, CellInst]:
        """Nets driven by a stateful cell (MEMORY Q): the secondary variables, net -> cell."""
        return {c.outputs[0]: c for c in self.cells.values() if c.type in STATEFUL}

    def combinational_graph(self) -> nx.MultiDiGraph:
        """The graph with the edges leaving MEMORY cells removed: a stored state is a source
        for the logic it feeds, so this is acyclic for a well-formed sequential netlist."""
        cut = [(u, v, k) for u, v, k in self.graph.edges(keys=True)
               if u in self.cells and self.cells[u].type in STATEFUL]
        if not cut:
            return self.graph
        g = self.graph.copy()
        g.remove_edges_from(cut)
        return g

    # ---- queries --------------------------------------------------------------------------
    def nets(self) -> dict[str, dict]:
        """net -> {"driver": "node.pin", "loads": ["node.pin", ...]} (loads sorted)."""
        out: dict[str, dict] = {}
        for net, (node, pin) in self.driver.items():
            out[net] = {"driver": _pin_ref(node, pin), "loads": []}
        for _u, v, data in self.graph.edges(data=True):
            out[data["net"]]["loads"].append(_pin_ref(v, data["pin"]))
        for d in out.values():
            d["loads"].sort()
        return out

    def topo_cells(self) -> list[CellInst]:
        """Cells in a combinational order (MEMORY outputs count as sources); the order is
        kept until a cell or output is added (evaluation asks for it on every call)."""
        if self._topo is None:
            order = nx.lexicographical_topological_sort(self.combinational_graph(),
                                                        key=_sort_key)
            self._topo = [n for n in order if n in self.cells]
        return [self.cells[n] for n in self._topo]

    def depth(self) -> dict[str, int]:
        """Logic depth of every cell: 1 + the deepest cell among its drivers (inputs and MEMORY
        outputs, the state nets, are 0)."""
        d: dict[str, int] = {}
        state = self.state_nets()
        for cell in self.topo_cells():
            d[cell.id] = 1 + max((0 if n in state else d.get(self.driver[n][0], 0)
                                  for n in cell.inputs), default=0)
        return d

    def count_by_type(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for c in self.cells.values():
            out[c.type] = out.get(c.type, 0) + 1
        return dict(sorted(out.items()))

    # ---- logic evaluation -----------------------------------------------------------------
    def evaluate(self, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Every net's value for the input vectors in ``values`` (by logic type)."""
        if self.state_nets():
            raise TypeError("this netlist has MEMORY cells, which are stateful: evaluate it "
                            "with mechc.proofs.seq_logic, not combinationally")
        size = len(next(iter(values.values()))) if values else 1
        nets = dict(values)
        for cell in self.topo_cells():
            out = evaluate_type(cell.type, [nets[n] for n in cell.inputs], cell.params, size)
            for net in cell.outputs:
                nets[net] = out
        return nets

    # ---- text -----------------------------------------------------------------------------
    def to_text(self) -> str:
        """Canonical print (topological, deterministic) used by golden tests."""
        lines = ["inputs " + " ".join(self.inputs)]
        lines.append("outputs " + " ".join(f"{k}={v}" for k, v in self.outputs.items()))
        for c in self.topo_cells():
            params = ""
            if c.params:
                params = " " + " ".join(f"{k}={c.params[k]}" for k in sorted(c.params))
            lines.append(f"{c.id} {c.type} {c.cell} ({', '.join(c.inputs)}) -> "
                         f"({', '.join(c.outputs)}){params}")
        return "\n".join(lines) + "\n"

    # ---- JSON -----------------------------------------------------------------------------
    @staticmethod
    def from_json(inputs: list[str], outputs: dict[str, str], cells: list[dict]) -> Netlist:
        nl = Netlist(inputs)
        for c in cells:
            nl.add_cell(CellInst(c["id"], c["cell"], c["type"], tuple(c["inputs"]),
                                 tuple(c["outputs"]), dict(c.get("params", {}))))
        for name, net in outputs.items():
            nl.set_output(name, net)
        nl.check()
        return nl


def _pin_ref(node: str, pin: str) -> str:
    if node.startswith("in:") or node.startswith("out:"):
        return node
    return f"{node}.{pin}"


def _sort_key(node: str):
    # inputs first, then cells by numeric id, outputs last
    if node.startswith("in:"):
        return (0, 0, node)
    if node.startswith("out:"):
        return (2, 0, node)
    digits = "".join(ch for ch in node if ch.isdigit())
    return (1, int(digits) if digits else 0, node)
