"""Dynamic model: a pymunk scene built from a mechanism's geometry, and input moves run on it.

Units inside pymunk: mm, kg, s (so a force of 1 N is 1000). Every body of the chosen cells
becomes a pymunk body placed at its kinematic pose for the starting input state; each part
kind builds its own (``mechc.parts``):

- slider: rotation locked (infinite moment), a groove joint to the ground along its axis, and
  Coulomb guide friction (a ground pivot with no position correction whose force is capped);
- lever: a pivot joint to the ground;
- groove: pymunk GrooveJoint (slot on body a, pin on body b);
- rod joint (inside cells): PinJoint of the rod's length (a massless link);
- net rod: a ``pushrod`` body with the mass of its plate, pivot joints to the driver's fan-out
  bar and the load's input slider;
- contact: one-sided, as a SlideJoint between the face on b and a point far behind the face on a
  (distance >= that far offset means the faces have not passed each other);
- spring: DampedSpring.

Inputs are moved by a servo: a kinematic body following a minimum-jerk profile, joined to the
input slider by a pivot whose force is capped at the actuator's rating (so an overloaded input
lags or stalls, it is never teleported). Bodies outside the chosen cells that drive them are
kinematic bodies following the closed-form solution (a pruned scene).

pymunk stretches joints silently when overdriven or stepped too coarsely, so after every step
the distance between the two anchors of every joint is measured; ``max_violation`` is reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import pymunk
import pymunk.batch as pb

from mechc.ir.mechanism import GROUND, Body, Mechanism
from mechc.parts import body_kind, joint_kind
from mechc.parts.base import N
from mechc.parts.contact import FAR
from mechc.parts.pushrod import net_rods
from mechc.physics.closed_form import Poses
from mechc.physics.evaluate import CellModels, output_signals, settle

# FAR and N are part of this module's interface (cells' build_dynamics use them)
__all__ = ["FAR", "MOVE_SAMPLES", "N", "DynSettings", "MoveResult", "FrameSink", "Scene",
           "min_jerk"]

MOVE_SAMPLES = 41  # closed-form samples along an input move (boundary drive and reference)


@dataclass
class DynSettings:
    dt: float = 2.5e-4  # s
    iterations: int = 60
    move_time: float = 0.08  # s, input motion (minimum-jerk)
    settle_time: float = 0.15  # s, longest hold after a move
    violation_limit: float = 0.1  # mm: a larger stretch of a pivot, rod or guide fails the
    #                               proof ("solver error"); 0.5 % of the default stroke
    penetration_limit: float = 0.5  # mm: a one-sided contact or stop overrun by more fails it
    record_every: int = 4  # steps between samples of output positions
    # why settle_time is what it is (mechc.proofs.hold): "default", "static path" (with the
    # path), "memories" or "--hold"
    hold_from: str = "default"
    static_path: dict | None = None

    def to_json(self) -> dict:
        return {"dt_s": self.dt, "iterations": self.iterations, "move_time_s": self.move_time,
                "settle_time_s": self.settle_time, "violation_limit_mm": self.violation_limit,
                "penetration_limit_mm": self.penetration_limit, "hold_from": self.hold_from,
                **({"static_path": self.static_path} if self.static_path else {})}


def min_jerk(tau: np.ndarray | float):
    tau = np.clip(tau, 0.0, 1.0)
    return tau ** 3 * (10 - 15 * tau + 6 * tau * tau)


@dataclass
class MoveResult:
    t: np.ndarray  # sample times (s), 0 = move start
    outputs: dict[str, np.ndarray]  # output signal (0..1) at each sample
    reference: dict[str, np.ndarray]  # closed-form output at each sample (same input position)
    final: dict[str, float]
    max_violation: float  # mm, bilateral joints (pivots, rods, guides, slots)
    worst_joint: str
    max_penetration: float  # mm, one-sided contacts and stops
    settle_time: float  # s after the move ended (inf if it never settled)
    servo_lag: float  # mm, largest distance between servo and input slider
    steps: int
    servo_lag_end: float = 0.0  # mm, distance between servo and input slider at the end
    watched: dict[str, np.ndarray] = field(default_factory=dict)  # Scene.watch sliders' u (mm)


class FrameSink(Protocol):
    """What receives every body's pose while a move runs (a trace, ``mechc.proofs.trace``):
    ``sample`` is called before the first step, every ``every`` seconds of simulated time and
    after the last step; it reads the poses with :meth:`Scene.frames`."""

    every: float  # s between samples

    def sample(self, scene: Scene, t: float, frac: float) -> None: ...


@dataclass
class _J:
    """A joint's anchors for violation measurement (body index -1 = ground, world coords)."""

    id: str
    kind: str  # pivot | groove | rod | contact
    ia: int
    la: tuple
    ib: int
    lb: tuple
    extra: tuple = ()


