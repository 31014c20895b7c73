"""Kinematic evaluation of a whole mechanism: inputs -> every body's pose, vectorised.

Cells are solved in topological order by their own closed forms (``Cell.kinematics``); the rods
of each net carry a driver's output slider to its loads' input sliders.
"""

from __future__ import annotations

import numpy as np

from mechc.library import Library
from mechc.mech.assemble import Mechanism
from mechc.mech.kinematics import Poses, _slider_from_rod, position
from mechc.mech.model import Body, Terminal


def signal_of(t: Terminal, body: Body, poses: Poses) -> np.ndarray:
    """Signal value of a terminal: 0 at its off position, 1 at on (projected on off->on)."""
    p = ((t.off[0] + t.on[0]) / 2, (t.off[1] + t.on[1]) / 2)
    x, y = position(body, poses, p)
    dx, dy = t.on[0] - t.off[0], t.on[1] - t.off[1]
    return ((x - t.off[0]) * dx + (y - t.off[1]) * dy) / (dx * dx + dy * dy)


def evaluate(mech: Mechanism, lib: Library, cell_types: dict[str, str],
             values: dict[str, np.ndarray]) -> Poses:
    """Poses of every body for input signal values (0..1 arrays, one per input)."""
    size = len(next(iter(values.values())))
    S = mech.ctx.stroke
    poses = Poses()
    bodies = mech.body_index()
    for name, part in mech.inputs.items():
        t = part.terminals[name]
        poses.u[t.body] = (np.asarray(values[name], dtype=float) - 0.5) * S
        poses.bad[t.body] = np.zeros(size, dtype=bool)
    rods_to: dict[str, list] = {}
    for part in mech.nets.values():
        for j in part.joints:
            rods_to.setdefault(j.b, []).append(j)
    for cid in mech.order:
        part = mech.cells[cid]
        fixed = {}
        for t in part.terminals.values():
            for j in rods_to.get(t.body, []):
                if t.body not in fixed:
                    _slider_from_rod(j, bodies[t.body], bodies[j.a], poses, size)
                    fixed[t.body] = poses.u[t.body]
        cls = lib[cell_types[cid]]
        sub = cls.kinematics(part, fixed, size)
        for b, bad in poses.bad.items():  # carry the badness of what drives this cell
            if b in fixed:
                sub.mark(b, bad)
        poses.update(sub)
    return poses


def output_signals(mech: Mechanism, poses: Poses) -> dict[str, np.ndarray]:
    bodies = mech.body_index()
    out = {}
    for name, (owner, pin) in mech.outputs.items():
        t = mech.owner_part(owner).terminals[pin]
        out[name] = signal_of(t, bodies[t.body], poses)
    return out
