"""Static hazards of a combinational netlist by ternary simulation (Eichelberger), vectorised.

A mechanism's signals move continuously: while one input travels, it is at mid-stroke, which
is the ternary value X. An output that should hold across that single-input change but is X
in ternary simulation has a static logic hazard: its mechanism moves partway and back, which
the kinematic proof rejects as a failed dwell. The two-level mapper avoids them with consensus
terms; a multi-level network (restructured by ABC, or composed of per-node covers) has to be
checked, and this is that check: every input vector and every single-input change, for
designs up to :data:`MAX_EXHAUSTIVE_INPUTS` inputs.
"""

from __future__ import annotations

import numpy as np

from mechc.ir.logic_types import evaluate_type
from mechc.ir.netlist import Netlist
from mechc.logic.cubes import input_matrix

#: Above this many inputs the check takes a seeded sample of vectors (2^n * n changes).
MAX_EXHAUSTIVE_INPUTS = 16
SAMPLE_VECTORS = 1 << 14

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


def hazard_transitions(nl: Netlist, seed: int = 0) -> dict[str, list[tuple[int, np.ndarray]]]:
    """Output -> [(k, vectors)]: the single-input changes that leave it logically unchanged but
    X in ternary simulation, as input k moving from 0 to 1 at each of ``vectors`` (one column
    per vector, one row per input; every vector up to MAX_EXHAUSTIVE_INPUTS inputs, a seeded
    sample beyond)."""
    n = len(nl.inputs)
    if n <= MAX_EXHAUSTIVE_INPUTS:
        bits = input_matrix(n)
    else:
        rng = np.random.default_rng(seed)
        bits = rng.integers(0, 2, size=(n, SAMPLE_VECTORS)).astype(bool)
    found: dict[str, list[tuple[int, np.ndarray]]] = {}
    for k in range(n):
        base = bits[:, ~bits[k]] if n <= MAX_EXHAUSTIVE_INPUTS else bits.copy()
        base[k] = False
        flip = base.copy()
        flip[k] = True
        a = nl.evaluate({x: base[i] for i, x in enumerate(nl.inputs)})
        b = nl.evaluate({x: flip[i] for i, x in enumerate(nl.inputs)})
        vals: dict[str, Tern] = {}
        for i, x in enumerate(nl.inputs):
            vals[x] = (~base[i] | (i == k), base[i] | (i == k))
        t = evaluate3(nl, vals)
        for o, net in nl.outputs.items():
            lo, hi = t[net]
            bad = (a[net] == b[net]) & lo & hi
            if bad.any():
                found.setdefault(o, []).append((k, base[:, bad]))
    return found


def static_hazards(nl: Netlist, seed: int = 0) -> dict[str, int]:
    """Output -> how many single-input changes leave it logically unchanged but X in ternary
    simulation (every vector up to MAX_EXHAUSTIVE_INPUTS inputs, a seeded sample beyond)."""
    return {o: sum(v.shape[1] for _, v in ts)
            for o, ts in hazard_transitions(nl, seed).items()}
