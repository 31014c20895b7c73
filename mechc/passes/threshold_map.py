"""Mapping outputs to THRESHOLD cells (``mechc compile --map threshold|auto``; 001 Ch. III).

- ``threshold``: every output whose function depends on at most three inputs becomes one
  THRESHOLD cell with the minimum-threshold realisation of :func:`mechc.threshold.realise`
  (weights, ascending thresholds, ``below``), over the inputs it depends on; a function that is
  a constant or a single literal stays a CONST cell, a wire or a NOT cell.
- ``auto``: an output of at most three inputs becomes a THRESHOLD cell only where that makes
  the whole netlist cost fewer parts than the conventional network (the full adder's sum,
  001 §3.8.2), tried output by output, keeping each switch that lowers the total.

Outputs of more than three inputs are left to the conventional mapper (their 3-input
sub-functions are not extracted; see docs/threshold.md). The function of an output is its
minimised cover, so don't-cares are resolved as the minimiser chose.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mechc.cells.library import Library
from mechc.errors import DesignError
from mechc.ir.equations import Equations
from mechc.ir.netlist import CellInst, Netlist
from mechc.passes.map_sop import Mapped, map_sop
from mechc.threshold.functions import depends_on
from mechc.threshold.weights import Realisation, realise

MAX_INPUTS = 3


def cover_table(eq: Equations, name: str) -> tuple[int, ...]:
    """Truth table of an output's minimised cover over all the spec's inputs (input 0 MSB)."""
    n = len(eq.inputs)
    m = np.arange(1 << n)
    on = np.zeros(1 << n, dtype=bool)
    for cube in eq.covers[name].cubes:
        on |= (m & cube.mask) == cube.value
    return tuple(int(v) for v in on)


def restrict(tt: tuple[int, ...], keep: list[int], n: int) -> tuple[int, ...]:
    """The table over the inputs ``keep`` (others set to 0; they do not matter)."""
    k = len(keep)
    out = []
    for sub in range(1 << k):
        m = 0
        for i, j in enumerate(keep):
            if sub >> (k - 1 - i) & 1:
                m |= 1 << (n - 1 - j)
        out.append(tt[m])
    return tuple(out)


def threshold_candidate(eq: Equations, name: str) -> tuple[list[str], Realisation] | None:
    """(inputs, realisation) for an output a THRESHOLD cell can take, else None (more than
    three inputs, or a constant or a single literal, which need no generator)."""
    n = len(eq.inputs)
    tt = cover_table(eq, name)
    keep = depends_on(tt)
    if len(keep) < 2 or len(keep) > MAX_INPUTS:
        return None
    return [eq.inputs[j] for j in keep], realise(restrict(tt, keep, n), n=len(keep))


def params_of(r: Realisation) -> dict:
    return {"weights": [int(w) for w in r.weights],
            "thresholds": [float(t) for t in r.thresholds], "below": int(r.below)}


def parts(nl: Netlist, library: Library) -> int:
    return sum(library[c.cell].cost(len(c.inputs)) for c in nl.cells.values())


def build(eq: Equations, library: Library, opts, chosen: dict[str, tuple[list[str], Realisation]]):
    """Conventional netlist for the other outputs, plus one THRESHOLD cell per chosen output."""
    rest = [o for o in eq.outputs if o not in chosen]
    conv = map_sop(replace(eq, outputs=rest), library, replace(opts, target="conventional"))
    nl = conv.netlist
    cls = library.for_type("THRESHOLD", MAX_INPUTS)
    if cls is None and chosen:
        raise DesignError("the cell library has no THRESHOLD cell")
    taken = set(nl.driver) | set(eq.outputs)
    implemented = dict(conv.implemented)
    for k, name in enumerate(o for o in eq.outputs if o in chosen):
        ins, r = chosen[name]
        net = name if name not in nl.driver else _fresh(taken)
        taken.add(net)
        cid = f"t{k + 1}"
        nl.add_cell(CellInst(cid, cls.name, "THRESHOLD", tuple(ins), (net,), params_of(r)),
                    pin_names=cls.input_names(len(ins)), out_pins=list(cls.outputs))
        nl.set_output(name, net)
        implemented[name] = (f"THRESHOLD({', '.join(ins)}; w={list(r.weights)}, "
                             f"T={list(r.thresholds)}, below={r.below})")
    # keep the spec's output order
    nl.outputs = {o: nl.outputs[o] for o in eq.outputs}
    nl.check()
    return Mapped(nl, {o: implemented[o] for o in eq.outputs})


def _fresh(taken: set[str]) -> str:
    k = 1
    while f"t{k}" in taken:
        k += 1
    return f"t{k}"


def map_threshold(eq: Equations, library: Library, opts):
    if opts.target not in ("threshold", "auto"):
        raise ValueError(f"unknown mapping target {opts.target!r}")
    cands = {o: c for o in eq.outputs if (c := threshold_candidate(eq, o)) is not None}
    if opts.target == "threshold":
        return build(eq, library, opts, cands)
    chosen: dict = {}
    best = build(eq, library, opts, chosen)
    best_parts = parts(best.netlist, library)
    for name, c in cands.items():
        trial = build(eq, library, opts, {**chosen, name: c})
        p = parts(trial.netlist, library)
        if p < best_parts:
            chosen, best, best_parts = {**chosen, name: c}, trial, p
    return best
