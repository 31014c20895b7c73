"""Samples of a sequential design proven together: the kinematic sequential proof's walks
(``mechc.proofs.seq_mechanism``: the spec's transition tour and seeded random walks, each step
sampled along the moving input, the MEMORY cells settled at every sample), with every sample's
states carried on its own.

Per sample, as the proof judges a design: every output at the end of every step within the
tolerance of what the spec expects, an output the step must not change dwelling within it all
along, no MEMORY driven by SET and RESET at once (it binds), no oscillation; plus every
spring's weakest force against what it must move, with the sample's rate and preload. Pin play
is not modelled here (its lost motion needs the derivatives of the combinational run).
"""

from __future__ import annotations

import numpy as np

from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.mechanism import GROUND
from mechc.physics.closed_form import position
from mechc.physics.evaluate import output_signals, settle
from mechc.physics.measures import MIN_SPRING_MARGIN
from mechc.proofs.seq_logic import expected_after, transition_tour
from mechc.tolerance.batch import DWELL, REST, CheckKey, ChunkResult
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

    def _mech(self, delta: np.ndarray, n: int):
        """The mechanism with each sample's dimensions repeated over ``n`` states."""
        ks = [k for k in self.geo if np.any(delta[:, k])]
        if not ks:
            return self.mech
        return perturb(self.mech, [self.dims[k] for k in ks],
                       [np.repeat(self.dims[k].nominal + delta[:, k], n) for k in ks],
                       springs=False, absolute=True)

    def run(self, delta: np.ndarray) -> ChunkResult:
        M, ns, tol = delta.shape[0], self.samples, self.tolerance
        t = np.linspace(0.0, 1.0, ns)
        at_rest, at_step = self._mech(delta, 1), self._mech(delta, ns)
        rest_dev = {o: np.zeros(M) for o in self.mech.outputs}
        dwell = {o: np.zeros(M) for o in self.mech.outputs}
        jam = np.zeros(M)
        osc = np.zeros(M)
        springs: dict[str, np.ndarray] = {}
        for seq, want in self.walks:
            cur = {k: float(v) for k, v in seq[0].items()}
            poses, state, _ = settle(at_rest, self.lib, self.types,
                                     {k: np.full(M, v) for k, v in cur.items()})
            self._outputs(at_rest, poses, M, 1, want[0], {}, rest_dev, dwell)
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
                self._outputs(at_step, poses, M, ns, want[k], want[k - 1], rest_dev, dwell)
                self._springs(at_step, poses, delta, M, ns, springs)
                state = {c: np.asarray(v).reshape(M, ns)[:, -1] for c, v in path_state.items()}
                cur = {n: float(v) for n, v in seq[k].items()}
        res = ChunkResult()
        for o in self.mech.outputs:
            res.checks[CheckKey(REST, o, tol, "<=", "of stroke")] = rest_dev[o]
            res.checks[CheckKey(DWELL, o, tol, "<=", "of stroke")] = dwell[o]
            res.worst_dev[o] = np.maximum(rest_dev[o], dwell[o])
        res.checks[CheckKey(JAM, "MEMORY", 0.0, "<=", "steps")] = jam
        res.checks[CheckKey(OSC, "design", 0.0, "<=", "steps")] = osc
        for sid, f in springs.items():
            res.checks[CheckKey("spring force margin", sid, MIN_SPRING_MARGIN, ">=", "x")] = f
        for c in self.mech.synthesis_checks():
            res.checks[CheckKey(c.name, c.where, c.limit, c.sense, c.unit)] = np.full(
                M, float(c.value))
        return res

    def _outputs(self, mech, poses, M: int, n: int, want: dict, before: dict,
                 rest_dev: dict, dwell: dict) -> None:
        for o, v in output_signals(mech, poses).items():
            w = want.get(o)
            if w is None:
                continue
            path = np.broadcast_to(v, (M * n,)).reshape(M, n)
            end = np.abs(path[:, -1] - w)
            rest_dev[o] = np.maximum(rest_dev[o], np.where(np.isfinite(end), end, np.inf))
            if before.get(o) is not None and before[o] == w:
                d = np.abs(path - w)
                d = np.where(np.isfinite(d), d, np.inf).max(axis=1)
                dwell[o] = np.maximum(dwell[o], d)

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
