"""Which input changes a proof exercises: every vector, every single-input change, Gray tours,
and for designs too wide for those, changes directed to switch every cell."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.errors import UsageError
from mechc.ir.netlist import Netlist


def bits(rows: np.ndarray, n: int) -> np.ndarray:
    """(n, len(rows)) 0/1 matrix, input 0 the most significant bit."""
    shifts = np.arange(n - 1, -1, -1, dtype=np.int64)[:, None]
    return ((rows[None, :] >> shifts) & 1).astype(float)


def single_changes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Every single-input change as (row with the input off, input index)."""
    rows, ks = [], []
    idx = np.arange(1 << n, dtype=np.int64)
    for k in range(n):
        bit = 1 << (n - 1 - k)
        low = idx[(idx & bit) == 0]
        rows.append(low)
        ks.append(np.full(len(low), k))
    return np.concatenate(rows), np.concatenate(ks)


def gray_tour(n: int) -> list[int]:
    """All 2**n vectors, each differing from the last in one input (reflected Gray code)."""
    return [i ^ (i >> 1) for i in range(1 << n)]


def random_walk(n: int, start: int, steps: int, seed: int) -> list[int]:
    """Seeded random single-input changes from ``start`` (deterministic for a seed)."""
    rng = np.random.default_rng(seed)
    out, cur = [], int(start)
    for _ in range(steps):
        cur ^= 1 << int(rng.integers(n))  # Python ints: any number of inputs
        out.append(cur)
    return out


#: Directed changes: at most this many cells no sampled change toggles are looked up by SAT.
MAX_SAT_CELLS = 200
#: Directed changes: random states whose every single-input change is tried.
POOL_STATES = 256


@dataclass
class Directed:
    """Single-input changes chosen so that every cell's output switches in one of them.

    ``lo``: (n, N) boolean start states, the moving input off; ``k``: the moving input of each;
    ``toggled``: cells whose output switches in at least one of them; ``never``: cells no
    single-input change can switch (proved by SAT: constant or redundant cells); ``unknown``:
    cells neither found nor proved (SAT budget or a cell with no CNF form)."""

    lo: np.ndarray
    k: np.ndarray
    cells: int
    toggled: int
    never: int
    unknown: int

    def coverage(self) -> dict:
        return {"directed_changes": int(len(self.k)), "cells": self.cells,
                "cells_toggled": self.toggled, "cells_never_toggle": self.never,
                "cells_not_reached": self.unknown}


def _toggles(nl: Netlist, names: list[str], lo: np.ndarray, k: np.ndarray,
             cells: list[str]) -> np.ndarray:
    """(changes, cells) boolean: which cells' outputs differ between each change's two ends
    (``lo`` row i is input ``names[i]``, ``k`` indexes ``names``)."""
    hi = lo.copy()
    hi[k, np.arange(len(k))] = True
    a = nl.evaluate({nm: lo[i] for i, nm in enumerate(names)})
    b = nl.evaluate({nm: hi[i] for i, nm in enumerate(names)})
    out = [nl.cells[c].outputs[0] for c in cells]
    return np.stack([a[net] != b[net] for net in out], axis=1) if out \
        else np.zeros((len(k), 0), dtype=bool)


def try_directed(nl: Netlist, names: list[str], seed: int) -> Directed | None:
    """:func:`directed_changes`, or None where the netlist cannot be evaluated as logic (a
    stateful cell, or a logic type whose cell file is not loaded): the proofs that call it
    then run their random sample alone, as they did before."""
    if nl.state_nets():
        return None
    try:
        return directed_changes(nl, names, seed)
    except (UsageError, TypeError):
        return None


