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

import operator
import weakref

import numpy as np

from mechc.geometry.circles import circle_meeting
from mechc.ir.mechanism import GROUND, Body, Joint, Part
from mechc.parts import body_kind, joint_kind
from mechc.parts.base import (
    JointKind,
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
    may refer to (e.g. a connector's driver).

    The order in which bodies are placed, and by which closed form, depends only on which
    bodies and joints the part has and which are given, never on the values: it is worked out
    on the first solve and replayed after (:class:`_Plan`), as a proof solves each part once
    per chunk of states."""
    plan = _plan_of(part, fixed, extra_bodies)
    bodies = plan.bodies if plan is not None else _bodies(part, extra_bodies)
    poses = Poses()
    for bid, u in fixed.items():
        b = bodies[bid]
        kind = body_kind(b.kind)
        if not kind.input_terminal:
            raise KinematicsError(f"{bid}: a free {b.kind} cannot be an input terminal")
        if isinstance(u, np.ndarray) and u.dtype == np.float64 and u.shape == (size,):
            u = u.copy()
        else:
            u = np.broadcast_to(np.asarray(u, dtype=float), (size,)).copy()
        getattr(poses, kind.coordinate)[bid] = u
        poses.bad[bid] = np.zeros(size, dtype=bool)
    if plan is not None:
        for step, args in plan.steps:
            if not step(*args, poses, size):  # the structure is the plan's: cannot happen
                raise AssertionError(f"{part}: a planned closed form did not apply")
        for violation, j, a, b in plan.checks:
            _mark_violation(violation(j, a, b, poses, size, 1e-6), a, b, poses)
        return poses
    steps: list[tuple] = []
    todo = [b for b in part.bodies if b.id not in fixed]
    by_body: dict[str, list[Joint]] = {}
    for j in part.joints:
        for x in (j.a, j.b):
            by_body.setdefault(x, []).append(j)
    while todo:
        progress = False
        for b in list(todo):
            if poses.known(b.id):
                todo.remove(b)
                progress = True
                continue
            step = _try_solve(part, b, bodies, by_body, poses, size)
            if step is not None:
                steps.append(step)
                todo.remove(b)
                progress = True
        if not progress:
            raise KinematicsError(
                "cannot determine " + ", ".join(b.id for b in todo)
                + " from the geometry (no joint or limit drives them)")
    checks = _consistency_checks(part, bodies, poses)
    for violation, j, a, b in checks:
        _mark_violation(violation(j, a, b, poses, size, 1e-6), a, b, poses)
    _keep_plan(part, fixed, extra_bodies, _Plan(tuple(part.bodies), tuple(part.joints),
                                                tuple((extra_bodies or {}).values()), bodies,
                                                steps, checks))
    return poses


def _try_solve(part, b: Body, bodies, by_body: dict[str, list[Joint]], poses: Poses,
               size: int) -> tuple | None:
    """Place ``b`` by the first closed form that applies; the step taken, ``(function, its
    arguments before poses and size)``, or None if none applies yet."""
    joints = by_body.get(b.id, [])
    # 1) bilateral joints to an already known body
    for j in joints:
        other = j.b if j.a == b.id else j.a
        if not poses.known(other):
            continue
        step = (joint_kind(j.kind).solve, (j, b, body_or_ground(bodies, other)))
        if step[0](*step[1], poses, size):
            return step
    kind = body_kind(b.kind)
    if kind.dyad:
        step = (_try_dyad, (b, bodies, by_body))
        if _try_dyad(b, bodies, by_body, poses, size):
            return step
    if not kind.held_by_contacts:
        return None
    # 2) a slider held only by contacts: all the other bodies must be known
    # contacts that position this body (those it drives are checked afterwards)
    contacts = [j for j in joints if joint_kind(j.kind).one_sided and j.driven in (b.id, None)]
    if not contacts or any(not poses.known(j.b if j.a == b.id else j.a) for j in contacts):
        return None
    step = (_held_by_contacts, (part, b, bodies, contacts))
    return step if _held_by_contacts(part, b, bodies, contacts, poses, size) else None


def _held_by_contacts(part, b: Body, bodies, contacts: list[Joint], poses: Poses,
                      size: int) -> bool:
    """A slider held by one-sided contacts against known bodies, pushed by its spring to the
    nearest limit on its side."""
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


def _consistency_checks(part: Part, bodies, poses: Poses) -> list[tuple]:
    """The joints whose kind checks them once both bodies are solved (contacts must not be
    penetrated, redundant bilateral joints must close), as ``(violation, joint, a, b)``."""
    out = []
    for j in part.joints:
        a, b = body_or_ground(bodies, j.a), body_or_ground(bodies, j.b)
        if (a is not None and not poses.known(a.id)) or (b is not None and not poses.known(b.id)):
            continue
        kind = joint_kind(j.kind)
        if getattr(kind.violation, "__func__", None) is not _NO_CHECK:  # it checks something
            out.append((kind.violation, j, a, b))
    return out


def _mark_violation(viol: np.ndarray | None, a: Body | None, b: Body | None,
                    poses: Poses) -> None:
    """States where a joint's check fails are marked bad on its bodies (the mechanism binds
    there)."""
    if viol is None:
        return
    for x in (a, b):
        if x is not None:
            poses.mark(x.id, viol)


_NO_CHECK = JointKind.violation.__func__  # the default: nothing to check


class _Plan:
    """How a part was solved for one set of given bodies: the bodies and joints it had (by
    identity: a part whose lists were changed is planned again), the id -> body table, each
    step (a closed form and the arguments it was called with) and each joint check."""

    __slots__ = ("part_bodies", "part_joints", "extra", "bodies", "steps", "checks")

    def __init__(self, part_bodies, part_joints, extra, bodies, steps, checks):
        self.part_bodies, self.part_joints, self.extra = part_bodies, part_joints, extra
        self.bodies, self.steps, self.checks = bodies, steps, checks


#: id(part) -> (weak reference to the part, {(given body ids, extra body ids): plan}); an entry
#: goes with its part
_PLANS: dict[int, tuple[weakref.ref, dict]] = {}


def _plan_key(fixed, extra_bodies) -> tuple:
    return tuple(fixed), tuple(extra_bodies) if extra_bodies else ()


def _plan_of(part: Part, fixed, extra_bodies) -> _Plan | None:
    """The part's plan for these given bodies, if it still has the bodies and joints it was
    made with."""
    entry = _PLANS.get(id(part))
    if entry is None or entry[0]() is not part:
        return None
    plan = entry[1].get(_plan_key(fixed, extra_bodies))
    if plan is None or not (_same(plan.part_bodies, part.bodies)
                            and _same(plan.part_joints, part.joints)
                            and _same(plan.extra, (extra_bodies or {}).values())):
        return None
    return plan


def _same(kept: tuple, now) -> bool:
    return len(kept) == len(now) and all(map(operator.is_, kept, now))


def _keep_plan(part: Part, fixed, extra_bodies, plan: _Plan) -> None:
    key = id(part)
    entry = _PLANS.get(key)
    if entry is None or entry[0]() is not part:
        ref = weakref.ref(part, lambda _, key=key: _PLANS.pop(key, None))
        entry = _PLANS[key] = (ref, {})
    entry[1][_plan_key(fixed, extra_bodies)] = plan


def _bodies(part: Part, extra_bodies) -> dict[str, Body]:
    bodies = {b.id: b for b in part.bodies}
    if extra_bodies:
        bodies.update(extra_bodies)
    return bodies
