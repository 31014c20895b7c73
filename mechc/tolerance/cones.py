"""The states each cell actually sees: a cell's poses depend only on the primary inputs in its
fan-in cone, so of the proof's S states it needs only the distinct values of those inputs (a
two-input cell of the sorter: 80 of 688). A tolerance run solves each cell on its own distinct
states and expands to all S only where a check or an output reads them.

Each owner (an input's slider part or a cell) gets ``rep`` (its distinct states, as indices of
full states) and ``inv`` (for every full state, the index of its distinct state). A load's cone
holds its driver's, so a driver's poses reach a load's states through ``inv[rep]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.ir.mechanism import Mechanism
from mechc.parts.pushrod import NetRod, net_rods


@dataclass
class StateSet:
    rep: np.ndarray  # (U,) full-state index of each distinct state
    inv: np.ndarray  # (S,) distinct-state index of each full state

    @property
    def size(self) -> int:
        return len(self.rep)


@dataclass
class Plan:
    owner_of: dict[str, str]  # body id -> "in:NAME" or cell id
    sets: dict[str, StateSet]  # owner -> its distinct states
    rods_to: dict[str, list[tuple[str, NetRod]]]  # load body -> (net name, rod)


def plan(mech: Mechanism, names: list[str], values: np.ndarray) -> Plan:
    owner_of = {}
    for name, part in mech.inputs.items():
        for b in part.bodies:
            owner_of[b.id] = f"in:{name}"
    for cid in mech.order:
        for b in mech.cells[cid].bodies:
            owner_of[b.id] = cid
    rods_to: dict[str, list[tuple[str, NetRod]]] = {}
    for net, part in mech.nets.items():
        for r in net_rods(part):
            rods_to.setdefault(r.load, []).append((net, r))
    cone: dict[str, set[int]] = {f"in:{nm}": {k} for k, nm in enumerate(names)}
    for cid in mech.order:
        c: set[int] = set()
        for t in mech.cells[cid].terminals.values():
            for _, r in rods_to.get(t.body, []):
                c |= cone[owner_of[r.driver]]
        cone[cid] = c
    sets = {}
    for owner, c in cone.items():
        cols = values[sorted(c)] if c else np.zeros((1, values.shape[1]))
        _, rep, inv = np.unique(cols, axis=1, return_index=True, return_inverse=True)
        sets[owner] = StateSet(rep, inv.reshape(-1))
    return Plan(owner_of, sets, rods_to)
