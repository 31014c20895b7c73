"""Every dimension a design has, and a copy of its mechanism with them changed.

A dimension is one number of the geometry a maker cuts, drills or buys: a coordinate of a
joint's point (a pin hole, a slot's end, a contact face, a stop on the frame), a rod's length,
a lever's pivot, a spring's rate and preload, a part's outline, a threshold generator's cam
outline (its radial error per segment of the follower program) and roller radius (data its
cell's kinematics reads: ``profile_error``). :func:`perturb` gives the
mechanism with every dimension at a value of its own; a value may be an array (one entry per
sample and state of a tolerance run), which the closed forms (``mechc.physics.closed_form`` and
the part kinds) carry through as they carry states, so many perturbed designs are solved in one
evaluation.

Directions (a slider's axis, a contact's normal) stay nominal: a guide cut at an angle moves a
slider's points across its travel, not along it, to first order. Terminals (where a signal is
read off and on) are the measuring reference and stay nominal too.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mechc.ir.mechanism import GROUND, Body, Joint, Mechanism, Part, Spring
from mechc.parts.pushrod import net_rods

#: joint attributes that are points, and whether the point is a pin's centre (clearance)
POINT_ATTRS = ("p0", "p1", "q", "pa", "pb")


@dataclass(frozen=True)
class Dim:
    """One dimension: where it is (``part`` key, ``obj`` kind, index in the part's list,
    attribute, component) and what it is (``what``, ``unit``: "mm" or "fraction")."""

    name: str  # e.g. "c6.stop3.pb.x", "c1.spring5 rate"
    owner: str  # the cell id, "net A" or "input A" it belongs to
    what: str  # joint point | rod length | lever pivot | spring rate | spring preload | outline
    unit: str  # "mm" (tolerance) or "fraction" (spring tolerance)
    nominal: float
    part: str  # "cell:c1" | "input:A" | "net:A"
    obj: str  # "joint" | "body" | "spring"
    index: int
    attr: str
    comp: int  # 0 x, 1 y, -1 a scalar
    pin: str = ""  # the pin centre this coordinate places ("" for none): pin clearance acts here
    ground: bool = False  # the point is on the frame (a stop, a fixed pivot)


def _parts(mech: Mechanism) -> list[tuple[str, str, Part]]:
    out = [(f"input:{k}", f"input {k}", p) for k, p in mech.inputs.items()]
    out += [(f"cell:{c}", c, mech.cells[c]) for c in mech.order]
    out += [(f"net:{k}", f"net {k}", p) for k, p in mech.nets.items()]
    return out


def _pin_point(j: Joint, attr: str) -> bool:
    """Points where a pin sits in a hole (or a slot): the joints with play."""
    return ((j.kind == "pin" and attr == "pa") or (j.kind == "rod" and attr in ("pa", "pb"))
            or (j.kind in ("groove", "touch") and attr == "q"))


def dimensions(mech: Mechanism) -> list[Dim]:
    """Every dimension of ``mech``, in a stable order (parts, then their bodies, joints and
    springs in the order the design lists them)."""
    dims: list[Dim] = []
    rod_length = {r.body: float(r.length) for part in mech.nets.values()
                  for r in net_rods(part) if r.body is not None}
    for key, owner, part in _parts(mech):
        for i, b in enumerate(part.bodies):
            if b.kind == "lever" and b.pivot is not None:
                for c, ax in enumerate("xy"):
                    dims.append(Dim(f"{b.id}.pivot.{ax}", owner, "lever pivot", "mm",
                                    float(b.pivot[c]), key, "body", i, "pivot", c,
                                    pin=f"{b.id}.pivot", ground=True))
            if b.outline:
                dims.append(Dim(f"{b.id}.outline", owner, "outline", "mm", 0.0, key, "body", i,
                                "outline", -1))
            if b.id in rod_length:  # a net's rod: its holes' spacing, cut apart from the pins
                dims.append(Dim(f"{b.id}.length", owner, "rod length", "mm", rod_length[b.id],
                                key, "body", i, "length", -1))
        for i, j in enumerate(part.joints):
            for attr in (("q",) if j.kind == "touch" else POINT_ATTRS):
                # a cam's or roller's contact: only the roller's axle hole is a point of its
                # own (the outline is its cell's data: ``_cam_dims``)
                p = getattr(j, attr)
                if p is None:
                    continue
                on = _point_body(j, attr)
                for c, ax in enumerate("xy"):
                    dims.append(Dim(f"{j.id}.{attr}.{ax}", owner, "joint point", "mm",
                                    float(p[c]), key, "joint", i, attr, c,
                                    pin=f"{j.id}.{attr}" if _pin_point(j, attr) else "",
                                    ground=on == GROUND))
            if j.kind == "rod" and j.length is not None:
                dims.append(Dim(f"{j.id}.length", owner, "rod length", "mm", float(j.length),
                                key, "joint", i, "length", -1))
        dims += _cam_dims(key, owner, part)
        for i, s in enumerate(part.springs):
            dims.append(Dim(f"{s.id} rate", owner, "spring rate", "fraction", float(s.rate),
                            key, "spring", i, "rate", -1))
            dims.append(Dim(f"{s.id} preload", owner, "spring preload", "fraction",
                            float(s.preload), key, "spring", i, "preload", -1))
    return dims


def cam_angles(info: dict) -> list[float]:
    """Where a threshold generator's cam outline gets a radial error of its own: the middle
    of each segment of its follower program (each dwell and each rise or return) over the
    working range and its 5 degree dwells; linear between them (``stdlib/threshold.py``)."""
    lo, hi = info["cam_range"]
    ends = [lo - np.radians(5.0)] + [e for band in info["bands"] for e in band
                                     if lo - np.radians(5.0) < e < hi + np.radians(5.0)]
    ends = sorted(set(ends + [hi + np.radians(5.0)]))
    return [float((a + b) / 2) for a, b in zip(ends, ends[1:])]


def _cam_dims(key: str, owner: str, part: Part) -> list[Dim]:
    """A threshold generator's cam outline (radial error at each of :func:`cam_angles`) and
    its roller's radius: data of the cell's own kinematics, not joint points."""
    info = part.data.get("threshold")
    if not info or "cam_range" not in info:
        return []
    err = info.get("profile_error", {})
    was = err.get("mm", [])
    cell = info["cam_body"].rsplit(".", 1)[0]
    dims = [Dim(f"{cell}.cam.r{k}", owner, "cam profile", "mm",
                float(was[k]) if k < len(was) else 0.0, key, "data", k, "profile", -1)
            for k in range(len(cam_angles(info)))]
    dims.append(Dim(f"{cell}.roller.radius", owner, "roller radius", "mm",
                    float(err.get("roller_mm", 0.0)), key, "data", 0, "roller", -1))
    return dims


def _point_body(j: Joint, attr: str) -> str:
    """The body a joint's point is on (a groove's slot ends on a, its pin on b; a contact's and
    a rod's ``pa`` on a, ``pb`` on b; a pin's point on both: a)."""
    if attr in ("p0", "p1", "pa"):
        return j.a
    return j.b


def perturb(mech: Mechanism, dims: list[Dim], delta, springs: bool = True,
            absolute: bool = False) -> Mechanism:
    """A copy of ``mech`` with dimension ``k`` changed by ``delta[k]`` (mm, or a fraction of a
    spring's rate or preload). A ``delta[k]`` may be an array (one value per sample and state):
    then every number it changes becomes an array.

    ``springs=False`` leaves the springs nominal: the closed forms read a spring only for the
    direction it pulls, so a tolerance run measures spring forces from the same deltas itself
    (``mechc.tolerance.batch``) instead of carrying them through the solve. Outlines are
    changed only in a scalar copy (a design to write): no closed form reads them. A net rod's
    length is not held by a design file apart from its pins (the rod is the line between them):
    only the tolerance run's batch applies it (``mechc.tolerance.batch.Batch``).
    ``absolute``: ``delta`` holds the new values themselves (nominal plus delta, made by the
    caller in one pass), not changes."""
    by_part: dict[str, list[tuple[Dim, object]]] = {}
    for d, v in zip(dims, delta):
        by_part.setdefault(d.part, []).append((d, v))

    def new_part(key: str, part: Part) -> Part:
        return perturb_part(part, by_part.get(key, []), springs, absolute)

    return Mechanism(mech.ctx,
                     {c: new_part(f"cell:{c}", p) for c, p in mech.cells.items()},
                     {k: new_part(f"input:{k}", p) for k, p in mech.inputs.items()},
                     {k: new_part(f"net:{k}", p) for k, p in mech.nets.items()},
                     mech.outputs, mech.actuators, mech.order, mech.checks)


def perturb_part(part: Part, changes: list[tuple[Dim, object]], springs: bool = True,
                 absolute: bool = False) -> Part:
    """One part with its dimensions changed (``changes``: the part's dimensions and their
    deltas, or new values with ``absolute``); see :func:`perturb`."""
    if not changes:
        return part
    scalar = all(np.ndim(v) == 0 for _, v in changes)
    by_obj: dict[tuple[str, int], list[tuple[Dim, object]]] = {}
    for d, v in changes:
        by_obj.setdefault((d.obj, d.index), []).append((d, v))
    bodies = list(part.bodies)
    joints = list(part.joints)
    sprs = list(part.springs)
    for (obj, i), ch in by_obj.items():
        if obj == "body":
            bodies[i] = _body(bodies[i], ch, scalar, absolute)
        elif obj == "joint":
            joints[i] = _changed(joints[i], ch, absolute)
        elif obj == "spring" and springs:
            sprs[i] = _spring(sprs[i], ch)
    data = part.data
    if "cam_range" in part.data.get("threshold", {}):  # its cam pair measures every change
        data = _cam_error(part, [(d, v) for d, v in changes if d.obj == "data"], absolute)
    return Part(bodies, joints, sprs, part.terminals, data)


def _cam_error(part: Part, changes: list[tuple[Dim, object]], absolute: bool) -> dict:
    """The cell's data with the cam's error (``profile_error``, which the THRESHOLD cell's
    kinematics reads): the outline's radial errors, the roller's, and the drawing's pivots and
    roller centre, from which the part's own (perturbed) ones are measured."""
    info = dict(part.data["threshold"])
    old = info.get("profile_error")
    angles = cam_angles(info)
    mm: list[object] = list(old["mm"]) if old else [0.0] * len(angles)
    roller: object = old.get("roller_mm", 0.0) if old else 0.0
    for d, v in changes:
        if d.attr == "profile":
            mm[d.index] = v if absolute else mm[d.index] + v
        else:
            roller = v if absolute else roller + v
    if old:
        ref = {k: old[k] for k in ("K", "Z", "H")}
    else:
        bodies = {b.id: b for b in part.bodies}
        touch = next(j for j in part.joints if j.id == info["touch_joint"])
        ref = {"K": list(bodies[info["cam_body"]].pivot),
               "Z": list(bodies[info["follower_body"]].pivot), "H": list(touch.q)}
    info["profile_error"] = {"phi": angles, "mm": mm, "roller_mm": roller, **ref}
    return {**part.data, "threshold": info}


def _changed(obj, changes: list[tuple[Dim, object]], absolute: bool = False):
    """A copy of a body or joint with its points' components and scalars moved."""
    new: dict[str, object] = {}
    for d, v in changes:
        if d.attr in ("outline", "length") and d.obj == "body":
            continue  # an outline: below; a net rod's length: carried by the batch (its rod)
        if d.comp < 0:
            new[d.attr] = v if absolute else getattr(obj, d.attr) + v
        else:
            p = list(new.get(d.attr, getattr(obj, d.attr)))
            p[d.comp] = v if absolute else p[d.comp] + v
            new[d.attr] = tuple(p)
    return replace(obj, **new) if new else obj


def _body(b: Body, changes: list[tuple[Dim, object]], scalar: bool,
          absolute: bool = False) -> Body:
    b = _changed(b, changes, absolute)
    grow = [v for d, v in changes if d.attr == "outline"]
    if not grow or not scalar:
        return b
    out = []
    for poly in b.outline:  # every edge moved outwards by the delta: the plate cut larger
        cx = sum(p[0] for p in poly) / len(poly)
        cy = sum(p[1] for p in poly) / len(poly)
        out.append([(x + float(np.sign(x - cx)) * grow[0], y + float(np.sign(y - cy)) * grow[0])
                    for x, y in poly])
    return replace(b, outline=out)


def _spring(s: Spring, changes: list[tuple[Dim, object]]) -> Spring:
    """Rate times (1 + its delta); preload times (1 + its delta), by the rest length: the force
    at any length becomes (1 + e_rate) (F + e_preload x preload)."""
    e_rate = sum((v for d, v in changes if d.attr == "rate"), 0.0)
    e_pre = sum((v for d, v in changes if d.attr == "preload"), 0.0)
    rate = s.rate * (1.0 + e_rate)
    rest = s.rest - e_pre * s.preload / s.rate if s.rate else s.rest
    return replace(s, rate=rate, rest=rest, preload=s.preload * (1.0 + e_rate) * (1.0 + e_pre))
