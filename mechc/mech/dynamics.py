"""Dynamic model: a pymunk scene built from a mechanism's geometry, and input moves run on it.

Units inside pymunk: mm, kg, s (so a force of 1 N is 1000). Every body of the chosen cells
becomes a pymunk body placed at its kinematic pose for the starting input state:

- slider: rotation locked (infinite moment), a groove joint to the ground along its axis, and
  Coulomb guide friction (a ground pivot with no position correction whose force is capped);
- lever: a pivot joint to the ground;
- groove: pymunk GrooveJoint (slot on body a, pin on body b);
- rod: PinJoint of the rod's length (a massless link);
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

import numpy as np
import pymunk
import pymunk.batch as pb

from mechc.library import Library
from mechc.mech.assemble import Mechanism
from mechc.mech.evaluate import settle, signal_of
from mechc.mech.kinematics import Poses
from mechc.mech.model import GROUND, Body

N = 1000.0  # newtons -> pymunk force units (kg mm / s^2)
FAR = 1000.0  # mm: how far behind a contact face its slide-joint anchor sits


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

    def to_json(self) -> dict:
        return {"dt_s": self.dt, "iterations": self.iterations, "move_time_s": self.move_time,
                "settle_time_s": self.settle_time, "violation_limit_mm": self.violation_limit,
                "penetration_limit_mm": self.penetration_limit}


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
    lib: Library
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
    state: dict[str, float] = field(default_factory=dict)  # current input values
    mem_state: dict[str, float] = field(default_factory=dict)  # stateful cells (MEMORY)

    # ---- building ---------------------------------------------------------------------------
    @staticmethod
    def build(mech: Mechanism, lib: Library, types: dict[str, str], settings: DynSettings,
              start: dict[str, float], cells: list[str] | None = None) -> Scene:
        sc = Scene(mech, lib, types, settings, list(cells if cells is not None else mech.order))
        sc.space.iterations = settings.iterations
        sc.space.gravity = (0, 0)
        sc.state = dict(start)
        index = mech.body_index()
        sc._index = index
        parts = [mech.inputs[n] for n in mech.inputs] + [mech.cells[c] for c in sc.cells]
        own = {b.id for p in parts for b in p.bodies}
        # bodies outside the scene that its rods hang on become closed-form driven
        rods = [j for p in mech.nets.values() for j in p.joints if j.b in own]
        for j in rods:
            if j.a not in own:
                sc.boundary.add(j.a)
        poses = sc._kinematic({k: np.array([v]) for k, v in start.items()})
        for p in parts:
            for b in p.bodies:
                sc._add_body(b, poses, kinematic=False)
        for bid in sorted(sc.boundary):
            sc._add_body(index[bid], poses, kinematic=True)
        for cid in sc.cells:
            p = mech.cells[cid]
            for j in p.joints:
                sc._add_joint(j)
            for s in p.springs:
                sc._add_spring(s)
            lib[types[cid]].build_dynamics(sc, p)  # what the geometry alone cannot say
        for j in rods:
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
        if b.kind == "slider":
            pts = [p for poly in b.outline for p in poly]
            ref = (sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts))
        else:
            ref = b.pivot
        if kinematic or b.kind == "rotor":
            body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        elif b.kind == "slider":
            body = pymunk.Body(b.mass, math.inf)
        else:
            r2 = max(sum((p[0] - ref[0]) ** 2 + (p[1] - ref[1]) ** 2 for poly in b.outline
                         for p in poly) / max(1, sum(len(pl) for pl in b.outline)), 1.0)
            body = pymunk.Body(b.mass, b.mass * r2)
        self.ref[b.id] = ref
        self.kind[b.id] = b.kind
        if b.kind == "slider":
            u = float(poses.u[b.id][0])
            self.axis[b.id] = b.axis
            body.position = (ref[0] + u * b.axis[0], ref[1] + u * b.axis[1])
        elif b.kind == "link":
            tx, ty = poses.xy[b.id]
            body.position = (ref[0] + float(np.ravel(tx)[0]), ref[1] + float(np.ravel(ty)[0]))
            body.angle = float(poses.theta[b.id][0])
        elif b.kind == "rotor":  # powered: turns at its set speed whatever loads it
            body.position = ref
            body.angular_velocity = float(b.speed or 0.0)
        else:
            body.position = ref
            body.angle = float(poses.theta[b.id][0])
        self.space.add(body)
        self.bodies[b.id] = body
        if kinematic:
            self.boundary.add(b.id)
            return
        if b.kind in ("link", "rotor"):  # free in the plane / driven by its motor
            return
        i = len(self.bodies) - 1
        if b.kind == "slider":
            L = 2.0 * self.mech.ctx.stroke
            a0 = (ref[0] - L * b.axis[0], ref[1] - L * b.axis[1])
            a1 = (ref[0] + L * b.axis[0], ref[1] + L * b.axis[1])
            self.space.add(pymunk.GrooveJoint(self.space.static_body, body, a0, a1, (0, 0)))
            self.joints.append(_J(f"{b.id}.guide", "groove", -1, a0, i, (0, 0), (a1,)))
            fr = pymunk.PivotJoint(self.space.static_body, body, (0, 0), (0, 0))
            fr.max_bias = 0
            fr.max_force = self.mech.ctx.friction * N
            self.space.add(fr)
        else:
            self.space.add(pymunk.PivotJoint(self.space.static_body, body, ref, (0, 0)))
            self.joints.append(_J(f"{b.id}.pivot", "pivot", -1, ref, i, (0, 0)))

    def _b(self, bid: str):
        return self.space.static_body if bid == GROUND else self.bodies[bid]

    def _idx(self, bid: str) -> int:
        return -1 if bid == GROUND else list(self.bodies).index(bid)

    def _anchor(self, bid: str, p) -> tuple[float, float]:
        return tuple(p) if bid == GROUND else self._local(bid, p)

    def _add_joint(self, j) -> None:
        if j.kind == "groove":
            c = pymunk.GrooveJoint(self._b(j.a), self._b(j.b), self._anchor(j.a, j.p0),
                                   self._anchor(j.a, j.p1), self._anchor(j.b, j.q))
            self.joints.append(_J(j.id, "groove", self._idx(j.a), self._anchor(j.a, j.p0),
                                  self._idx(j.b), self._anchor(j.b, j.q),
                                  (self._anchor(j.a, j.p1),)))
        elif j.kind == "rod":
            c = pymunk.PinJoint(self._b(j.a), self._b(j.b), self._anchor(j.a, j.pa),
                                self._anchor(j.b, j.pb))
            c.distance = j.length
            self.joints.append(_J(j.id, "rod", self._idx(j.a), self._anchor(j.a, j.pa),
                                  self._idx(j.b), self._anchor(j.b, j.pb), (j.length,)))
        elif j.kind == "contact":
            far = (j.pa[0] - FAR * j.normal[0], j.pa[1] - FAR * j.normal[1])
            c = pymunk.SlideJoint(self._b(j.a), self._b(j.b), self._anchor(j.a, far),
                                  self._anchor(j.b, j.pb), FAR, FAR + 100 * self.mech.ctx.stroke)
            self.joints.append(_J(j.id, "contact", self._idx(j.a), self._anchor(j.a, far),
                                  self._idx(j.b), self._anchor(j.b, j.pb), (FAR,)))
        elif j.kind == "pin":
            c = pymunk.PivotJoint(self._b(j.a), self._b(j.b), self._anchor(j.a, j.pa),
                                  self._anchor(j.b, j.pa))
            self.joints.append(_J(j.id, "pivot", self._idx(j.a), self._anchor(j.a, j.pa),
                                  self._idx(j.b), self._anchor(j.b, j.pa)))
        elif j.kind == "touch":
            self._add_touch(j)
            return
        else:
            raise ValueError(f"unknown joint kind {j.kind}")
        self.space.add(c)

    def _add_touch(self, j) -> None:
        """Shapes that collide only with each other (a cam and its roller, a friction roller and
        the faces it drives); their overrun is measured like a contact's."""
        bit = 1 << (len(self.touches) % 31)
        filt = pymunk.ShapeFilter(group=0, categories=bit, mask=bit)
        a, b = self._b(j.a), self._b(j.b)
        mu = 0.0 if j.friction is None else j.friction
        shapes: list[pymunk.Shape] = []
        if j.profile:
            pts = [self._anchor(j.a, p) for p in j.profile]
            shapes += [pymunk.Segment(a, p, q, 0.0) for p, q in zip(pts, pts[1:])]
        else:
            shapes.append(pymunk.Circle(a, j.radius_a, self._anchor(j.a, j.pa)))
        roller = pymunk.Circle(b, j.length, self._anchor(j.b, j.q))
        shapes.append(roller)
        for sh in shapes:
            sh.filter = filt
            sh.friction = mu  # pymunk multiplies the two shapes' values: the roller's is 1
            sh.elasticity = 0.0
        roller.friction = 1.0
        self.space.add(*shapes)
        self.touches.append((j, shapes))

    def _add_spring(self, s) -> None:
        c = pymunk.DampedSpring(self._b(s.a), self._b(s.b), self._anchor(s.a, s.pa),
                                self._anchor(s.b, s.pb), s.rest, s.rate * N, s.damping * N)
        self.space.add(c)

    # ---- measuring --------------------------------------------------------------------------
    def _prepare(self) -> None:
        order = list(self.bodies)
        self._order = order
        self._pos = {bid: i for i, bid in enumerate(order)}
        js = self.joints
        self._ja = np.array([j.ia for j in js], dtype=np.int64)
        self._jb = np.array([j.ib for j in js], dtype=np.int64)
        self._la = np.array([j.la for j in js], dtype=float).reshape(-1, 2)
        self._lb = np.array([j.lb for j in js], dtype=float).reshape(-1, 2)
        kinds = np.array([j.kind for j in js])
        self._is_pivot = kinds == "pivot"
        self._is_rod = kinds == "rod"
        self._is_contact = kinds == "contact"
        self._is_groove = kinds == "groove"
        self._bilateral = ~self._is_contact
        self._la2 = np.array([j.extra[0] if j.kind == "groove" else (0.0, 0.0) for j in js],
                             dtype=float).reshape(-1, 2)
        self._len = np.array([j.extra[0] if j.kind in ("rod", "contact") else 0.0
                              for j in js], dtype=float)
        self._buf = pb.Buffer()
        self._buf.clear()
        pb.get_space_bodies(self.space, pb.BodyFields.BODY_ID, self._buf)
        ids = np.frombuffer(self._buf.int_buf(), dtype=np.int64)
        mine = {self.bodies[k].id: i for i, k in enumerate(order)}
        self._batch_index = np.array([mine.get(int(i), -1) for i in ids])
        self._dynamic = np.array([self.bodies[k].body_type == pymunk.Body.DYNAMIC
                                  for k in order])

    def _state(self):
        """Positions (n, 2) and angles (n,) of the scene's bodies in self._order."""
        self._buf.clear()
        pb.get_space_bodies(self.space, pb.BodyFields.POSITION | pb.BodyFields.ANGLE, self._buf)
        f = np.frombuffer(self._buf.float_buf(), dtype=np.float64).reshape(-1, 3)
        pos = np.zeros((len(self._order), 2))
        ang = np.zeros(len(self._order))
        sel = self._batch_index >= 0
        pos[self._batch_index[sel]] = f[sel, :2]
        ang[self._batch_index[sel]] = f[sel, 2]
        return pos, ang

    def _world(self, idx: np.ndarray, local: np.ndarray, pos, ang) -> np.ndarray:
        out = local.copy()
        m = idx >= 0
        if m.any():
            c, s = np.cos(ang[idx[m]]), np.sin(ang[idx[m]])
            lx, ly = local[m, 0], local[m, 1]
            out[m, 0] = pos[idx[m], 0] + lx * c - ly * s
            out[m, 1] = pos[idx[m], 1] + lx * s + ly * c
        return out

    def violations(self, pos, ang) -> np.ndarray:
        """Per joint: anchor separation (pivot), length error (rod), distance of the pin from
        its slot segment (groove, guide), overrun (contact)."""
        wa = self._world(self._ja, self._la, pos, ang)
        wb = self._world(self._jb, self._lb, pos, ang)
        d = wb - wa
        dist = np.hypot(d[:, 0], d[:, 1])
        v = np.where(self._is_pivot, dist, 0.0)
        v = np.where(self._is_rod, np.abs(dist - self._len), v)
        v = np.where(self._is_contact, np.maximum(0.0, self._len - dist), v)
        if self._is_groove.any():
            a1 = self._world(self._ja, self._la2, pos, ang)
            seg = a1 - wa
            ss = np.maximum((seg * seg).sum(axis=1), 1e-12)
            t = np.clip((d * seg).sum(axis=1) / ss, 0.0, 1.0)
            off = wb - (wa + t[:, None] * seg)
            v = np.where(self._is_groove, np.hypot(off[:, 0], off[:, 1]), v)
        return v

    def touch_overrun(self) -> float:
        """Deepest interpenetration (mm) of any shape contact now."""
        worst = 0.0
        for _, shapes in self.touches:
            roller = shapes[-1]
            for sh in shapes[:-1]:
                if not sh.bb.intersects(roller.bb):
                    continue
                try:
                    points = sh.shapes_collide(roller).points
                except AssertionError:  # pymunk 7.3 asserts on an empty contact set
                    continue
                for p in points:
                    worst = max(worst, -p.distance)
        return worst

    def pose_of(self, bid: str, pos, ang) -> Poses:
        """The scene's pose of one body in the closed form's terms (for signals)."""
        i = self._pos[bid]
        rx, ry = self.ref[bid]
        if self.kind[bid] == "slider":
            return Poses(u={bid: np.array([self.body_u(bid, pos)])})
        p = Poses(theta={bid: np.array([ang[i]])})
        if self.kind[bid] == "link":
            p.xy[bid] = (np.array([pos[i, 0] - rx]), np.array([pos[i, 1] - ry]))
        return p

    def body_u(self, bid: str, pos) -> float:
        i = self._pos[bid]
        rx, ry = self.ref[bid]
        ax, ay = self.axis[bid]
        return (pos[i, 0] - rx) * ax + (pos[i, 1] - ry) * ay

    def outputs_now(self, pos, ang) -> dict[str, float]:
        out = {}
        for name, (owner, pin) in self.mech.outputs.items():
            if not owner.startswith("in:") and owner not in self.cells:
                continue
            t = self.mech.owner_part(owner).terminals[pin]
            out[name] = float(signal_of(t, self._index[t.body],
                                           self.pose_of(t.body, pos, ang))[0])
        return out

    # ---- running ----------------------------------------------------------------------------
    def move(self, name: str, target: float) -> MoveResult:
        """Move input ``name`` to ``target`` (0 or 1) and hold until settled (or time out)."""
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
        # closed-form trajectory of the boundary bodies and the outputs along the move
        samples = np.linspace(0.0, 1.0, 41)
        vals = {k: np.full(len(samples), v) for k, v in self.state.items()}
        vals[name] = start + (target - start) * samples
        ref = self._kinematic(vals)
        from mechc.mech.evaluate import output_signals

        ref_out = output_signals(self.mech, ref)
        ts, outs, refs = [], {k: [] for k in self.mech.outputs}, {k: [] for k in
                                                                 self.mech.outputs}
        max_v, worst, lag, max_pen = 0.0, "", 0.0, 0.0
        last_dev = 0.0
        quiet_since = None
        total = n_move + n_hold
        final_seen: list[dict] = []
        for step in range(1, total + 1):
            t = step * st.dt
            tau = min(1.0, t / st.move_time)
            frac = float(min_jerk(tau))
            x = (target - start) * frac * S
            want = (s0[0] + x * axis[0], s0[1] + x * axis[1])
            servo.velocity = ((want[0] - servo.position[0]) / st.dt,
                              (want[1] - servo.position[1]) / st.dt)
            for bid in self.boundary:  # closed-form driven bodies
                kb = self.bodies[bid]
                k = frac * (len(samples) - 1)
                i0 = min(int(k), len(samples) - 2)
                w = k - i0
                if self.kind[bid] == "slider":
                    u = ref.u[bid][i0] * (1 - w) + ref.u[bid][i0 + 1] * w
                    rx, ry = self.ref[bid]
                    ax, ay = self.axis[bid]
                    goal = (rx + u * ax, ry + u * ay)
                    kb.velocity = ((goal[0] - kb.position[0]) / st.dt,
                                   (goal[1] - kb.position[1]) / st.dt)
                else:
                    th = ref.theta[bid][i0] * (1 - w) + ref.theta[bid][i0 + 1] * w
                    kb.angular_velocity = (th - kb.angle) / st.dt
                    if self.kind[bid] == "link":
                        rx, ry = self.ref[bid]
                        gx = rx + ref.xy[bid][0][i0] * (1 - w) + ref.xy[bid][0][i0 + 1] * w
                        gy = ry + ref.xy[bid][1][i0] * (1 - w) + ref.xy[bid][1][i0 + 1] * w
                        kb.velocity = ((gx - kb.position[0]) / st.dt,
                                       (gy - kb.position[1]) / st.dt)
            self.space.step(st.dt)
            pos, ang = self._state()
            v = self.violations(pos, ang)
            if len(v):
                vb = np.where(self._bilateral, v, 0.0)
                i = int(np.argmax(vb))
                if vb[i] > max_v:
                    max_v, worst = float(vb[i]), self.joints[i].id
                max_pen = max(max_pen, float(np.max(np.where(self._is_contact, v, 0.0))))
            if self.touches:
                max_pen = max(max_pen, self.touch_overrun())
            bp = body.position
            lag = max(lag, math.hypot(bp[0] - servo.position[0], bp[1] - servo.position[1]))
            if step % st.record_every == 0 or step == total:
                o = self.outputs_now(pos, ang)
                ts.append(t)
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
            if not np.isfinite(max_v):
                break
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
                                     body.position[1] - servo.position[1]))

    def _max_speed(self) -> float:
        """Largest speed (mm/s, or mm/s at 30 mm radius for levers) of a free body."""
        best = 0.0
        for bid in self._order:
            b = self.bodies[bid]
            if b.body_type != pymunk.Body.DYNAMIC:
                continue
            sp = math.hypot(*b.velocity) + abs(b.angular_velocity) * 30.0
            best = max(best, sp)
        return best
