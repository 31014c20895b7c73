"""Ternary simulation of a combinational netlist (Eichelberger), vectorised.

Each net carries, per input vector, whether it *can be* 0 and whether it *can be* 1: a moving
input (mid-stroke in a mechanism) can be both, X. A cell's output can be a value when some
completion of its unknown inputs gives it. An output that is definite is the same whatever
order and delays its cells switch in, so a definite output across a single-input change has
no static hazard. Used by the multi-level hazard check (:mod:`mechc.passes.ternary`) and by
the screened proof (:mod:`mechc.proofs.screen`).
"""

from __future__ import annotations

import numpy as np

from mechc.ir.logic_types import evaluate_type
from mechc.ir.netlist import Netlist
from mechc.logic.cubes import input_matrix

Tern = tuple[np.ndarray, np.ndarray]  # (can be 0, can be 1)


def _cell3(type_name: str, ins: list[Tern], params: dict) -> Tern:
    lo = [a for a, _ in ins]
    hi = [b for _, b in ins]
    if type_name in ("AND", "NAND"):
        out = (np.logical_or.reduce(lo), np.logical_and.reduce(hi))
    elif type_name in ("OR", "NOR"):
        out = (np.logical_and.reduce(lo), np.logical_or.reduce(hi))
    elif type_name in ("NOT",):
        return ins[0][1], ins[0][0]
    elif type_name in ("AMPLIFIER",):
        return ins[0]
    elif type_name in ("XOR", "XNOR"):
        unknown = np.logical_or.reduce([a & b for a, b in ins])
        value = np.logical_xor.reduce(hi)
        out = (unknown | ~value, unknown | value)
    elif type_name == "AND_NOT":
        out = (lo[0] | hi[1], hi[0] & lo[1])
    elif type_name == "OR_NOT":
        out = (lo[0] & hi[1], hi[0] | lo[1])
    else:  # any other type: over the rows of its table the unknown inputs allow
        return _generic(type_name, ins, params)
    if type_name in ("NAND", "NOR", "XNOR"):
        return out[1], out[0]
    return out


def _generic(type_name: str, ins: list[Tern], params: dict) -> Tern:
    k = len(ins)
    size = len(ins[0][0]) if ins else 1
    rows = input_matrix(k) if k else np.zeros((0, 1), dtype=bool)
    table = evaluate_type(type_name, [rows[i] for i in range(k)], params, max(1, 1 << k))
    lo = np.zeros(size, dtype=bool)
    hi = np.zeros(size, dtype=bool)
    for r in range(1 << k):
        ok = np.ones(size, dtype=bool)
        for i in range(k):
            ok &= ins[i][1] if rows[i][r] else ins[i][0]
        if table[r]:
            hi |= ok
        else:
            lo |= ok
    return lo, hi


def evaluate3(nl: Netlist, values: dict[str, Tern]) -> dict[str, Tern]:
    """Every net's ternary value for the input vectors in ``values``."""
    nets = dict(values)
    size = len(next(iter(values.values()))[0]) if values else 1
    for cell in nl.topo_cells():
        out = _cell3(cell.type, [nets[n] for n in cell.inputs], cell.params)
        if not cell.inputs:  # a constant: one value, for every vector
            out = (np.broadcast_to(out[0], size).copy(), np.broadcast_to(out[1], size).copy())
        for net in cell.outputs:
            nets[net] = out
    return nets
