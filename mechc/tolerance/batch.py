"""Many perturbed designs solved at once: the closed forms over an axis of samples x states,
and every check of the kinematic proof measured per sample.

Each cell's dimensions become arrays of length samples x (the distinct states of its inputs,
``mechc.tolerance.cones``), each sample's value repeated over its states
(``mechc.tolerance.dimensions.perturb_part``); the cells are solved by their own closed forms
in the order and the way ``mechc.physics.evaluate.evaluate`` (the kinematic proof's
evaluation) solves them, all samples of a chunk in one pass. The checks are those of
``prove_kinematic``, each reduced over a sample's own states: outputs at rest within the
tolerance of their positions, outputs that must not change dwelling within it along every
single-input change, transmission angles, distance from toggle, states that cannot be solved,
and the springs' force against what they must move; plus the input actuators' rating against
their demand with the springs' error.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.mechanism import GROUND, Part
from mechc.parts.poses import Poses
from mechc.parts.pushrod import NetRod
from mechc.parts.rod import slider_from_rod
from mechc.physics.closed_form import position
from mechc.physics.evaluate import evaluate, signal_of
from mechc.physics.measures import (
    MIN_SINGULAR_MARGIN_DEG,
    MIN_SPRING_MARGIN,
    MIN_TRANSMISSION_DEG,
)
from mechc.physics.measures import _where as where_of  # the checks' places, as the proof's
from mechc.tolerance.clearance import displacement, radius
from mechc.tolerance.cones import plan
from mechc.tolerance.dimensions import Dim, perturb_part
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
class Solved:
    """One chunk of M samples: each owner's (input's or cell's) poses on its distinct states,
    its part at the samples' dimensions, and every output's signal on all S states."""

    M: int
    poses: dict[str, Poses] = field(default_factory=dict)
    parts: dict[str, Part] = field(default_factory=dict)
    signals: dict[str, np.ndarray] = field(default_factory=dict)  # output -> (M, S)


@dataclass
class ChunkResult:
    checks: dict[CheckKey, np.ndarray] = field(default_factory=dict)  # key -> (M,)
    rest_pos: dict[str, np.ndarray] = field(default_factory=dict)  # output -> (M, n_rest)
    worst_dev: dict[str, np.ndarray] = field(default_factory=dict)  # output -> (M,) fraction
    moves: dict[str, np.ndarray] = field(default_factory=dict)  # body -> (M,) mm, its most


class Batch:
    """Solves chunks of samples of one design; ``lost`` is each output's lost motion from pin
    clearance per state (fraction of stroke, added to its deviation: the play taken up the
    worst way).

    Each cell is solved on the distinct states of its own inputs (``mechc.tolerance.cones``);
    the nets' rods carry a driver's poses to a load's states. The solving itself is the
    kinematic proof's: each cell's ``kinematics`` and the rods' closed form
    (``slider_from_rod``), in the order ``mechc.physics.evaluate.evaluate`` takes."""

    def __init__(self, design: Design, lib: Library, states: States, dims: list[Dim],
                 tolerance: float = 0.05, lost: dict[str, np.ndarray] | None = None):
        self.design, self.lib, self.states, self.dims = design, lib, states, dims
        self.mech = design.mechanism
        self.tolerance = tolerance
        self.lost = lost or {}
        self.types = {c.id: c.cell for c in design.netlist.cells.values()}
        self.rod_length = {d.name[:-len(".length")]: k for k, d in enumerate(dims)
                           if d.obj == "body" and d.attr == "length"}  # net rods
        self.geo = [k for k, d in enumerate(dims) if d.obj != "spring" and d.attr != "outline"]
        self.spring_dims = {(d.part, d.index, d.attr): k for k, d in enumerate(dims)
                            if d.obj == "spring"}
        self.bodies = self.mech.body_index()
        self.plan = plan(self.mech, states.names, states.values)
        self.geo_by_part: dict[str, list[int]] = {}
        for k in self.geo:
            self.geo_by_part.setdefault(dims[k].part, []).append(k)
        self.mult = {o: np.bincount(ss.inv, minlength=ss.size).astype(float)
                     for o, ss in self.plan.sets.items()}
        self.radii = {b.id: radius(b) for b in self.bodies.values()}
        self._nominal: Solved | None = None
        for rods in self.plan.rods_to.values():
            for _, r in rods:
                if self.bodies[r.driver].kind != "slider":
                    raise UsageError(f"{r.id}: a net driven by a {self.bodies[r.driver].kind} "
                                     "(the tolerance run carries nets from sliders)")

    # ---- solving ------------------------------------------------------------------------
    def _values(self, part_key: str, delta: np.ndarray, U: int, only=None):
        """The part's changed dimensions as arrays of M x U (each sample's value repeated
        over its U states: one pass per dimension)."""
        ks = [k for k in self.geo_by_part.get(part_key, [])
              if (only is None or (self.dims[k].obj == "joint" and self.dims[k].index in only))
              and np.any(delta[:, k])]
        return [(self.dims[k], np.repeat(self.dims[k].nominal + delta[:, k], U)) for k in ks]

    def solve(self, delta: np.ndarray) -> Solved:
        """Every owner's poses on its distinct states (M x U each), for the samples ``delta``
        (M, D)."""
        M, st, pl = delta.shape[0], self.states, self.plan
        stroke = self.mech.ctx.stroke
        out = Solved(M)
        for k, name in enumerate(st.names):
            owner = f"in:{name}"
            part = self.mech.inputs[name]
            ss = pl.sets[owner]
            t = part.terminals[name]
            p = Poses()
            p.u[t.body] = np.tile((st.values[k, ss.rep] - 0.5) * stroke, M)
            p.bad[t.body] = np.zeros(M * ss.size, dtype=bool)
            out.poses[owner], out.parts[owner] = p, part
        for cid in self.mech.order:
            ss = pl.sets[cid]
            U, size = ss.size, M * ss.size
            part = perturb_part(self.mech.cells[cid], self._values(f"cell:{cid}", delta, U),
                                springs=False, absolute=True)
            fixed: dict[str, np.ndarray] = {}
            carried = Poses()
            for t in part.terminals.values():
                for net, r in pl.rods_to.get(t.body, []):
                    if t.body in fixed:
                        continue
                    drv = pl.owner_of[r.driver]
                    dset, dposes = pl.sets[drv], out.poses[drv]
                    take = (np.arange(M)[:, None] * dset.size
                            + dset.inv[ss.rep][None, :]).reshape(-1)
                    view = Poses(u={r.driver: dposes.u[r.driver][take]},
                                 bad={r.driver: dposes.bad[r.driver][take]})
                    rod = self._rod(net, r, delta, U)
                    slider_from_rod(rod.as_joint(), self.bodies[t.body], self.bodies[r.driver],
                                    view, size)
                    fixed[t.body] = view.u[t.body]
                    carried.bad[t.body] = view.bad[t.body]
                    carried.transmission[r.id] = view.transmission[r.id]
                    carried.singular_margin[r.id] = view.singular_margin[r.id]
            sub = self.lib[self.types[cid]].kinematics(part, fixed, size, None)
            for b, bad in carried.bad.items():  # the badness of what drives this cell
                sub.mark(b, bad)
            sub.transmission.update(carried.transmission)
            sub.singular_margin.update(carried.singular_margin)
            out.poses[cid], out.parts[cid] = sub, part
        for o, (owner, pin) in self.mech.outputs.items():
            part = out.parts[owner]
            t = part.terminals[pin]
            ss = pl.sets[owner]
            v = np.broadcast_to(signal_of(t, self.bodies[t.body], out.poses[owner]),
                                (M * ss.size,))
            out.signals[o] = v.reshape(M, ss.size)[:, ss.inv]
        return out

    def _rod(self, net: str, r: NetRod, delta: np.ndarray, U: int) -> NetRod:
        """A net's rod with its two pins at the sample's values (arrays of M x U)."""
        part = self.mech.nets[net]
        at = [next(i for i, j in enumerate(part.joints) if j is x) for x in r.joints]
        changes = self._values(f"net:{net}", delta, U, only=set(at))
        new = perturb_part(part, changes, absolute=True) if changes else part
        jd, jl = new.joints[at[0]], new.joints[at[-1]]
        # the rod keeps its own length (its holes' spacing, a dimension of its own): a driver's
        # hole off by h moves the load by h
        k = self.rod_length.get(r.body or "")
        length = r.length if k is None or not np.any(delta[:, k]) else np.repeat(
            self.dims[k].nominal + delta[:, k], U)
        if not changes and k is None:
            return r
        return replace(r, pa=jd.pa, pb=jl.pa, length=length)

    def signals(self, delta: np.ndarray) -> dict[str, np.ndarray]:
        return self.solve(delta).signals

    @property
    def size(self) -> int:
        """The proof states each sample is solved in (what ``signals`` gives per sample)."""
        return self.states.size

    def rest_reference(self, o: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The states where output ``o`` is at rest and cared for, what the spec wants there,
        and the lost motion of the pins there (fraction of stroke)."""
        st = self.states
        want = st.rest_want[o]
        at = np.flatnonzero(want != 2)  # DC
        return at, want[at].astype(float), self.lost.get(o, np.zeros(st.size))[at]

    # ---- the checks ---------------------------------------------------------------------
    def run(self, delta: np.ndarray) -> ChunkResult:
        solved = self.solve(delta)
        sig = solved.signals
        M, S, st = delta.shape[0], self.states.size, self.states
        res = ChunkResult()
        self._moves(solved, M, res)
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
        for owner, poses in solved.poses.items():
            U = self.plan.sets[owner].size
            self._angles(poses, M, U, res)
            for bid, bad in poses.bad.items():
                key = CheckKey("unsolvable states (binding or cannot assemble)", where_of(bid),
                               0.0, "<=")
                # states counted as the proof counts them: each distinct state as often as
                # it occurs among the S
                n = np.broadcast_to(bad, (M * U,)).reshape(M, U) @ self.mult[owner]
                res.checks[key] = np.maximum(res.checks.get(key, n), n)
        self._springs(solved, delta, M, res)
        for c in self.mech.synthesis_checks():  # decided when the design was sized
            if c.name != "actuator force":
                res.checks[CheckKey(c.name, c.where, c.limit, c.sense, c.unit)] = np.full(
                    M, float(c.value))
        return res

    def _moves(self, solved: Solved, M: int, res: ChunkResult) -> None:
        """How far each body moves from its nominal poses, per sample (its most over its
        states): what the interference bound (``mechc.tolerance.clearance``) reads."""
        if self._nominal is None:
            self._nominal = self.solve(np.zeros((1, len(self.dims))))
        for owner, poses in solved.poses.items():
            part = self.mech.inputs[owner[3:]] if owner.startswith("in:") \
                else self.mech.cells[owner]
            res.moves.update(displacement(part.bodies, poses, self._nominal.poses[owner], M,
                                          self.plan.sets[owner].size, self.radii))

    def nominal_poses(self) -> list[Poses]:
        """Every body's poses in every proof state at nominal (what the interference check
        measures the nominal gaps on)."""
        st = self.states
        values = {n: st.values[k] for k, n in enumerate(st.names)}
        return [evaluate(self.mech, self.lib, self.types, values)]

    def _angles(self, poses: Poses, M: int, S: int, res: ChunkResult) -> None:
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

    def _springs(self, solved: Solved, delta: np.ndarray, M: int, res: ChunkResult) -> None:
        """Each spring's weakest force against what it must move, with its rate and preload
        at the sample's values; each input actuator's demand scaled by the strongest spring
        error of the sample (a bound: every spring the input moves at its heaviest)."""
        mech = self.mech
        worst = np.ones(M)
        for key, part in ([(f"cell:{c}", mech.cells[c]) for c in mech.order]
                          + [(f"input:{k}", p) for k, p in mech.inputs.items()]
                          + [(f"net:{k}", p) for k, p in mech.nets.items()]):
            need = part.data.get("spring_required_N", {})
            owner = key.split(":", 1)[1]
            for i, sp in enumerate(part.springs):
                fr, ep = self._factors(delta, key, i)
                worst = np.maximum(worst, fr * (1.0 + ep))
                if not need.get(sp.id) or owner not in solved.poses:
                    continue
                poses = solved.poses[owner]
                bodies = {b.id: b for b in solved.parts[owner].bodies}
                a = None if sp.a == GROUND else bodies.get(sp.a)
                b = None if sp.b == GROUND else bodies.get(sp.b)
                if (a is None and sp.a != GROUND) or (b is None and sp.b != GROUND) or (
                        a is not None and not poses.known(a.id)) or (
                        b is not None and not poses.known(b.id)):
                    continue
                U = self.plan.sets[owner].size
                ax, ay = position(a, poses, sp.pa)
                bx, by = position(b, poses, sp.pb)
                stretch = np.broadcast_to(np.hypot(bx - ax, by - ay) - sp.rest, (M * U,))
                force = fr[:, None] * (sp.rate * stretch.reshape(M, U) + ep[:, None]
                                       * sp.preload)
                f = np.fmin.reduce(force, axis=1)
                res.checks[CheckKey("spring force margin", sp.id, MIN_SPRING_MARGIN, ">=",
                                    "x")] = f / need[sp.id]
        for name, act in mech.actuators.items():
            demand = max(act.get("required_right_N", 0.0), act.get("required_left_N", 0.0))
            res.checks[CheckKey(ACTUATOR, f"input {name}", 1.0, "<=", "x")] = (
                demand * worst / act["rated_force_N"])
