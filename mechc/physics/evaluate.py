"""Kinematic evaluation of a whole mechanism: inputs -> every body's pose, vectorised.

Cells are solved in topological order by their own closed forms (``Cell.kinematics``); the rods
of each net carry a driver's output slider to its loads' input sliders, and each rod body is
posed on the line between its two pins.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from mechc.ir.mechanism import Body, Mechanism, Terminal
from mechc.parts.pushrod import NetRod, net_rods, pose_rod_body
from mechc.parts.rod import slider_from_rod
from mechc.physics.closed_form import Poses, position


class CellModels(Protocol):
    """What the physics asks of a cell library: the cell class of a name, whose
    ``kinematics`` and ``build_dynamics`` it calls (``mechc.cells.library.Library`` is one)."""

    def __getitem__(self, name: str) -> Any: ...


def signal_of(t: Terminal, body: Body, poses: Poses) -> np.ndarray:
    """Signal value of a terminal: 0 at its off position, 1 at on (projected on off->on)."""
    x, y = position(body, poses, t.design_point)
    dx, dy = t.on[0] - t.off[0], t.on[1] - t.off[1]
    return ((x - t.off[0]) * dx + (y - t.off[1]) * dy) / (dx * dx + dy * dy)


def evaluate(mech: Mechanism, lib: CellModels, cell_types: dict[str, str],
             values: dict[str, np.ndarray],
             state: dict[str, np.ndarray] | None = None) -> Poses:
    """Poses of every body for input signal values (0..1 arrays, one per input).

    Stateful cells (MEMORY) need their previous state (``state``: cell id -> 0/1 per sample,
    default their ``initial``). Their outputs are first placed from that state alone, so the
    cells they feed (feedback loops) can be solved; when their own inputs are known they are
    solved again, and ``poses.state`` says where each now stands (fundamental mode: the caller
    iterates until the states stop changing)."""
    size = len(next(iter(values.values())))
    S = mech.ctx.stroke
    poses = Poses()
    bodies = mech.body_index()
    for name, part in mech.inputs.items():
        t = part.terminals[name]
        poses.u[t.body] = (np.asarray(values[name], dtype=float) - 0.5) * S
        poses.bad[t.body] = np.zeros(size, dtype=bool)
    rods_to: dict[str, list[NetRod]] = {}
    for part in mech.nets.values():
        for r in net_rods(part):
            rods_to.setdefault(r.load, []).append(r)
    prior = {}
    for cid in mech.order:
        cls = lib[cell_types[cid]]
        if getattr(cls, "stateful", False):
            part = mech.cells[cid]
            init = np.full(size, float(part.data.get("initial", 0)))
            prior[cid] = init if state is None or cid not in state else state[cid]
            poses.update(cls.kinematics(part, {}, size, prior[cid]))
    for cid in mech.order:
        part = mech.cells[cid]
        fixed = {}
        for t in part.terminals.values():
            for r in rods_to.get(t.body, []):
                if t.body not in fixed:
                    slider_from_rod(r.as_joint(), bodies[t.body], bodies[r.driver], poses, size)
                    fixed[t.body] = poses.u[t.body]

        cls = lib[cell_types[cid]]
        sub = cls.kinematics(part, fixed, size, prior.get(cid))
        for b in fixed:  # carry the badness of what drives this cell
            if b in poses.bad:
                sub.mark(b, poses.bad[b])
        poses.update(sub)
    # the rods themselves, bodies of plate between their pins, once every cell stands where it
    # ends (a MEMORY's output is placed first from its state, then again from its inputs)
    for rods in rods_to.values():
        for r in rods:
            if r.body is not None:
                pose_rod_body(r, bodies[r.body], bodies[r.driver], bodies[r.load], poses, size)
    return poses


def settle(mech: Mechanism, lib: CellModels, cell_types: dict[str, str],
           values: dict[str, np.ndarray], state: dict[str, np.ndarray] | None = None,
           max_rounds: int = 16) -> tuple[Poses, dict[str, np.ndarray], np.ndarray]:
    """Fundamental mode in closed form: evaluate, let the stateful cells take their new
    states, evaluate again until no state changes. Returns the poses, the states and a mask of
    samples that never came to rest (an oscillation: the states keep changing)."""
    size = len(next(iter(values.values())))
    state = {k: np.broadcast_to(np.asarray(v, dtype=float), (size,)).copy()
             for k, v in (state or {}).items()}
    for _ in range(max_rounds):
        poses = evaluate(mech, lib, cell_types, values, state or None)
        changed = np.zeros(size, dtype=bool)
        for cid, new in poses.state.items():
            old = state.get(cid, np.full(size, float(mech.cells[cid].data.get("initial", 0))))
            changed |= np.asarray(new) != old
            state[cid] = np.asarray(new, dtype=float)
        if not changed.any():
            return poses, state, changed
    return poses, state, changed


def output_signals(mech: Mechanism, poses: Poses) -> dict[str, np.ndarray]:
    bodies = mech.body_index()
    out = {}
    for name, (owner, pin) in mech.outputs.items():
        t = mech.owner_part(owner).terminals[pin]
        out[name] = signal_of(t, bodies[t.body], poses)
    return out
