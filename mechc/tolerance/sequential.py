"""Samples of a sequential design proven together: the kinematic sequential proof's walks
(``mechc.proofs.seq_mechanism``: the spec's transition tour and seeded random walks, each step
sampled along the moving input, the MEMORY cells settled at every sample), with every sample's
states carried on its own.

Per sample, as the proof judges a design: every output at the end of every step within the
tolerance of what the spec expects, an output the step must not change dwelling within it all
along, no MEMORY driven by SET and RESET at once (it binds), no oscillation; plus every
spring's weakest force against what it must move, with the sample's rate and preload. Pin play
is the lost motion of the combinational run (``mechc.tolerance.sensitivity``), taken from the
finite differences of every output at every point of the walks (``signals``), added to each
output's deviation there.
"""

from __future__ import annotations

import numpy as np

from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.mechanism import GROUND
from mechc.parts.poses import Poses
from mechc.physics.closed_form import position
from mechc.physics.evaluate import output_signals, settle
from mechc.physics.measures import MIN_SPRING_MARGIN
from mechc.proofs.seq_logic import expected_after, transition_tour
from mechc.tolerance.batch import DWELL, REST, CheckKey, ChunkResult
from mechc.tolerance.clearance import displacement, radius
from mechc.tolerance.dimensions import Dim, perturb

JAM = "SET and RESET together (MEMORY binds)"
OSC = "oscillation (states keep changing)"
RANDOM_WALKS = 4  # as the kinematic sequential proof


