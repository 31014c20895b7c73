"""Static hazards of a combinational netlist by ternary simulation (Eichelberger), vectorised.

A mechanism's signals move continuously: while one input travels, it is at mid-stroke, which
is the ternary value X. An output that should hold across that single-input change but is X
in ternary simulation has a static logic hazard: its mechanism moves partway and back, which
the kinematic proof rejects as a failed dwell. The two-level mapper avoids them with consensus
terms; a multi-level network (restructured by ABC, or composed of per-node covers) has to be
checked, and this is that check: every input vector and every single-input change by
enumeration below :data:`SAT_MIN_INPUTS` inputs, by SAT from there on
(:mod:`mechc.passes.hazard_sat`: the same question, no enumeration, a proof over all 2**n * n
changes), whichever is faster at that size (measured: docs/multilevel.md).
"""

from __future__ import annotations

import numpy as np

from mechc.ir.netlist import Netlist
from mechc.ir.ternary import Tern, evaluate3
from mechc.logic.cubes import input_matrix
from mechc.passes.hazard_sat import sat_hazards

#: The most inputs :func:`hazard_transitions` enumerates (2^n * n changes); beyond, it takes a
#: seeded sample of vectors (never used for a verdict: the hazard check goes to SAT there).
MAX_EXHAUSTIVE_INPUTS = 16
SAMPLE_VECTORS = 1 << 14
#: From this many inputs :func:`static_hazards` asks SAT instead of enumerating (measured on
#: ABC's mappings: ALU, 14 inputs, 0.067 s enumerated against 0.040 s by SAT; 8-bit adder, 16
#: inputs, 0.171 s against 0.023 s; 6-bit adder, 12 inputs, a tie at 0.02 s). One check is
#: not the whole cost: the enumerated cure below SAT_CURE_MIN_INPUTS checks again after each
#: output, and there SAT's per-call set-up dominates (the ALU's multi-level stage took 60 s
#: with the SAT check against 14.8 s enumerated), so both switch at the same width.
SAT_MIN_INPUTS = 15


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


def static_hazards(nl: Netlist, seed: int = 0, method: str = "auto") -> dict[str, int]:
    """Output -> how many single-input changes leave it logically unchanged but X in ternary
    simulation: all of them by enumeration ("enumerate", "auto" below SAT_MIN_INPUTS inputs),
    or 1, a witness, for each output SAT finds one for ("sat", "auto" from SAT_MIN_INPUTS on;
    an output SAT leaves out has none at all). ``seed`` is kept for callers of old: neither
    method samples any more."""
    n = len(nl.inputs)
    if method == "auto":
        method = "enumerate" if n < SAT_MIN_INPUTS else "sat"
    if method == "sat":
        return {o: 1 for o in sat_hazards(nl)}
    if n > MAX_EXHAUSTIVE_INPUTS:
        raise ValueError(f"{n} inputs are too many to enumerate every change: use SAT")
    return {o: sum(v.shape[1] for _, v in ts)
            for o, ts in hazard_transitions(nl, seed).items()}
