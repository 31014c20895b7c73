"""Many perturbed designs solved at once: one evaluation of the closed forms over an axis of
samples x states, and every check of the kinematic proof measured per sample.

The mechanism's dimensions become arrays of length samples x states (each sample's value
repeated over its states, ``mechc.tolerance.dimensions.perturb``), the inputs are the proof's
states tiled once per sample, and ``mechc.physics.evaluate.evaluate`` (the kinematic proof's own
evaluation) solves them all in one pass. The checks are those of ``prove_kinematic``, each
reduced over a sample's own states: outputs at rest within the tolerance of their positions,
outputs that must not change dwelling within it along every single-input change, transmission
angles, distance from toggle, states that cannot be solved, and the springs' force against what
they must move; plus the input actuators' rating against their demand with the springs' error.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.mechanism import GROUND
from mechc.physics.closed_form import position
from mechc.physics.evaluate import evaluate, output_signals
from mechc.physics.measures import (
    MIN_SINGULAR_MARGIN_DEG,
    MIN_SPRING_MARGIN,
    MIN_TRANSMISSION_DEG,
)
from mechc.physics.measures import _where as where_of  # the checks' places, as the proof's
from mechc.tolerance.dimensions import Dim, perturb
from mechc.tolerance.states import States

REST = "output at rest"
DWELL = "output dwell"
ACTUATOR = "actuator force (springs at tolerance)"


@dataclass(frozen=True)
class CheckKey:
    name: str
    where: str
    limit: float
    sense: str  # ">=" or "<="
    unit: str = ""

    def passed(self, v: np.ndarray) -> np.ndarray:
        """Per sample; NaN never passes (as ``mechc.ir.check.Check``)."""
        with np.errstate(invalid="ignore"):
            return (v >= self.limit) if self.sense == ">=" else (v <= self.limit)


@dataclass
class ChunkResult:
    checks: dict[CheckKey, np.ndarray] = field(default_factory=dict)  # key -> (M,)
    rest_pos: dict[str, np.ndarray] = field(default_factory=dict)  # output -> (M, n_rest)
    worst_dev: dict[str, np.ndarray] = field(default_factory=dict)  # output -> (M,) fraction


class Batch:
    """Solves chunks of samples of one design; ``lost`` is each output's lost motion from pin
    clearance per state (fraction of stroke, added to its deviation: the play taken up the
    worst way)."""

    def __init__(self, design: Design, lib: Library, states: States, dims: list[Dim],
                 tolerance: float = 0.05, lost: dict[str, np.ndarray] | None = None):
        self.design, self.lib, self.states, self.dims = design, lib, states, dims
        self.mech = design.mechanism
        self.tolerance = tolerance
        self.lost = lost or {}
        self.types = {c.id: c.cell for c in design.netlist.cells.values()}
        self.geo = [k for k, d in enumerate(dims) if d.obj != "spring" and d.attr != "outline"]
        self.spring_dims = {(d.part, d.index, d.attr): k for k, d in enumerate(dims)
                            if d.obj == "spring"}
        self.bodies = self.mech.body_index()

    # ---- solving ------------------------------------------------------------------------
    def solve(self, delta: np.ndarray):
        """Poses and output signals ((M, S) per output) of the samples ``delta`` (M, D)."""
        M, S = delta.shape[0], self.states.size
        ks = [k for k in self.geo if np.any(delta[:, k])]
        # each sample's value repeated over its states: one pass per dimension
        cols = [np.repeat(self.dims[k].nominal + delta[:, k], S) for k in ks]
        mech = perturb(self.mech, [self.dims[k] for k in ks], cols, springs=False,
                       absolute=True) if ks else self.mech
        values = {nm: np.tile(self.states.values[i], M) for i, nm in enumerate(self.states.names)}
        poses = evaluate(mech, self.lib, self.types, values)
        sig = {o: np.broadcast_to(v, (M * S,)).reshape(M, S)
               for o, v in output_signals(mech, poses).items()}
        return mech, poses, sig

    def signals(self, delta: np.ndarray) -> dict[str, np.ndarray]:
        return self.solve(delta)[2]

    # ---- the checks ---------------------------------------------------------------------
    def run(self, delta: np.ndarray) -> ChunkResult:
        mech, poses, sig = self.solve(delta)
        M, S, st = delta.shape[0], self.states.size, self.states
        res = ChunkResult()
        nr, ne, ns = st.n_rest, st.n_edges, st.samples
        for o, v in sig.items():
            lost = self.lost.get(o, np.zeros(S))
            want = st.rest_want[o]
            care = want != 2
            rest = v[:, :nr]
            dev = np.abs(rest - want[None, :]) + lost[None, :nr]
            dev = np.where(np.isnan(dev), np.inf, dev)
            r = dev[:, care].max(axis=1) if care.any() else np.zeros(M)
            path = v[:, nr:].reshape(M, ne, ns)
            d = np.abs(path - st.lo[o][None, :, None]) + lost[nr:].reshape(ne, ns)[None]
            d = np.where(np.isnan(d), np.inf, d).max(axis=2)
            hold = st.hold[o]
            w = d[:, hold].max(axis=1) if hold.any() else np.zeros(M)
            tol = self.tolerance
            res.checks[CheckKey(REST, o, tol, "<=", "of stroke")] = r
            res.checks[CheckKey(DWELL, o, tol, "<=", "of stroke")] = w
            res.rest_pos[o] = rest
            res.worst_dev[o] = np.maximum(r, w)
        self._angles(poses, M, S, res)
        for bid, bad in poses.bad.items():
            key = CheckKey("unsolvable states (binding or cannot assemble)", where_of(bid), 0.0,
                           "<=")
            n = np.broadcast_to(bad, (M * S,)).reshape(M, S).sum(axis=1).astype(float)
            res.checks[key] = np.maximum(res.checks.get(key, n), n)
        self._springs(mech, poses, delta, M, S, res)
        for c in self.mech.synthesis_checks():  # decided when the design was sized
            if c.name != "actuator force":
                res.checks[CheckKey(c.name, c.where, c.limit, c.sense, c.unit)] = np.full(
                    M, float(c.value))
        return res

    def _angles(self, poses, M: int, S: int, res: ChunkResult) -> None:
        for name, data, limit in (("transmission angle", poses.transmission,
                                   MIN_TRANSMISSION_DEG),
                                  ("distance from toggle", poses.singular_margin,
                                   MIN_SINGULAR_MARGIN_DEG)):
            for jid, mu in data.items():
                if not np.size(mu):
                    continue
                v = np.fmin.reduce(np.broadcast_to(mu, (M * S,)).reshape(M, S), axis=1)
                key = CheckKey(name, where_of(jid), limit, ">=", "°")
                old = res.checks.get(key)
                # as the proof: a joint whose every state is unsolved (NaN) fails its place
                res.checks[key] = v if old is None else np.where(
                    np.isnan(old) | np.isnan(v), np.nan, np.minimum(old, v))

    def _factors(self, delta: np.ndarray, part: str, index: int) -> tuple[np.ndarray, ...]:
        """Per sample (1 + e_rate) and e_preload of one spring."""
        kr = self.spring_dims.get((part, index, "rate"))
        kp = self.spring_dims.get((part, index, "preload"))
        M = delta.shape[0]
        er = delta[:, kr] if kr is not None else np.zeros(M)
        ep = delta[:, kp] if kp is not None else np.zeros(M)
        return 1.0 + er, ep

    def _springs(self, mech, poses, delta: np.ndarray, M: int, S: int,
                 res: ChunkResult) -> None:
        """Each spring's weakest force against what it must move, with its rate and preload
        at the sample's values; each input actuator's demand scaled by the strongest spring
        error of the sample (a bound: every spring the input moves at its heaviest)."""
        bodies = mech.body_index()
        worst = np.ones(M)
        for key, part in ([(f"cell:{c}", mech.cells[c]) for c in mech.order]
                          + [(f"input:{k}", p) for k, p in mech.inputs.items()]
                          + [(f"net:{k}", p) for k, p in mech.nets.items()]):
            need = part.data.get("spring_required_N", {})
            for i, sp in enumerate(part.springs):
                fr, ep = self._factors(delta, key, i)
                worst = np.maximum(worst, fr * (1.0 + ep))
                if not need.get(sp.id):
                    continue
                a = None if sp.a == GROUND else bodies[sp.a]
                b = None if sp.b == GROUND else bodies[sp.b]
                if (a is not None and not poses.known(a.id)) or (
                        b is not None and not poses.known(b.id)):
                    continue
                ax, ay = position(a, poses, sp.pa)
                bx, by = position(b, poses, sp.pb)
                stretch = np.broadcast_to(np.hypot(bx - ax, by - ay) - sp.rest, (M * S,))
                force = fr[:, None] * (sp.rate * stretch.reshape(M, S) + ep[:, None]
                                       * sp.preload)
                f = np.fmin.reduce(force, axis=1)
                res.checks[CheckKey("spring force margin", sp.id, MIN_SPRING_MARGIN, ">=",
                                    "x")] = f / need[sp.id]
        for name, act in mech.actuators.items():
            demand = max(act.get("required_right_N", 0.0), act.get("required_left_N", 0.0))
            res.checks[CheckKey(ACTUATOR, f"input {name}", 1.0, "<=", "x")] = (
                demand * worst / act["rated_force_N"])