class SequentialBatch:
    def __init__(self, design: Design, lib: Library, dims: list[Dim], tolerance: float = 0.05,
                 samples: int = 21, seed: int = 0):
        self.design, self.lib, self.dims = design, lib, dims
        self.mech = design.mechanism
        self.tolerance = tolerance
        self.samples = samples
        self.types = {c.id: c.cell for c in design.netlist.cells.values()}
        self.mems = [c.id for c in design.netlist.cells.values()
                     if getattr(lib[c.cell], "stateful", False)]
        self.walks = [(s, expected_after(design.spec, s))
                      for s in transition_tour(design.spec, seed=seed,
                                               random_walks=RANDOM_WALKS)]
        # joint points, cell rods' lengths and pivots (a net rod's own length needs the
        # combinational batch's rods: here a net's rod follows its pins, as in a design file)
        self.geo = [k for k, d in enumerate(dims)
                    if d.obj in ("joint", "data") or (d.obj == "body" and d.attr == "pivot")]
        self.spring_dims = {(d.part, d.index, d.attr): k for k, d in enumerate(dims)
                            if d.obj == "spring"}
        self.lost: dict[str, np.ndarray] = {}
        self._layout()
        self.solid = [b for part in [*self.mech.inputs.values(),
                                     *(self.mech.cells[c] for c in self.mech.order)]
                      for b in part.bodies]
        self.radii = {b.id: radius(b) for b in self.solid}
        self._nominal: list[Poses] = []
        self.trace(np.zeros((1, len(dims))), keep=self._nominal)

    def nominal_poses(self) -> list[Poses]:
        """Every body's poses at every point of the walks at nominal, a step at a time."""
        return self._nominal

    def _mech(self, delta: np.ndarray, n: int):
        """The mechanism with each sample's dimensions repeated over ``n`` states."""
        ks = [k for k in self.geo if np.any(delta[:, k])]
        if not ks:
            return self.mech
        return perturb(self.mech, [self.dims[k] for k in ks],
                       [np.repeat(self.dims[k].nominal + delta[:, k], n) for k in ks],
                       springs=False, absolute=True)

    # ---- the walks' layout: every point where an output is read ----------------------------
    def _layout(self) -> None:
        """Per output: the points of every walk where it is read (each walk's first state,
        then ``samples`` points along every step), what the spec wants at each step's end,
        and which points must hold it (a step that must leave the output where it is)."""
        ns = self.samples
        want_end: dict[str, list[float]] = {o: [] for o in self.mech.outputs}
        ends: dict[str, list[int]] = {o: [] for o in self.mech.outputs}
        hold: dict[str, list[float]] = {o: [] for o in self.mech.outputs}
        at = 0
        for seq, want in self.walks:
            for k in range(len(seq)):
                n = 1 if k == 0 else ns
                for o in self.mech.outputs:
                    w = want[k].get(o)
                    if w is not None:
                        ends[o].append(at + n - 1)
                        want_end[o].append(float(w))
                    keep = k > 0 and w is not None and want[k - 1].get(o) == w
                    hold[o] += [float(w) if keep else np.nan] * n
                at += n
        self.size = at
        self.ends = {o: np.asarray(v, dtype=np.int64) for o, v in ends.items()}
        self.want_end = {o: np.asarray(v) for o, v in want_end.items()}
        self.hold = {o: np.asarray(v) for o, v in hold.items()}

    def trace(self, delta: np.ndarray, keep: list[Poses] | None = None):
        """Every output at every point of the walks (M, size), and per sample the steps in
        which a MEMORY binds or the states oscillate, every spring's weakest margin and how
        far each body moves from its nominal poses (``keep``: a list to collect each step's
        poses in)."""
        M, ns = delta.shape[0], self.samples
        moves: dict[str, np.ndarray] = {}
        step = 0

        def record(poses: Poses, n: int) -> None:
            nonlocal step
            if keep is not None:
                keep.append(poses)
            elif self._nominal:
                # at the step's end only: mid-step a MEMORY's throw is a jump in time
                for b, d in displacement(self.solid, poses, self._nominal[step], M, n,
                                         self.radii, last=True).items():
                    moves[b] = np.maximum(moves[b], d) if b in moves else d
            step += 1

        t = np.linspace(0.0, 1.0, ns)
        at_rest, at_step = self._mech(delta, 1), self._mech(delta, ns)
        paths: dict[str, list[np.ndarray]] = {o: [] for o in self.mech.outputs}
        jam = np.zeros(M)
        osc = np.zeros(M)
        springs: dict[str, np.ndarray] = {}
        for seq, _ in self.walks:
            cur = {k: float(v) for k, v in seq[0].items()}
            poses, state, _ = settle(at_rest, self.lib, self.types,
                                     {k: np.full(M, v) for k, v in cur.items()})
            self._read(at_rest, poses, M, 1, paths)
            record(poses, 1)
            for k in range(1, len(seq)):
                moved = next(n for n in seq[k] if seq[k][n] != cur[n])
                vals = {n: np.full(M * ns, v) for n, v in cur.items()}
                vals[moved] = np.tile(cur[moved] + (seq[k][moved] - cur[moved]) * t, M)
                prior = {c: np.repeat(np.broadcast_to(v, (M,)), ns) for c, v in state.items()}
                poses, path_state, changing = settle(at_step, self.lib, self.types, vals,
                                                     prior)
                for c in self.mems:
                    for b in self.mech.cells[c].bodies:
                        bad = poses.bad.get(b.id)
                        if bad is not None:
                            jam += np.broadcast_to(bad, (M * ns,)).reshape(M, ns).any(axis=1)
                osc += np.broadcast_to(changing, (M * ns,)).reshape(M, ns).any(axis=1)
                self._read(at_step, poses, M, ns, paths)
                record(poses, ns)
                self._springs(at_step, poses, delta, M, ns, springs)
                state = {c: np.asarray(v).reshape(M, ns)[:, -1] for c, v in path_state.items()}
                cur = {n: float(v) for n, v in seq[k].items()}
        sig = {o: np.concatenate(v, axis=1) for o, v in paths.items()}
        return sig, jam, osc, springs, moves

    def signals(self, delta: np.ndarray) -> dict[str, np.ndarray]:
        """Every output at every point of the walks, (M, size): what the finite differences
        of the sensitivity (and the pins' lost motion) are taken of."""
        return self.trace(delta)[0]

    def rest_reference(self, o: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The points where output ``o`` is at rest (each step's end), what the spec wants
        there, and the lost motion of the pins there (fraction of stroke)."""
        ends = self.ends[o]
        lost = self.lost.get(o, np.zeros(self.size))[ends]
        return ends, self.want_end[o], lost

    def judged(self, o: str) -> np.ndarray:
        """(size,) bool: the points where output ``o`` is judged (a step's end, or holding)."""
        m = np.isfinite(self.hold[o])
        m[self.ends[o]] = True
        return m

    def run(self, delta: np.ndarray) -> ChunkResult:
        M, tol = delta.shape[0], self.tolerance
        sig, jam, osc, springs, moves = self.trace(delta)
        res = ChunkResult(moves=moves)
        for o, v in sig.items():
            lost = self.lost.get(o, np.zeros(self.size))
            ends = self.ends[o]
            end = np.abs(v[:, ends] - self.want_end[o][None, :]) + lost[ends][None, :]
            end = np.where(np.isfinite(end), end, np.inf)
            rest_dev = end.max(axis=1) if len(ends) else np.zeros(M)
            keep = np.isfinite(self.hold[o])
            d = np.abs(v[:, keep] - self.hold[o][keep][None, :]) + lost[keep][None, :]
            dwell = np.where(np.isfinite(d), d, np.inf).max(axis=1) if keep.any() \
                else np.zeros(M)
            res.checks[CheckKey(REST, o, tol, "<=", "of stroke")] = rest_dev
            res.checks[CheckKey(DWELL, o, tol, "<=", "of stroke")] = dwell
            res.worst_dev[o] = np.maximum(rest_dev, dwell)
            res.rest_pos[o] = v[:, ends]
        res.checks[CheckKey(JAM, "MEMORY", 0.0, "<=", "steps")] = jam
        res.checks[CheckKey(OSC, "design", 0.0, "<=", "steps")] = osc
        for sid, f in springs.items():
            res.checks[CheckKey("spring force margin", sid, MIN_SPRING_MARGIN, ">=", "x")] = f
        for c in self.mech.synthesis_checks():
            res.checks[CheckKey(c.name, c.where, c.limit, c.sense, c.unit)] = np.full(
                M, float(c.value))
        return res

    def _read(self, mech, poses, M: int, n: int, paths: dict) -> None:
        for o, v in output_signals(mech, poses).items():
            paths[o].append(np.array(np.broadcast_to(v, (M * n,)).reshape(M, n)))

    def _springs(self, mech, poses, delta: np.ndarray, M: int, n: int,
                 out: dict[str, np.ndarray]) -> None:
        bodies = mech.body_index()
        for cid in mech.order:
            part = mech.cells[cid]
            need = part.data.get("spring_required_N", {})
            for i, sp in enumerate(part.springs):
                if not need.get(sp.id):
                    continue
                a = None if sp.a == GROUND else bodies[sp.a]
                b = None if sp.b == GROUND else bodies[sp.b]
                if (a is not None and not poses.known(a.id)) or (
                        b is not None and not poses.known(b.id)):
                    continue
                kr = self.spring_dims.get((f"cell:{cid}", i, "rate"))
                kp = self.spring_dims.get((f"cell:{cid}", i, "preload"))
                fr = 1.0 + (delta[:, kr] if kr is not None else 0.0)
                ep = delta[:, kp] if kp is not None else np.zeros(M)
                ax, ay = position(a, poses, sp.pa)
                bx, by = position(b, poses, sp.pb)
                stretch = np.broadcast_to(np.hypot(bx - ax, by - ay) - sp.rest, (M * n,))
                force = np.broadcast_to(fr, (M,))[:, None] * (
                    sp.rate * stretch.reshape(M, n) + ep[:, None] * sp.preload)
                f = np.fmin.reduce(force, axis=1) / need[sp.id]
                out[sp.id] = np.fmin(out[sp.id], f) if sp.id in out else f