def directed_changes(nl: Netlist, names: list[str], seed: int) -> Directed:
    """Every input toggled from ``POOL_STATES`` seeded random states, evaluated by the cells'
    logic; greedily the fewest of those changes that switch every cell that any of them
    switches; for each cell still not switched, a change that does from a SAT query (two copies
    of the netlist, inputs differing in exactly one place, the cell's outputs differing), or
    the proof that none exists. Only the choice of cases reads the logic types; the proofs
    that run them still move the geometry."""
    n = len(names)
    rng = np.random.default_rng(seed)
    cells = [c.id for c in nl.cells.values() if c.outputs]
    states = rng.random((n, POOL_STATES)) < 0.5
    lo = np.repeat(states, n, axis=1)
    k = np.tile(np.arange(n), POOL_STATES)
    lo[k, np.arange(len(k))] = False
    d = _toggles(nl, names, lo, k, cells)
    chosen: list[int] = []
    covered = np.zeros(len(cells), dtype=bool)
    counts = d.sum(axis=1).astype(np.int64)
    while counts.size and counts.max() > 0:
        j = int(counts.argmax())
        chosen.append(j)
        new = d[j] & ~covered
        covered |= new
        counts -= d[:, new].sum(axis=1)
    los = [lo[:, j] for j in chosen]
    ks = [int(k[j]) for j in chosen]
    never = unknown = 0
    missing = [i for i in range(len(cells)) if not covered[i]]
    if missing:
        found, never, unknown = _sat_toggles(nl, names, [cells[i] for i in missing])
        for vec, kk in found:
            col = np.array([(vec >> (n - 1 - i)) & 1 for i in range(n)], dtype=bool)
            col[kk] = False
            los.append(col)
            ks.append(kk)
        if found:  # which cells these changes switch (often more than the one asked for)
            extra = _toggles(nl, names, np.stack(los[len(chosen):], axis=1),
                             np.array(ks[len(chosen):]), cells)
            covered |= extra.any(axis=0)
    lo_m = np.stack(los, axis=1) if los else np.zeros((n, 0), dtype=bool)
    return Directed(lo_m, np.array(ks, dtype=np.int64), len(cells), int(covered.sum()), never,
                    unknown)


def _sat_toggles(nl: Netlist, names: list[str],
                 cells: list[str]) -> tuple[list[tuple[int, int]], int, int]:
    """For each cell (up to ``MAX_SAT_CELLS``): a (start vector, moving input) that switches
    it, found by SAT, or proved impossible. Returns (changes found, cells that can never
    switch, cells not decided)."""
    # python-sat: loaded only for a design whose sample leaves a cell unswitched
    from pysat.card import CardEnc
    from pysat.solvers import Solver

    from mechc.proofs.sat_equiv import SOLVER, Cnf, NotEncodable, encode_netlist

    n = len(names)
    cnf = Cnf()
    x = {nm: cnf.new() for nm in names}
    sel = [cnf.new() for _ in names]
    y = {nm: cnf.xor2(x[nm], s) for nm, s in zip(names, sel)}
    try:
        a, b = encode_netlist(nl, cnf, x), encode_netlist(nl, cnf, y)
    except NotEncodable:
        return [], 0, len(cells)
    one = CardEnc.equals(lits=sel, bound=1, top_id=cnf.top)
    top = max(cnf.top, one.nv)
    found: list[tuple[int, int]] = []
    never = unknown = 0
    with Solver(name=SOLVER, bootstrap_with=cnf.clauses + one.clauses) as s:
        for i, cid in enumerate(cells):
            if i >= MAX_SAT_CELLS:
                unknown += len(cells) - i
                break
            net = nl.cells[cid].outputs[0]
            top += 1  # a fresh variable: "the cell's two outputs differ", as an assumption
            s.add_clause([-top, a[net], b[net]])
            s.add_clause([-top, -a[net], -b[net]])
            if not s.solve(assumptions=[top]):
                never += 1
                continue
            model = set(v for v in s.get_model() if v > 0)
            vec = sum(1 << (n - 1 - j) for j, nm in enumerate(names) if x[nm] in model)
            kk = next(j for j, v in enumerate(sel) if v in model)
            found.append((vec, kk))
    return found, never, unknown
