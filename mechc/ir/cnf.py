"""Clauses for SAT: a combinational netlist and a BLIF-style network written as CNF (Tseitin
variables, python-sat's DIMACS convention).

Shared by the logic proof's SAT miter (:mod:`mechc.proofs.sat_equiv`) and the SAT check of
static hazards (:mod:`mechc.passes.hazard_sat`), so both read one definition of what a cell
does: each cell's clauses come from its truth table computed by
:func:`mechc.ir.logic_types.evaluate_type`, the function the exhaustive checks evaluate with.
Only cells wider than ``TABLE_MAX_INPUTS`` are written by their structure (AND, OR, NAND, NOR:
built-in types a cell file cannot redefine); a wide cell of another type raises
:class:`NotEncodable`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechc.ir.logic_types import evaluate_type, table_rows
from mechc.ir.netlist import Netlist
from mechc.ir.network import Network

#: Cells with at most this many inputs are encoded by their truth table (2**k clauses).
TABLE_MAX_INPUTS = 8
class NotEncodable(Exception):
    """A cell the CNF writer cannot express (a wide cell of a type with no structural form)."""


@dataclass
class Cnf:
    """Clauses over integer variables (python-sat's DIMACS convention), with constants."""

    clauses: list[list[int]] = field(default_factory=list)
    top: int = 0
    _true: int = 0

    def new(self) -> int:
        self.top += 1
        return self.top

    @property
    def true(self) -> int:
        """A variable fixed to true (made on first use)."""
        if not self._true:
            self._true = self.new()
            self.clauses.append([self._true])
        return self._true

    def and_(self, lits: list[int]) -> int:
        """y <-> AND(lits)."""
        if not lits:
            return self.true
        if len(lits) == 1:
            return lits[0]
        y = self.new()
        self.clauses += [[-y, a] for a in lits]
        self.clauses.append([y] + [-a for a in lits])
        return y

    def or_(self, lits: list[int]) -> int:
        """y <-> OR(lits)."""
        return -self.and_([-a for a in lits])

    def xor2(self, a: int, b: int) -> int:
        y = self.new()
        self.clauses += [[-y, a, b], [-y, -a, -b], [y, -a, b], [y, a, -b]]
        return y

    def table(self, ins: list[int], values: np.ndarray) -> int:
        """y <-> the function with output ``values[row]`` (input 0 the row's MSB)."""
        k = len(ins)
        y = self.new()
        for row, v in enumerate(values):
            lits = [-ins[i] if (row >> (k - 1 - i)) & 1 else ins[i] for i in range(k)]
            self.clauses.append(lits + [y if v else -y])
        return y


def encode_netlist(nl: Netlist, cnf: Cnf, inputs: dict[str, int],
                   cells: list | None = None) -> dict[str, int]:
    """Every net of ``nl`` (or of ``cells``, a topologically ordered part of it) as a literal
    of ``cnf`` (inputs given); returns net -> literal."""
    nets: dict[str, int] = dict(inputs)
    cache: dict[tuple, np.ndarray] = {}
    for cell in (nl.topo_cells() if cells is None else cells):
        ins = [nets[n] for n in cell.inputs]
        k = len(ins)
        if k <= TABLE_MAX_INPUTS:
            values = cell_table(cell, cache)
            y = (cnf.true if values[0] else -cnf.true) if k == 0 else cnf.table(ins, values)
        elif cell.type in ("AND", "NAND"):
            y = cnf.and_(ins) * (1 if cell.type == "AND" else -1)
        elif cell.type in ("OR", "NOR"):
            y = cnf.or_(ins) * (1 if cell.type == "OR" else -1)
        else:
            raise NotEncodable(f"cell {cell.id} ({cell.type}, {k} inputs) has no CNF form "
                               f"beyond {TABLE_MAX_INPUTS} inputs")
        for net in cell.outputs:
            nets[net] = y
    return nets


def encode_network(net: Network, cnf: Cnf, inputs: dict[str, int]) -> dict[str, int]:
    """A network-valued spec's outputs as literals: each ``.names`` node the OR of its cubes
    (each the AND of its fanins' literals), negated for an off-set cover."""
    lits: dict[str, int] = dict(inputs)
    for nd in net.nodes:
        terms = [cnf.and_([lits[f] if ch == "1" else -lits[f]
                           for ch, f in zip(cube, nd.fanins) if ch != "-"])
                 for cube in nd.cubes]
        y = cnf.or_(terms)
        lits[nd.out] = -y if nd.phase == 0 else y
    return {o: lits[o] for o in net.outputs}


def cell_table(cell, cache: dict) -> np.ndarray:
    """A cell's output for each of its input rows (input 0 the row's most significant bit)."""
    k = len(cell.inputs)
    key = (cell.type, k, repr(sorted(cell.params.items())))
    if key not in cache:  # the single definition of the cell's function
        cache[key] = evaluate_type(cell.type, table_rows(k), cell.params, 1 << k)
    return cache[key]
