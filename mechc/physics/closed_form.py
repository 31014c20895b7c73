"""Closed-form kinematics of slider-and-lever mechanisms, read from their geometry alone.

Quasi-static: every spring wins against friction, so a slider held only by one-sided contacts
and stops sits against its nearest limit in the direction its spring pulls — the largest lower
bound or the smallest upper bound (OR bars take the max of their inputs, AND bars the min).
Bilateral joints are solved in closed form: a pin in a slot gives the lever angle from
``a cos θ + b sin θ = c`` (branch fixed at the design pose), a slot on a slider follows a lever
pin linearly, a rod between two sliders is a quadratic. Everything is numpy-vectorised over
many states at once. Where a closed form has no real solution (the parts cannot assemble, or a
slider is jammed between contradictory limits) the state is marked bad, never guessed.

This module holds the solving order (which body next, from what); the maths of each body and
joint kind lives with its kind in ``mechc.parts``.
"""

from __future__ import annotations

import numpy as np

from mechc.geometry.circles import circle_meeting
from mechc.ir.mechanism import GROUND, Body, Joint, Part
from mechc.parts import body_kind, joint_kind
from mechc.parts.base import (
    body_or_ground,
    cross,
    displacement,
    line_tan,
    position,
    side_of,
)
from mechc.parts.poses import KinematicsError, Poses, cos_sin

# the closed form's public names (``Poses``, ``position``, ... live with the parts and poses)
__all__ = ["KinematicsError", "Poses", "cos_sin", "displacement", "position", "solve",
           "spring_sign"]


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
        kind = body_kind(b.kind)
        if isinstance(u, np.ndarray) and u.dtype == np.float64 and u.shape == (size,):
            u = u.copy()
        else:
            u = np.broadcast_to(np.asarray(u, dtype=float), (size,)).copy()
        getattr(poses, kind.coordinate)[bid] = u
        poses.bad[bid] = np.zeros(size, dtype=bool)
        if not kind.input_terminal:
            raise KinematicsError(f"{bid}: a free {b.kind} cannot be an input terminal")
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


def _try_solve(part, b: Body, bodies, by_body: dict[str, list[Joint]], poses: Poses,
               size: int) -> bool:
    joints = by_body.get(b.id, [])
    # 1) bilateral joints to an already known body
    for j in joints:
        other = j.b if j.a == b.id else j.a
        if not poses.known(other):
            continue
        if joint_kind(j.kind).solve(j, b, body_or_ground(bodies, other), poses, size):
            return True
    kind = body_kind(b.kind)
    if kind.dyad and _try_dyad(b, bodies, by_body, poses, size):
        return True
    if not kind.held_by_contacts:
        return False
    # 2) a slider held only by contacts: all the other bodies must be known
    # contacts that position this body (those it drives are checked afterwards)
    contacts = [j for j in joints if joint_kind(j.kind).one_sided and j.driven in (b.id, None)]
    if not contacts or any(not poses.known(j.b if j.a == b.id else j.a) for j in contacts):
        return False
    sign = spring_sign(part, b)
    if sign == 0:
        raise KinematicsError(f"{b.id}: held only by contacts but no spring pushes it")
    lo = np.full(size, -np.inf)
    hi = np.full(size, np.inf)
    bad = np.zeros(size, dtype=bool)
    for j in contacts:
        other = j.a if j.b == b.id else j.b
        limit = joint_kind(j.kind).slider_limit(j, b, body_or_ground(bodies, other), poses)
        if limit is None:
            continue
        axn, rhs = limit  # u·axn >= rhs
        bound = np.broadcast_to(rhs / axn, (size,))
        if axn > 0:
            lo = np.maximum(lo, bound)
        else:
            hi = np.minimum(hi, bound)
        bad |= np.broadcast_to(poses.bad.get(other, np.zeros(size, bool)), (size,))
    u = lo if sign < 0 else hi
    if np.isinf(u).any():
        raise KinematicsError(f"{b.id}: its spring pushes it towards a side with no stop")
    jam = lo > hi + 1e-9
    poses.u[b.id] = np.where(jam, np.nan, u)
    # NaN: a limit from a body no closed form could place in that state (upstream bad)
    poses.mark(b.id, bad | jam | np.isnan(u))
    return True


def _try_dyad(b: Body, bodies, by_body: dict[str, list[Joint]], poses: Poses,
              size: int) -> bool:
    """Two bodies joined by a pin, each turning about a known point (a lever's pivot or a pin
    to a solved body): the pin is where the two circles meet, on the design pose's side."""
    joints = by_body.get(b.id, [])
    kind_b = body_kind(b.kind)
    mine = kind_b.dyad_anchor(b, joints, bodies, poses)
    if mine is None:
        return False
    for j in joints:
        if not joint_kind(j.kind).revolute or j is mine[4]:
            continue
        other_id = j.b if j.a == b.id else j.a
        if other_id == GROUND or poses.known(other_id):
            continue
        c = bodies[other_id]
        kind_c = body_kind(c.kind)
        if not kind_c.dyad:
            continue
        theirs = kind_c.dyad_anchor(c, [k for k in by_body.get(c.id, []) if k is not j], bodies,
                                    poses)
        if theirs is None:
            continue
        P0 = j.pa
        (A0, ax, ay, abad, _), (B0, bx, by, bbad, _) = mine, theirs
        r1 = np.hypot(P0[0] - A0[0], P0[1] - A0[1])  # arrays in a tolerance run
        r2 = np.hypot(P0[0] - B0[0], P0[1] - B0[1])
        # the pin is where the two circles meet, on the side it has at the design pose
        side = side_of(cross((B0[0] - A0[0], B0[1] - A0[1]), (P0[0] - A0[0], P0[1] - A0[1])))
        centres_a = np.stack(np.broadcast_arrays(ax, ay), axis=-1)
        centres_b = np.stack(np.broadcast_arrays(bx, by), axis=-1)
        pin, h2 = circle_meeting(centres_a, r1, centres_b, r2, side, miss="clamp")
        px, py = pin[..., 0], pin[..., 1]
        ok = np.broadcast_to((h2 >= 0) & np.isfinite(h2), (size,))
        bad = ~ok
        for x in (abad, bbad):
            if x is not None:
                bad = bad | np.broadcast_to(x, (size,))
        for body, kind, (Q0, qx, qy) in ((b, kind_b, (A0, ax, ay)), (c, kind_c, (B0, bx, by))):
            th = (np.arctan2(py - qy, px - qx) - np.arctan2(P0[1] - Q0[1], P0[0] - Q0[0]))
            th = (th + np.pi) % (2 * np.pi) - np.pi
            kind.set_turn(body, poses, th, ok, Q0, qx, qy, size)
            poses.mark(body.id, bad)
        gamma = line_tan(px - ax, py - ay, px - bx, py - by) * np.ones(size)
        poses.transmission.set_tan(j.id, gamma)
        poses.singular_margin.set_tan(j.id, gamma)
        return True
    return False


def _check_consistency(part: Part, bodies, poses: Poses, size: int, tol: float = 1e-6) -> None:
    """Contacts must not be penetrated and redundant bilateral joints must close; states where
    they do not are marked bad on the joint's bodies (the mechanism binds there)."""
    for j in part.joints:
        a, b = body_or_ground(bodies, j.a), body_or_ground(bodies, j.b)
        if (a is not None and not poses.known(a.id)) or (b is not None and not poses.known(b.id)):
            continue
        viol = joint_kind(j.kind).violation(j, a, b, poses, size, tol)
        if viol is None:
            continue
        for x in (a, b):
            if x is not None:
                poses.mark(x.id, viol)