@dataclass
class Scene:
    mech: Mechanism
    lib: CellModels
    types: dict[str, str]
    settings: DynSettings
    cells: list[str]
    space: pymunk.Space = field(default_factory=pymunk.Space)
    bodies: dict[str, pymunk.Body] = field(default_factory=dict)
    ref: dict[str, tuple[float, float]] = field(default_factory=dict)  # design position
    kind: dict[str, str] = field(default_factory=dict)
    axis: dict[str, tuple[float, float]] = field(default_factory=dict)
    boundary: set[str] = field(default_factory=set)  # bodies driven by the closed form
    servos: dict[str, tuple[pymunk.Body, str]] = field(default_factory=dict)
    joints: list[_J] = field(default_factory=list)
    touches: list = field(default_factory=list)  # (joint, shapes) of shape contacts
    profiles: list = field(default_factory=list)  # per touch: (start points, segment vectors)
    state: dict[str, float] = field(default_factory=dict)  # current input values
    mem_state: dict[str, float] = field(default_factory=dict)  # stateful cells (MEMORY)
    watch: list[str] = field(default_factory=list)  # slider bodies whose u each move records
    sink: FrameSink | None = None  # receives every body's pose while a move runs (a trace)

    # ---- building ---------------------------------------------------------------------------
    @staticmethod
    def build(mech: Mechanism, lib: CellModels, types: dict[str, str], settings: DynSettings,
              start: dict[str, float], cells: list[str] | None = None,
              poses: Poses | None = None) -> Scene:
        """``poses``: the closed form of ``start`` if the caller has it (its first sample is
        used), so a scene per input change does not solve the whole mechanism again."""
        sc = Scene(mech, lib, types, settings, list(cells if cells is not None else mech.order))
        sc.space.iterations = settings.iterations
        sc.space.gravity = (0, 0)
        sc.state = dict(start)
        index = mech.body_index()
        sc._index = index
        parts = [mech.inputs[n] for n in mech.inputs] + [mech.cells[c] for c in sc.cells]
        own = {b.id for p in parts for b in p.bodies}
        # the rods to the scene's loads, and bodies outside it that they hang on (closed-form
        # driven)
        rods = [r for p in mech.nets.values() for r in net_rods(p) if r.load in own]
        for r in rods:
            if r.driver not in own:
                sc.boundary.add(r.driver)
        if poses is None:
            poses = sc._kinematic({k: np.array([v]) for k, v in start.items()})
        else:
            sc._last_state = {k: float(v[0]) for k, v in poses.state.items()}
        for p in parts:
            for b in p.bodies:
                sc._add_body(b, poses, kinematic=False)
        for r in rods:  # rod bodies: plate with mass, pinned at both ends
            if r.body is not None:
                sc._add_body(index[r.body], poses, kinematic=False)
        for bid in sorted(sc.boundary):
            sc._add_body(index[bid], poses, kinematic=True)
        for cid in sc.cells:
            p = mech.cells[cid]
            for j in p.joints:
                sc._add_joint(j)
            for s in p.springs:
                sc._add_spring(s)
            lib[types[cid]].build_dynamics(sc, p)  # what the geometry alone cannot say
        for r in rods:
            for j in r.joints:
                sc._add_joint(j)
        for name, part in mech.inputs.items():
            t = part.terminals[name]
            body = sc.bodies[t.body]
            servo = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
            servo.position = body.position
            pivot = pymunk.PivotJoint(servo, body, (0, 0), (0, 0))
            pivot.max_force = mech.actuators[name]["rated_force_N"] * N
            sc.space.add(servo, pivot)
            sc.servos[name] = (servo, t.body)
        return sc

    def _kinematic(self, values: dict[str, np.ndarray]) -> Poses:
        """The closed form from the stateful cells' current states (settled per sample)."""
        poses, state, _ = settle(self.mech, self.lib, self.types, values, self.mem_state)
        self._last_state = {k: float(v[-1]) for k, v in state.items()}
        return poses

    def _local(self, bid: str, p) -> tuple[float, float]:
        rx, ry = self.ref[bid]
        return (p[0] - rx, p[1] - ry)

    def _add_body(self, b: Body, poses: Poses, kinematic: bool) -> None:
        kind = body_kind(b.kind)
        ref = kind.scene_ref(b)
        if kinematic:
            body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        else:
            body = kind.pymunk_body(b, ref)
        self.ref[b.id] = ref
        self.kind[b.id] = b.kind
        kind.place(self, b, body, ref, poses)
        self.space.add(body)
        self.bodies[b.id] = body
        if kinematic:
            self.boundary.add(b.id)
            return
        kind.hold(self, b, body, ref)

    # what a part kind asks of the scene while it builds its bodies and joints
    def body_of(self, bid: str) -> pymunk.Body:
        """The pymunk body of ``bid`` (the space's static body for the ground)."""
        return self.space.static_body if bid == GROUND else self.bodies[bid]

    def order_of(self, bid: str) -> int:
        """Index of ``bid`` among the scene's bodies (-1: the ground)."""
        return -1 if bid == GROUND else list(self.bodies).index(bid)

    def anchor(self, bid: str, p) -> tuple[float, float]:
        """World point ``p`` in the frame of ``bid``'s pymunk body."""
        return tuple(p) if bid == GROUND else self._local(bid, p)

    def measure(self, jid: str, kind: str, ia: int, la: tuple, ib: int, lb: tuple,
                extra: tuple = ()) -> None:
        """Measure a constraint's stretch after every step (``kind``: pivot, groove, rod or
        contact; anchors in their bodies' frames, -1 the ground)."""
        self.joints.append(_J(jid, kind, ia, la, ib, lb, extra))

    def _add_joint(self, j) -> None:
        joint_kind(j.kind).add_to_scene(self, j)

    def _add_spring(self, s) -> None:
        c = pymunk.DampedSpring(self.body_of(s.a), self.body_of(s.b), self.anchor(s.a, s.pa),
                                self.anchor(s.b, s.pb), s.rest, s.rate * N, s.damping * N)
        self.space.add(c)

    # ---- measuring --------------------------------------------------------------------------
    def _prepare(self) -> None:
        """Index arrays for measuring every joint in a few numpy passes per step: the per-step
        Python work must stay small against pymunk's own step, or it, not the solver, sets
        what a scene costs (and a pruned scene saves nothing)."""
        order = list(self.bodies)
        n = len(order)
        self._order = order
        self._pos = {bid: i for i, bid in enumerate(order)}
        js = self.joints
        m = len(js)
        ja = np.array([j.ia for j in js], dtype=np.int64)
        jb = np.array([j.ib for j in js], dtype=np.int64)
        kinds = np.array([j.kind for j in js], dtype=object)
        self._is_pivot = kinds == "pivot"
        self._is_rod = kinds == "rod"
        self._is_contact = kinds == "contact"
        self._is_groove = kinds == "groove"
        self._bilateral = ~self._is_contact
        self._contact_rows = np.flatnonzero(self._is_contact)
        self._groove_rows = np.flatnonzero(self._is_groove)
        self._len = np.array([j.extra[0] if j.kind in ("rod", "contact") else 0.0
                              for j in js], dtype=float)
        la = np.array([j.la for j in js], dtype=float).reshape(-1, 2)
        lb = np.array([j.lb for j in js], dtype=float).reshape(-1, 2)
        la2 = np.array([js[i].extra[0] for i in self._groove_rows], dtype=float).reshape(-1, 2)
        # every anchor (a, b, groove ends) in one array; ground is the extra row n
        idx = np.concatenate([ja, jb, ja[self._groove_rows]])
        self._m = m
        self._widx = np.where(idx < 0, n, idx)
        loc = np.concatenate([la, lb, la2]).reshape(-1, 2)
        self._wloc_c = loc[:, 0] + 1j * loc[:, 1]
        self._buf = pb.Buffer()
        pb.get_space_bodies(self.space, pb.BodyFields.BODY_ID, self._buf)
        ids = np.frombuffer(self._buf.int_buf(), dtype=np.int64)
        mine = {self.bodies[k].id: i for i, k in enumerate(order)}
        where = np.array([mine.get(int(i), -1) for i in ids], dtype=np.int64)
        self._src = np.flatnonzero(where >= 0)
        self._dst = where[self._src]
        self._dynamic = np.array([self.bodies[k].body_type == pymunk.Body.DYNAMIC
                                  for k in order], dtype=bool)
        self._spin_free = np.array([_spin_is_invisible(self, k) for k in order], dtype=bool)
        self._P = np.zeros((n + 1, 2))  # positions, ground row last
        self._A = np.zeros(n + 1)  # angles
        self._V = np.zeros((n, 3))  # vx, vy, angular velocity
        self._fields = (pb.BodyFields.POSITION | pb.BodyFields.ANGLE | pb.BodyFields.VELOCITY
                        | pb.BodyFields.ANGULAR_VELOCITY)

    def _read(self) -> None:
        """One batch read of every body's position, angle and velocities."""
        self._buf.clear()
        pb.get_space_bodies(self.space, self._fields, self._buf)
        f = np.frombuffer(self._buf.float_buf(), dtype=np.float64).reshape(-1, 6)[self._src]
        self._P[self._dst] = f[:, :2]
        self._A[self._dst] = f[:, 2]
        self._V[self._dst] = f[:, 3:]

    def _state(self):
        """Positions (n, 2) and angles (n,) of the scene's bodies in self._order."""
        if not hasattr(self, "_order"):
            self._prepare()
        self._read()
        n = len(self._order)
        return self._P[:n].copy(), self._A[:n].copy()

    def frames(self) -> tuple[list[str], np.ndarray, np.ndarray]:
        """Every body's id, and now the world position (n, 2) of its ``ref`` point and its
        angle (n,) from the design pose: a point p of the body (design pose) stands at
        R(angle)·(p − ref) + position."""
        pos, ang = self._state()
        return self._order, pos, ang

    def violations(self, pos, ang) -> np.ndarray:
        """Per joint: anchor separation (pivot), length error (rod), distance of the pin from
        its slot segment (groove, guide), overrun (contact); a non-finite pose is infinite."""
        if not hasattr(self, "_order"):
            self._prepare()
        n = len(self._order)
        self._P[:n] = pos
        self._A[:n] = ang
        return self._violations()

    def _violations(self) -> np.ndarray:
        idx, m = self._widx, self._m
        rot = np.exp(1j * self._A)  # anchors as complex numbers: one rotation per body
        w = self._P[:, 0][idx] + 1j * self._P[:, 1][idx] + self._wloc_c * rot[idx]
        d = w[m:2 * m] - w[:m]
        dist = np.abs(d)
        v = np.abs(dist - self._len)  # pivot (length 0) and rod
        cr = self._contact_rows
        v[cr] = np.maximum(0.0, self._len[cr] - dist[cr])
        g = self._groove_rows
        if len(g):
            wa = w[g]
            seg = w[2 * m:] - wa
            ss = np.maximum(np.abs(seg) ** 2, 1e-12)
            t = np.clip((d[g] * seg.conj()).real / ss, 0.0, 1.0)
            v[g] = np.abs(w[m + g] - wa - t * seg)
        v[np.isnan(v)] = np.inf
        return v

    def touch_overrun(self) -> float:
        """Deepest interpenetration (mm) of any shape contact now, measured geometrically: the
        roller's radius less its centre's distance to the profile (a polyline) or to the
        other circle. (pymunk's own contact query returns nothing for most touching pairs.)"""
        worst = 0.0
        for (_, shapes), profile in zip(self.touches, self.profiles):
            roller = shapes[-1]
            c = roller.body.local_to_world(roller.offset)
            first = shapes[0]
            if profile is None:  # two circles
                o = first.body.local_to_world(first.offset)
                d = math.hypot(c[0] - o[0], c[1] - o[1])
                worst = max(worst, first.radius + roller.radius - d)
                continue
            d = _polyline_distance(profile, first.body, c)
            worst = max(worst, roller.radius - d)
        return worst

    def pose_of(self, bid: str, pos, ang) -> Poses:
        """The scene's pose of one body in the closed form's terms (for signals)."""
        return body_kind(self.kind[bid]).scene_pose(self, bid, self._pos[bid], pos, ang)

    def body_u(self, bid: str, pos) -> float:
        i = self._pos[bid]
        rx, ry = self.ref[bid]
        ax, ay = self.axis[bid]
        return (pos[i, 0] - rx) * ax + (pos[i, 1] - ry) * ay

    def outputs_now(self, pos, ang) -> dict[str, float]:
        """Output signals (0..1) of the outputs this scene holds, for a pose of the scene."""
        if not hasattr(self, "_out_names"):
            self._prepare_outputs()
        i = self._out_body
        if not len(i):
            return {}
        pos, ang = np.asarray(pos), np.asarray(ang)
        c, s = np.cos(ang[i]), np.sin(ang[i])
        qx, qy = self._out_q[:, 0], self._out_q[:, 1]
        x = pos[i, 0] + qx * c - qy * s - self._out_off[:, 0]
        y = pos[i, 1] + qx * s + qy * c - self._out_off[:, 1]
        # sliders: only the travel along the axis counts (as ``pose_of`` reads them)
        sl = self._out_slider
        if sl.any():
            ax, ay = self._out_axis[:, 0], self._out_axis[:, 1]
            u = (pos[i, 0] - self._out_ref[:, 0]) * ax + (pos[i, 1] - self._out_ref[:, 1]) * ay
            x = np.where(sl, self._out_p[:, 0] + u * ax - self._out_off[:, 0], x)
            y = np.where(sl, self._out_p[:, 1] + u * ay - self._out_off[:, 1], y)
        sig = x * self._out_g[:, 0] + y * self._out_g[:, 1]
        return dict(zip(self._out_names, sig.tolist()))

    def _prepare_outputs(self) -> None:
        """Per output: its body, design point and off->on direction, so every output signal
        comes from one vectorised pass (``signal_of`` on the scene's pose, for all at once)."""
        if not hasattr(self, "_pos"):
            self._pos = {bid: i for i, bid in enumerate(self.bodies)}
        names, body, q, p, off, g, slider, axis, ref = [], [], [], [], [], [], [], [], []
        for name, (owner, pin) in self.mech.outputs.items():
            if not owner.startswith("in:") and owner not in self.cells:
                continue
            t = self.mech.owner_part(owner).terminals[pin]
            rx, ry = self.ref[t.body]
            dx, dy = t.on[0] - t.off[0], t.on[1] - t.off[1]
            nn = dx * dx + dy * dy
            names.append(name)
            body.append(self._pos[t.body])
            q.append((t.design_point[0] - rx, t.design_point[1] - ry))
            p.append(t.design_point)
            off.append(t.off)
            g.append((dx / nn, dy / nn))
            slider.append(body_kind(self.kind[t.body]).translates)
            axis.append(self.axis.get(t.body, (0.0, 0.0)))
            ref.append((rx, ry))
        self._out_names = names
        self._out_body = np.array(body, dtype=np.int64)
        self._out_q, self._out_p, self._out_off, self._out_g, self._out_axis, self._out_ref = (
            np.array(v, dtype=float).reshape(-1, 2) for v in (q, p, off, g, axis, ref))
        self._out_slider = np.array(slider, dtype=bool)

    # ---- running ----------------------------------------------------------------------------
    def move(self, name: str, target: float, reference: Poses | None = None) -> MoveResult:
        """Move input ``name`` to ``target`` (0 or 1) and hold until settled (or time out).
        ``reference``: the closed form along the move if the caller has it (MOVE_SAMPLES
        samples of the moving input from its current value to ``target``, the others held)."""
        st = self.settings
        if not hasattr(self, "_order"):
            self._prepare()
        S = self.mech.ctx.stroke
        start = self.state[name]
        servo, sbody = self.servos[name]
        body = self.bodies[sbody]
        axis = self.axis[sbody]
        s0 = servo.position
        n_move = max(1, int(round(st.move_time / st.dt)))
        n_hold = max(1, int(round(st.settle_time / st.dt)))
        ib, nb = self._pos[sbody], len(self._order)
        # closed-form trajectory of the boundary bodies and the outputs along the move
        samples = np.linspace(0.0, 1.0, MOVE_SAMPLES)
        if reference is None:
            vals = {k: np.full(len(samples), v) for k, v in self.state.items()}
            vals[name] = start + (target - start) * samples
            ref = self._kinematic(vals)
        else:
            ref = reference
            self._last_state = {k: float(v[-1]) for k, v in ref.state.items()}
        ref_out = output_signals(self.mech, ref)
        watched: dict[str, list[float]] = {}
        ts, outs, refs = [], {k: [] for k in self.mech.outputs}, {k: [] for k in
                                                                 self.mech.outputs}
        max_v, worst, lag, max_pen = 0.0, "", 0.0, 0.0
        last_dev = 0.0
        quiet_since = None
        total = n_move + n_hold
        final_seen: list[dict] = []
        followers = [(bid, self.bodies[bid], body_kind(self.kind[bid])) for bid in self.boundary]
        sink = self.sink
        every = max(1, int(round(sink.every / st.dt))) if sink is not None else 0
        sampled = 0  # the last step sampled
        if sink is not None:
            sink.sample(self, 0.0, 0.0)
        frac = 0.0
        for step in range(1, total + 1):
            t = step * st.dt
            tau = min(1.0, t / st.move_time)
            frac = float(min_jerk(tau))
            x = (target - start) * frac * S
            want = (s0[0] + x * axis[0], s0[1] + x * axis[1])
            servo.velocity = ((want[0] - servo.position[0]) / st.dt,
                              (want[1] - servo.position[1]) / st.dt)
            for bid, kb, kind in followers:  # closed-form driven bodies
                k = frac * (len(samples) - 1)
                i0 = min(int(k), len(samples) - 2)
                kind.follow(self, bid, kb, ref, i0, k - i0, st.dt)
            self.space.step(st.dt)
            self._read()
            v = self._violations()
            if len(v):
                vb = np.where(self._bilateral, v, 0.0)
                i = int(np.argmax(vb))
                if vb[i] > max_v:
                    max_v, worst = float(vb[i]), self.joints[i].id
                if len(self._contact_rows):
                    max_pen = max(max_pen, float(np.max(v[self._contact_rows])))
            if self.touches:
                max_pen = max(max_pen, self.touch_overrun())
            bp = self._P[ib]
            lag = max(lag, math.hypot(bp[0] - want[0], bp[1] - want[1]))
            if step % st.record_every == 0 or step == total:
                o = self.outputs_now(self._P[:nb], self._A[:nb])
                ts.append(t)
                for bid in self.watch:
                    watched.setdefault(bid, []).append(self.body_u(bid, self._P[:nb]))
                k = frac * (len(samples) - 1)
                for nm in o:
                    outs[nm].append(o[nm])
                    refs[nm].append(float(np.interp(k, np.arange(len(samples)),
                                                    ref_out[nm])))
                if step > n_move:
                    final_seen.append(o)
                    dev = max((abs(o[nm] - ref_out[nm][-1]) for nm in o), default=0.0)
                    if dev > 0.005:
                        last_dev = t
                    # settled: every free body nearly still for 10 ms -> stop holding
                    speed = self._max_speed()
                    if speed < 0.5 and dev <= 0.005:
                        quiet_since = t if quiet_since is None else quiet_since
                        if t - quiet_since >= 0.01:
                            break
                    else:
                        quiet_since = None
            if sink is not None and step % every == 0:
                sink.sample(self, t, frac)
                sampled = step
            if not np.isfinite(max_v):
                break
        if sink is not None and sampled != step:  # the pose it ends in (also after a break)
            sink.sample(self, step * st.dt, frac)
        self.state[name] = target
        self.mem_state = dict(self._last_state)
        final = final_seen[-1] if final_seen else self.outputs_now(*self._state())
        settle = max(0.0, last_dev - st.move_time)
        if quiet_since is None and last_dev >= total * st.dt - st.record_every * st.dt * 1.5:
            settle = math.inf
        return MoveResult(np.array(ts), {k: np.array(v) for k, v in outs.items() if v},
                          {k: np.array(v) for k, v in refs.items() if v}, final, max_v, worst,
                          max_pen, settle, lag, step,
                          math.hypot(body.position[0] - servo.position[0],
                                     body.position[1] - servo.position[1]),
                          {k: np.array(v) for k, v in watched.items()})

    def _max_speed(self) -> float:
        """Largest speed (mm/s, or mm/s at 30 mm radius for levers) of a free body, as of the
        last read of the scene. A roller's spin about its own centre is not motion (an idler
        driven by a powered roller spins for ever at rest)."""
        V = self._V[self._dynamic]
        if not len(V):
            return 0.0
        spin = np.where(self._spin_free[self._dynamic], 0.0, np.abs(V[:, 2]))
        return float(np.max(np.hypot(V[:, 0], V[:, 1]) + spin * 30.0))


