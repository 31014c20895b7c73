"""A logic network of ``.names`` nodes (BLIF's model), valued by simulation.

A spec given as a structure (BLIF, Verilog) too wide for a truth table is valued by this
network itself: its outputs at any input vectors are the network simulated on them (one
boolean array per node), so nothing of size 2**n is ever built. The SAT proof encodes the same
nodes as clauses (:mod:`mechc.proofs.sat_equiv`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class NamesNode:
    """One node: its output net, fanin nets, cover cubes (``01-`` strings, one per fanin) and
    whether the cubes are the on-set (phase 1) or the off-set (phase 0)."""

    out: str
    fanins: tuple[str, ...]
    cubes: tuple[str, ...]
    phase: int


@dataclass
class Network:
    """Primary inputs and outputs and the nodes in evaluation order (fanins first)."""

    inputs: list[str]
    outputs: list[str]
    nodes: list[NamesNode]

    def evaluate(self, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Every output's boolean value at the input vectors ``values`` (input -> array). A
        node's array is dropped once its last reader has been evaluated, so a wide network
        over 2**20 vectors stays within memory."""
        size = len(next(iter(values.values()))) if values else 1
        nets: dict[str, np.ndarray] = {x: np.asarray(values[x], dtype=bool)
                                       for x in self.inputs}
        readers: dict[str, int] = {}
        for nd in self.nodes:
            for f in nd.fanins:
                readers[f] = readers.get(f, 0) + 1
        keep = set(self.outputs) | set(self.inputs)
        for nd in self.nodes:
            hit = np.zeros(size, dtype=bool)
            for cube in nd.cubes:
                term = np.ones(size, dtype=bool)
                for ch, f in zip(cube, nd.fanins):
                    if ch == "1":
                        term &= nets[f]
                    elif ch == "0":
                        term &= ~nets[f]
                hit |= term
            nets[nd.out] = ~hit if nd.phase == 0 else hit
            for f in nd.fanins:
                readers[f] -= 1
                if readers[f] == 0 and f not in keep:
                    del nets[f]
        return {o: nets[o] for o in self.outputs}

    def to_blif(self) -> str:
        """The network as clean BLIF (model ``top``), what the BLIF front end reads back."""
        lines = [".model top", ".inputs " + " ".join(self.inputs),
                 ".outputs " + " ".join(self.outputs)]
        for nd in self.nodes:
            lines.append(".names " + " ".join([*nd.fanins, nd.out]))
            lines += [f"{c} {nd.phase}".strip() for c in nd.cubes]
        return "\n".join(lines + [".end"]) + "\n"
