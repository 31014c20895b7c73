"""Closed-form kinematics of slider-and-lever mechanisms, read from their geometry alone.

Quasi-static: every spring wins against friction, so a slider held only by one-sided contacts
and stops sits against its nearest limit in the direction its spring pulls — the largest lower
bound or the smallest upper bound (OR bars take the max of their inputs, AND bars the min).
Bilateral joints are solved in closed form: a pin in a slot gives the lever angle from
``a cos θ + b sin θ = c`` (branch fixed at the design pose), a slot on a slider follows a lever
pin linearly, a rod between two sliders is a quadratic. Everything is numpy-vectorised over
many states at once. Where a closed form has no real solution (the parts cannot assemble, or a
slider is jammed between contradictory limits) the state is marked bad, never guessed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechc.ir.mechanism import GROUND, Body, Joint, Part, Point


class KinematicsError(Exception):
    """The mechanism is not determinate from its geometry (a modelling error, not a state)."""


@dataclass
class Poses:
    """Body displacements from the design pose for N states."""

    u: dict[str, np.ndarray] = field(default_factory=dict)  # sliders (mm along axis)
    theta: dict[str, np.ndarray] = field(default_factory=dict)  # levers, links (rad, ccw)
    xy: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)  # links: ref
    #                                                 point's displacement (mm)
    bad: dict[str, np.ndarray] = field(default_factory=dict)  # states where a body is unsolved
    singular_margin: dict[str, np.ndarray] = field(default_factory=dict)  # joint -> degrees
    transmission: dict[str, np.ndarray] = field(default_factory=dict)  # joint -> degrees
    state: dict[str, np.ndarray] = field(default_factory=dict)  # stateful cell -> new state
    # world points a closed form placed while solving, (body, x0, y0) -> (x, y): the closure
    # check reuses them instead of re-deriving them through trig (private to ``solve``)
    placed: dict[tuple[str, float, float], tuple[np.ndarray, np.ndarray]] = field(
        default_factory=dict, repr=False, compare=False)

    def known(self, body: str) -> bool:
        return body == GROUND or body in self.u or body in self.theta

    def mark(self, body: str, bad: np.ndarray) -> None:
        if body in self.bad:
            self.bad[body] = self.bad[body] | bad
        else:
            self.bad[body] = bad.copy()

    def update(self, other: Poses) -> None:
        for k in ("u", "theta", "xy", "bad", "singular_margin", "transmission", "state"):
            getattr(self, k).update(getattr(other, k))


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def cos_sin(th) -> tuple[np.ndarray, np.ndarray]:
    """cos and sin of ``th`` from one tangent of the half angle: numpy vectorises float64 tan
    but sends cos and sin to scalar libm (~5x slower each); the results agree with libm to
    one ulp (|error| <= 2.3e-16, checked in tests/perf/test_perf_kinematics.py)."""
    t = np.tan(np.multiply(th, 0.5))
    t2 = t * t
    q = 1.0 / (1.0 + t2)
    return (1.0 - t2) * q, (t + t) * q


def displacement(body: Body | None, poses: Poses, p: Point) -> tuple[np.ndarray, np.ndarray]:
    """Displacement (dx, dy) of the design point ``p`` of ``body`` in every state."""
    if body is None:
        return np.zeros(1), np.zeros(1)
    if body.kind == "slider":
        u = poses.u[body.id]
        return u * body.axis[0], u * body.axis[1]
    th = poses.theta[body.id]
    rx, ry = p[0] - body.pivot[0], p[1] - body.pivot[1]
    c, s = cos_sin(th)
    dx, dy = rx * c - ry * s - rx, rx * s + ry * c - ry
    if body.kind == "link":
        tx, ty = poses.xy[body.id]
        return dx + tx, dy + ty
    return dx, dy


def position(body: Body | None, poses: Poses, p: Point) -> tuple[np.ndarray, np.ndarray]:
    if body is not None and body.kind == "lever":  # pivot + R(θ)·arm: fewer array passes
        c, s = cos_sin(poses.theta[body.id])
        rx, ry = p[0] - body.pivot[0], p[1] - body.pivot[1]
        x, y = rx * c, rx * s
        x -= ry * s
        y += ry * c
        x += body.pivot[0]
        y += body.pivot[1]
        return x, y
    dx, dy = displacement(body, poses, p)
    return p[0] + dx, p[1] + dy


def _unit(v):
    n = float(np.hypot(v[0], v[1]))
    return (v[0] / n, v[1] / n)


def _angle_between_lines(ax, ay, bx, by):
    """Acute angle (deg) between direction fields a and b."""
    dot = np.abs(ax * bx + ay * by) / (np.hypot(ax, ay) * np.hypot(bx, by))
    return np.degrees(np.arccos(np.clip(dot, 0.0, 1.0)))


def spring_sign(part: Part, body: Body) -> int:
    """Direction (+1/-1 along the slider axis) the springs on ``body`` push it at design."""
    f = 0.0
    for s in part.springs:
        if body.id not in (s.a, s.b):
            continue
        mine, other = (s.pb, s.pa) if s.b == body.id else (s.pa, s.pb)
        d = np.hypot(other[0] - mine[0], other[1] - mine[1])
        tension = s.rate * (d - s.rest)
        ux, uy = (other[0] - mine[0]) / d, (other[1] - mine[1]) / d
        f += tension * (ux * body.axis[0] + uy * body.axis[1])
    return 0 if abs(f) < 1e-12 else (1 if f > 0 else -1)


def solve(part: Part, fixed: dict[str, np.ndarray], size: int,
          extra_bodies: dict[str, Body] | None = None) -> Poses:
    """Solve every body of ``part`` given the displacements of the bodies in ``fixed``.

    ``extra_bodies`` are bodies outside the part (already solved, in ``fixed``) that joints
    may refer to (e.g. a connector's driver)."""
    bodies = {b.id: b for b in part.bodies}
    if extra_bodies:
        bodies.update(extra_bodies)
    poses = Poses()
    for bid, u in fixed.items():
        b = bodies[bid]
        (poses.u if b.kind == "slider" else poses.theta)[bid] = np.broadcast_to(
            np.asarray(u, dtype=float), (size,)).copy()
        poses.bad[bid] = np.zeros(size, dtype=bool)
        if b.kind == "link":
            raise KinematicsError(f"{bid}: a free link cannot be an input terminal")
    todo = [b for b in part.bodies if b.id not in fixed]
    by_body: dict[str, list[Joint]] = {}
    for j in part.joints:
        for x in (j.a, j.b):
            by_body.setdefault(x, []).append(j)
    while todo:
        progress = False
        for b in list(todo):
            if poses.known(b.id) or _try_solve(part, b, bodies, by_body, poses, size):
                todo.remove(b)
                progress = True
        if not progress:
            raise KinematicsError(
                "cannot determine " + ", ".join(b.id for b in todo)
                + " from the geometry (no joint or limit drives them)")
    _check_consistency(part, bodies, poses, size)
    return poses


def _get(bodies, bid):
    return None if bid == GROUND else bodies[bid]


def _try_solve(part, b: Body, bodies, by_body: dict[str, list[Joint]], poses: Poses,
               size: int) -> bool:
    joints = by_body.get(b.id, [])
    # 1) bilateral joints to an already known body
    for j in joints:
        other = j.b if j.a == b.id else j.a
        if not poses.known(other):
            continue
        if j.kind == "groove":
            if b.kind == "lever" and j.b == b.id:
                _lever_from_slot(j, b, _get(bodies, j.a), poses, size)
                return True
            if b.kind == "slider" and j.a == b.id:
                _slot_from_pin(j, b, _get(bodies, j.b), poses, size)
                return True
        if j.kind == "rod" and b.kind == "slider":
            _slider_from_rod(j, b, _get(bodies, other), poses, size)
            return True
        if j.kind == "rod" and b.kind == "lever":
            _lever_from_rod(j, b, _get(bodies, other), poses, size)
            return True
    if b.kind in ("lever", "link") and _try_dyad(b, bodies, by_body, poses, size):
        return True
    if b.kind != "slider":
        return False
    # 2) a slider held only by contacts: all the other bodies must be known
    # contacts that position this body (those it drives are checked afterwards)
    contacts = [j for j in joints if j.kind == "contact" and j.driven in (b.id, None)]
    if not contacts or any(not poses.known(j.b if j.a == b.id else j.a) for j in contacts):
        return False
    sign = spring_sign(part, b)
    if sign == 0:
        raise KinematicsError(f"{b.id}: held only by contacts but no spring pushes it")
    lo = np.full(size, -np.inf)
    hi = np.full(size, np.inf)
    bad = np.zeros(size, dtype=bool)
    for j in contacts:
        n = j.normal
        axn = b.axis[0] * n[0] + b.axis[1] * n[1]
        if abs(axn) < 1e-9:
            continue
        if j.b == b.id:  # (pb + u·axis - pa') . n >= 0
            ox, oy = position(_get(bodies, j.a), poses, j.pa)
            rhs = (ox - j.pb[0]) * n[0] + (oy - j.pb[1]) * n[1]  # u·axn >= rhs
        else:  # (pb' - pa - u·axis) . n >= 0  ->  u·axn <= (pb' - pa).n
            ox, oy = position(_get(bodies, j.b), poses, j.pb)
            rhs = -((ox - j.pa[0]) * n[0] + (oy - j.pa[1]) * n[1])  # -u·axn >= rhs
            axn = -axn
        bound = np.broadcast_to(rhs / axn, (size,))
        if axn > 0:
            lo = np.maximum(lo, bound)
        else:
            hi = np.minimum(hi, bound)
        bad |= np.broadcast_to(poses.bad.get(j.a if j.b == b.id else j.b,
                                             np.zeros(size, bool)), (size,))
    u = lo if sign < 0 else hi
    if not np.isfinite(u).all():
        raise KinematicsError(f"{b.id}: its spring pushes it towards a side with no stop")
    jam = lo > hi + 1e-9
    poses.u[b.id] = np.where(jam, np.nan, u)
    poses.mark(b.id, bad | jam)
    return True


def _anchor(b: Body, joints: list[Joint], bodies, poses: Poses):
    """The point ``b`` turns about: its ground pivot (lever) or a pin to a known body (link).
    Returns (design point, world x, world y, bad, joint) or None."""
    if b.kind == "lever":
        return b.pivot, np.asarray(b.pivot[0]), np.asarray(b.pivot[1]), None, None
    for j in joints:
        if j.kind != "pin":
            continue
        other = j.b if j.a == b.id else j.a
        if poses.known(other):
            x, y = position(_get(bodies, other), poses, j.pa)
            return j.pa, x, y, poses.bad.get(other), j
    return None


def _try_dyad(b: Body, bodies, by_body: dict[str, list[Joint]], poses: Poses,
              size: int) -> bool:
    """Two bodies joined by a pin, each turning about a known point (a lever's pivot or a pin
    to a solved body): the pin is where the two circles meet, on the design pose's side."""
    joints = by_body.get(b.id, [])
    mine = _anchor(b, joints, bodies, poses)
    if mine is None:
        return False
    for j in joints:
        if j.kind != "pin" or j is mine[4]:
            continue
        other_id = j.b if j.a == b.id else j.a
        if other_id == GROUND or poses.known(other_id):
            continue
        c = bodies[other_id]
        if c.kind not in ("lever", "link"):
            continue
        theirs = _anchor(c, [k for k in by_body.get(c.id, []) if k is not j], bodies, poses)
        if theirs is None:
            continue
        P0 = j.pa
        (A0, ax, ay, abad, _), (B0, bx, by, bbad, _) = mine, theirs
        r1 = float(np.hypot(P0[0] - A0[0], P0[1] - A0[1]))
        r2 = float(np.hypot(P0[0] - B0[0], P0[1] - B0[1]))
        dx, dy = bx - ax, by - ay
        d = np.hypot(dx, dy)
        a = (r1 * r1 - r2 * r2 + d * d) / (2 * np.where(d > 0, d, 1.0))
        h2 = r1 * r1 - a * a
        ok = np.broadcast_to((h2 >= 0) & (d > 0), (size,))
        h = np.sqrt(np.where(h2 >= 0, h2, 0.0))
        side = float(np.sign(_cross((B0[0] - A0[0], B0[1] - A0[1]),
                                    (P0[0] - A0[0], P0[1] - A0[1])))) or 1.0
        ex, ey = dx / np.where(d > 0, d, 1.0), dy / np.where(d > 0, d, 1.0)
        px, py = ax + a * ex - side * h * ey, ay + a * ey + side * h * ex
        bad = ~ok
        for x in (abad, bbad):
            if x is not None:
                bad = bad | np.broadcast_to(x, (size,))
        for body, (Q0, qx, qy) in ((b, (A0, ax, ay)), (c, (B0, bx, by))):
            th = (np.arctan2(py - qy, px - qx) - np.arctan2(P0[1] - Q0[1], P0[0] - Q0[0]))
            th = (th + np.pi) % (2 * np.pi) - np.pi
            poses.theta[body.id] = np.where(ok, th, np.nan) * np.ones(size)
            if body.kind == "link":  # the anchor point moves to (qx, qy): carry the ref
                cs, sn = np.cos(th), np.sin(th)
                rx, ry = body.pivot[0] - Q0[0], body.pivot[1] - Q0[1]
                tx = qx + rx * cs - ry * sn - body.pivot[0]
                ty = qy + rx * sn + ry * cs - body.pivot[1]
                poses.xy[body.id] = (np.where(ok, tx, np.nan) * np.ones(size),
                                     np.where(ok, ty, np.nan) * np.ones(size))
            poses.mark(body.id, bad)
        gamma = _angle_between_lines(px - ax, py - ay, px - bx, py - by)
        poses.transmission[j.id] = gamma * np.ones(size)
        poses.singular_margin[j.id] = gamma * np.ones(size)
        return True
    return False


def _lever_from_slot(j: Joint, lever: Body, slot_body: Body, poses: Poses, size: int):
    """Pin on the lever (unknown angle) in a slot on a known body."""
    P = lever.pivot
    d = _unit((j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
    r = (j.q[0] - P[0], j.q[1] - P[1])
    a = _cross(r, d)
    b = -(r[0] * d[0] + r[1] * d[1])
    rho = float(np.hypot(a, b))
    phi = float(np.arctan2(b, a))
    x0, y0 = position(slot_body, poses, j.p0)
    c = (x0 - P[0]) * d[1] - (y0 - P[1]) * d[0]
    if slot_body is not None and slot_body.kind == "lever":
        raise KinematicsError(f"{j.id}: slot on a lever driving a lever is not supported")
    ratio = np.broadcast_to(c / rho, (size,))
    ok = np.abs(ratio) <= 1.0
    s = -1.0 if phi > 0 else 1.0
    theta = phi + s * np.arccos(np.clip(ratio, -1.0, 1.0))
    theta = (theta + np.pi) % (2 * np.pi) - np.pi
    poses.theta[lever.id] = np.where(ok, theta, np.nan)
    poses.mark(lever.id, ~ok | poses.bad.get(slot_body.id if slot_body else GROUND,
                                              np.zeros(size, bool)))
    poses.singular_margin[j.id] = np.degrees(np.arccos(np.clip(np.abs(ratio), 0, 1)))
    _groove_transmission(j, lever, d, poses)


def _groove_transmission(j: Joint, lever: Body, d, poses: Poses) -> None:
    """Min over both members of 90° minus the angle between the slot's normal force and the
    driven point's motion."""
    th = poses.theta[lever.id]
    r = (j.q[0] - lever.pivot[0], j.q[1] - lever.pivot[1])
    c, s = np.cos(th), np.sin(th)
    rx, ry = r[0] * c - r[1] * s, r[0] * s + r[1] * c
    nx, ny = -d[1], d[0]  # force line: normal to the slot
    lever_mu = 90.0 - _angle_between_lines(nx, ny, -ry, rx)
    poses.transmission[j.id] = lever_mu


def _slot_from_pin(j: Joint, slider: Body, pin_body: Body, poses: Poses, size: int):
    """Slot on the slider (unknown), pin on a known body: linear."""
    d = _unit((j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
    qx, qy = position(pin_body, poses, j.q)
    den = _cross(slider.axis, d)
    if abs(den) < 1e-12:
        raise KinematicsError(f"{j.id}: slot parallel to its slider's travel")
    u = ((qx - j.p0[0]) * d[1] - (qy - j.p0[1]) * d[0]) / den
    poses.u[slider.id] = np.broadcast_to(u, (size,)).copy()
    poses.mark(slider.id, np.broadcast_to(poses.bad.get(pin_body.id, np.zeros(size, bool)),
                                          (size,)))
    slider_mu = 90.0 - _angle_between_lines(-d[1], d[0], slider.axis[0], slider.axis[1])
    mu = np.broadcast_to(np.asarray(slider_mu, dtype=float), (size,))
    if pin_body is not None and pin_body.kind == "lever":  # the lever's side of the pair
        th = poses.theta[pin_body.id]
        r = (j.q[0] - pin_body.pivot[0], j.q[1] - pin_body.pivot[1])
        rx = r[0] * np.cos(th) - r[1] * np.sin(th)
        ry = r[0] * np.sin(th) + r[1] * np.cos(th)
        mu = np.minimum(mu, 90.0 - _angle_between_lines(-d[1], d[0], -ry, rx))
        poses.singular_margin[j.id] = np.broadcast_to(mu, (size,)).copy()
    poses.transmission[j.id] = np.broadcast_to(mu, (size,)).copy()


def _slider_from_rod(j: Joint, slider: Body, other: Body, poses: Poses, size: int):
    """A rod of fixed length between a known body and the slider: the root that is zero at the
    design pose (the branch the mechanism is built on)."""
    mine, theirs = (j.pb, j.pa) if j.b == slider.id else (j.pa, j.pb)
    ox, oy = position(other, poses, theirs)
    wx, wy = mine[0] - ox, mine[1] - oy
    e = slider.axis
    we = wx * e[0] + wy * e[1]
    disc = we * we - (wx * wx + wy * wy) + j.length ** 2
    we0 = (mine[0] - theirs[0]) * e[0] + (mine[1] - theirs[1]) * e[1]
    s = 1.0 if we0 >= 0 else -1.0
    ok = disc >= 0
    u = -we + s * np.sqrt(np.where(ok, disc, 0.0))
    poses.u[slider.id] = np.where(ok, u, np.nan) * np.ones(size)
    poses.mark(slider.id, ~np.broadcast_to(ok, (size,))
               | np.broadcast_to(poses.bad.get(other.id if other else GROUND,
                                               np.zeros(size, bool)), (size,)))
    # rod direction against the slider's travel
    px, py = mine[0] + poses.u[slider.id] * e[0] - ox, mine[1] + poses.u[slider.id] * e[1] - oy
    alpha = _angle_between_lines(px, py, e[0], e[1])
    mu = 90.0 - alpha
    if other is not None and other.kind == "lever":  # the lever arm's side of the pair
        th = poses.theta[other.id]
        r = (theirs[0] - other.pivot[0], theirs[1] - other.pivot[1])
        ax_ = r[0] * np.cos(th) - r[1] * np.sin(th)
        ay_ = r[0] * np.sin(th) + r[1] * np.cos(th)
        mu = np.minimum(mu, _angle_between_lines(ax_, ay_, px, py))
    poses.transmission[j.id] = mu * np.ones(size)
    poses.singular_margin[j.id] = mu * np.ones(size)


def _lever_from_rod(j: Joint, lever: Body, other: Body, poses: Poses, size: int):
    """A rod from a known body to a pin on the lever: the pin is where the lever's circle
    (about its pivot) meets the rod's circle (about the known end), on the side of the line of
    centres the design pose is on.

    Worked in units of the centre distance d (D = rod end - pivot): the pin sits at
    A·D ± H·D⊥ from the pivot with A = 1/2 + (r² - L²)/(2d²) and H² = r²/d² - A², so one
    division, one square root and one arctan2 place it; the transmission angle comes from the
    same numbers (law of cosines: arm·rod = (d² - r² - L²)/2, |arm×rod| = H·d²) by arctan2,
    which unlike arccos of a cosine stays accurate at the toggle (H -> 0)."""
    mine, theirs = (j.pb, j.pa) if j.b == lever.id else (j.pa, j.pb)
    P = lever.pivot
    r2 = (mine[0] - P[0]) ** 2 + (mine[1] - P[1]) ** 2
    L2 = j.length * j.length
    cx, cy = position(other, poses, theirs)
    dx, dy = cx - P[0], cy - P[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / (dx * dx + dy * dy)  # d = 0 or NaN: A, H2 NaN below, the state is bad
        A = 0.5 * (r2 - L2) * inv
        A += 0.5
        H2 = r2 * inv - A * A
        ok = H2 >= 0
        H = np.sqrt(H2)  # unsolved states (past the toggle): NaN pin, NaN angle
    side = float(np.sign(_cross((theirs[0] - P[0], theirs[1] - P[1]),
                                (mine[0] - P[0], mine[1] - P[1])))) or 1.0
    rx, ry = A * dx, A * dy
    if side > 0:
        rx -= H * dy
        ry += H * dx
    else:
        rx += H * dy
        ry -= H * dx
    phi0 = float(np.arctan2(mine[1] - P[1], mine[0] - P[0]))
    theta = np.arctan2(ry, rx)
    theta -= phi0  # in [-pi - phi0, pi - phi0]: wrap the one side that can leave [-pi, pi)
    if phi0 > 0:
        np.add(theta, 2 * np.pi, out=theta, where=theta < -np.pi)
    else:
        np.subtract(theta, 2 * np.pi, out=theta, where=theta >= np.pi)
    poses.theta[lever.id] = theta if theta.shape == (size,) else np.broadcast_to(
        theta, (size,)).copy()
    other_bad = poses.bad.get(other.id if other else GROUND)
    bad = ~np.broadcast_to(ok, (size,))
    poses.mark(lever.id, bad if other_bad is None else bad | other_bad)
    rx += P[0]
    ry += P[1]
    poses.placed[_key(lever, mine)] = (rx, ry)
    if other is not None:
        poses.placed[_key(other, theirs)] = (cx, cy)
    # transmission: angle between the rod and the lever arm (90° is ideal); 0 past the toggle
    # (fmax takes 0 over H's NaN there)
    cos_part = np.abs(0.5 - 0.5 * (r2 + L2) * inv)
    gamma = np.arctan2(np.fmax(H, 0.0), cos_part)
    gamma *= 180.0 / np.pi
    if gamma.shape != (size,):
        gamma = np.broadcast_to(gamma, (size,)).copy()
    poses.transmission[j.id] = gamma  # read-only from here on: one array serves both
    poses.singular_margin[j.id] = gamma


def _key(body: Body | None, p: Point) -> tuple[str, float, float]:
    return (GROUND if body is None else body.id, float(p[0]), float(p[1]))


def _placed_position(body: Body | None, poses: Poses, p: Point):
    """``position``, reusing the point where a closed form of this solve placed it."""
    hit = poses.placed.get(_key(body, p))
    return hit if hit is not None else position(body, poses, p)


def _check_consistency(part: Part, bodies, poses: Poses, size: int, tol: float = 1e-6) -> None:
    """Contacts must not be penetrated and redundant bilateral joints must close; states where
    they do not are marked bad on the joint's bodies (the mechanism binds there)."""
    for j in part.joints:
        a, b = _get(bodies, j.a), _get(bodies, j.b)
        if (a is not None and not poses.known(a.id)) or (b is not None and not poses.known(b.id)):
            continue
        if j.kind == "contact":
            ax_, ay_ = position(a, poses, j.pa)
            bx_, by_ = position(b, poses, j.pb)
            gap = (bx_ - ax_) * j.normal[0] + (by_ - ay_) * j.normal[1]
            viol = np.broadcast_to(gap < -tol * max(1.0, abs(j.pa[0])), (size,))
        elif j.kind == "rod":  # |distance - length| > 1e-6, squared: no square root
            ax_, ay_ = _placed_position(a, poses, j.pa)
            bx_, by_ = _placed_position(b, poses, j.pb)
            ex, ey = bx_ - ax_, by_ - ay_
            g2 = ex * ex
            g2 += ey * ey
            viol = g2 > (j.length + 1e-6) ** 2
            if j.length > 1e-6:
                viol |= g2 < (j.length - 1e-6) ** 2
            viol = np.broadcast_to(viol, (size,))
        elif j.kind == "pin":
            ax_, ay_ = position(a, poses, j.pa)
            bx_, by_ = position(b, poses, j.pa)
            viol = np.broadcast_to(np.hypot(bx_ - ax_, by_ - ay_) > 1e-6, (size,))
        elif j.kind == "groove":
            d = _unit((j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
            x0, y0 = position(a, poses, j.p0)
            qx, qy = position(b, poses, j.q)
            off = (qx - x0) * d[1] - (qy - y0) * d[0]
            along = (qx - x0) * d[0] + (qy - y0) * d[1]
            length = float(np.hypot(j.p1[0] - j.p0[0], j.p1[1] - j.p0[1]))
            viol = np.broadcast_to((np.abs(off) > 1e-6) | (along < -1e-6)
                                   | (along > length + 1e-6), (size,))
        else:
            continue
        for x in (a, b):
            if x is not None:
                poses.mark(x.id, viol)