def _spin_is_invisible(scene: Scene, bid: str) -> bool:
    """Whether turning body ``bid`` about its centre changes nothing another body or an output
    can see: a dynamic body whose every constraint anchor is at its centre and whose every
    shape is a circle centred there, and which carries no output terminal."""
    b = scene.bodies[bid]
    if b.body_type != pymunk.Body.DYNAMIC or not b.shapes:
        return False
    for owner, pin in scene.mech.outputs.values():
        if owner.startswith("in:") or owner in scene.cells:
            if scene.mech.owner_part(owner).terminals[pin].body == bid:
                return False
    for sh in b.shapes:
        if not isinstance(sh, pymunk.Circle) or abs(sh.offset) > 1e-9:
            return False
    for c in b.constraints:
        anchor = getattr(c, "anchor_a" if c.a is b else "anchor_b", None)
        if anchor is None or abs(anchor) > 1e-9:
            return False
    return True


def _polyline_distance(profile, body: pymunk.Body, c) -> float:
    """Distance from world point ``c`` to a touch's profile segments (stored in ``body``'s
    frame as start points and segment vectors), vectorised over the segments."""
    a, ab = profile
    ca, sa = math.cos(body.angle), math.sin(body.angle)
    # the point in the profile body's frame (segments are stored in that frame)
    dx, dy = c[0] - body.position.x, c[1] - body.position.y
    px, py = ca * dx + sa * dy, -sa * dx + ca * dy
    rx, ry = px - a[:, 0], py - a[:, 1]
    ll = ab[:, 0] ** 2 + ab[:, 1] ** 2
    t = np.clip((rx * ab[:, 0] + ry * ab[:, 1]) / np.where(ll > 0, ll, 1.0), 0.0, 1.0)
    ex, ey = rx - t * ab[:, 0], ry - t * ab[:, 1]
    return float(np.sqrt(np.min(ex * ex + ey * ey)))
