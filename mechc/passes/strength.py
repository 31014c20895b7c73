"""Strength: the loads every part of a mechanism can see, its pins sized for them, and the
checks that no part yields, breaks or buckles (docs/mechanism.md, "Strength").

Loads. The kinematic model has no stress analysis; each part is given the largest force of the
force budget that passes through it (``mechc/passes/assemble.py``): a net's load is its demand
(``data["demand"]``, the larger of towards on and towards off: the springs and loads it moves,
with their 1.3 margin and 30 % rise, plus guide friction), for every rod and the fan-out bar of
the net; an input slider carries its net's load; a cell's parts carry the largest load of the
nets it touches (and of its own output demand). The actuators are position-controlled and limited
to their rating: they stop at the end of the stroke, before any load reaches its stop (2 % of
the stroke beyond), so in service no part sees the actuator's full rating. A jam (a load
blocked mid-stroke while the actuator pushes on) is NOT designed for: it would put up to the
rating (default 100 N) on a rod.

Every bar, slider, lever and rod has the cross-section ``ctx.bar`` x ``ctx.thickness``.

Checks (each a :class:`~mechc.ir.check.Check`), with the safety factors below:

- axial stress of every cell, input slider and net: load / (bar x thickness) against the plate's
  yield strength / ``YIELD_SAFETY`` (a brittle plate: its tensile strength / ``BRITTLE_SAFETY``);
- Euler buckling of every rod (pinned-pinned, K = 1) about its weak axis, under the load of the
  part it belongs to in compression: P_cr / load >= ``BUCKLING_SAFETY``;
- pin shear (single shear, steel pins) and bearing of the plate on its pins, per part;
- the wire stress of every designed spring against its allowable (``mechc/cells/springs.py``).

Not checked: bending of levers and cranks, contact (Hertz) stress of rollers and cams, fatigue.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from mechc.cells.materials import (
    PIN_MATERIAL,
    PIN_SHEAR_FRACTION,
    PIN_SIZES,
    Material,
    material,
)
from mechc.ir.check import Check
from mechc.ir.design import Design
from mechc.ir.mechanism import Mechanism, Part, SynthContext

#: Factor of safety on the yield strength of a ductile plate (and of the steel pins).
YIELD_SAFETY = 2.0
#: Factor of safety on the tensile strength of a brittle plate (acrylic), which gives no warning.
BRITTLE_SAFETY = 3.0
#: Factor of safety of the Euler critical load over the largest compressive load of a rod.
BUCKLING_SAFETY = 3.0
#: Joints made with pins (rods have one at each end) and the bodies turning about a fixed pin.
PIN_JOINTS = ("rod", "pin", "groove")
PIVOTED = ("lever", "rotor")


def plate_allowable(m: Material) -> float:
    """Allowable normal stress (MPa) of the plate: yield / 2, or tensile strength / 3."""
    return m.strength / (BRITTLE_SAFETY if m.brittle else YIELD_SAFETY)


def pin_shear_allowable() -> float:
    """Allowable shear stress (MPa) of a steel pin: 0.577 x yield / YIELD_SAFETY."""
    return PIN_SHEAR_FRACTION * PIN_MATERIAL.strength / YIELD_SAFETY


def force_ceiling(ctx: SynthContext) -> float:
    """The force (N) at which one bar of the plate yields (or breaks): the most any part of a
    design could carry without a safety factor. A load option beyond it is refused."""
    return material(ctx.material).strength * ctx.bar * ctx.thickness


def euler_load(E: float, width: float, thickness: float, length: float, k: float = 1.0) -> float:
    """Euler critical load (N) of a rectangular strut about its weak axis: pi^2 E I / (K L)^2,
    I = b h^3 / 12 with h the smaller side."""
    b, h = max(width, thickness), min(width, thickness)
    return math.pi ** 2 * E * (b * h ** 3 / 12.0) / (k * length) ** 2


@dataclass(frozen=True)
class PushRod:
    """A rod as the strength checks see it: a pinned-pinned strut."""

    id: str
    where: str  # the part it belongs to ("net n3", a cell id)
    length: float  # mm, pin to pin
    width: float  # mm, in the plane
    thickness: float  # mm, the plate
    load: float  # N, its largest compressive load


def _demand(d: dict) -> tuple[float, float]:
    """(towards on, towards off) of a Demand's JSON."""
    return float(d.get("right_N", 0.0)), float(d.get("left_N", 0.0))


def part_loads(design: Design) -> dict[str, float]:
    """Design load (N) of every net (``net NAME``), cell (its id) and input (``input NAME``):
    the largest force of the force budget through it, either way."""
    nl, mech = design.netlist, design.mechanism
    net = {name: max(_demand(part.data.get("demand", {}))) for name, part in mech.nets.items()}
    out = {f"net {k}": v for k, v in net.items()}
    out.update({f"input {k}": net.get(k, 0.0) for k in mech.inputs})
    for cid in mech.order:
        c, part = nl.cells[cid], mech.cells[cid]
        own = max(_demand(part.data.get("output_demand", {})))
        out[cid] = max([own] + [net.get(n, 0.0) for n in (*c.inputs, *c.outputs)])
    return out


def _parts(mech: Mechanism):
    """(where, part) for every part: inputs, cells, nets."""
    yield from ((f"input {k}", p) for k, p in mech.inputs.items())
    yield from ((cid, mech.cells[cid]) for cid in mech.order)
    yield from ((f"net {k}", p) for k, p in sorted(mech.nets.items()))


def push_rods(design: Design, loads: dict[str, float] | None = None) -> list[PushRod]:
    """Every rod of the mechanism (the nets' and the cells' own) with its length, cross-section
    and largest compressive load: the one place the strength checks read rods from.

    A net's rod ``rodK`` drives the net's K-th load (``data["loads"]``) and carries what that
    load asks in the force budget (its cell's input load plus guide friction): towards on it
    is pushed (compressed) when the load lies right of the fan-out bar (``pb`` right of
    ``pa``), towards off when the load lies left (a feedback rod). A cell's rods take the
    cell's load."""
    mech = design.mechanism
    loads = part_loads(design) if loads is None else loads
    ctx = mech.ctx
    rods = []
    for where, part in _parts(mech):
        ends = part.data.get("loads", [])
        for j in part.joints:
            if j.kind != "rod" or not j.length:
                continue
            load = loads.get(where, 0.0)
            if where.startswith("net ") and len(ends) == len(part.joints):
                right, left = _share(mech, ends[part.joints.index(j)])
                load = right if j.pb[0] >= j.pa[0] else left
            rods.append(PushRod(j.id, where, float(j.length), ctx.bar, ctx.thickness, load))
    return rods


def _share(mech: Mechanism, load: str) -> tuple[float, float]:
    """What one load ``cell.pin`` of a net asks (towards on, towards off), as the force budget
    added it to the net's demand: the cell's input load and its guide friction."""
    cid, pin = load.rsplit(".", 1)
    right, left = _demand(mech.cells[cid].data.get("input_loads", {}).get(pin, {}))
    return right + mech.ctx.friction, left + mech.ctx.friction


def pin_diameter(load: float, ctx: SynthContext) -> float:
    """The smallest stocked pin, at least the design rule ``ctx.pin_diameter``, whose shear and
    whose bearing on the plate hold ``load``; at most half the bar width (the hole leaves a
    quarter of the bar each side), which a load too large for any pin gets (and fails)."""
    cap = ctx.bar / 2
    plate = plate_allowable(material(ctx.material))
    sizes = [d for d in PIN_SIZES if ctx.pin_diameter <= d <= cap] or [min(ctx.pin_diameter, cap)]
    for d in sizes:
        if (load / (math.pi * d * d / 4) <= pin_shear_allowable()
                and load / (d * ctx.thickness) <= plate):
            return d
    return sizes[-1]


def size_pins(design: Design, loads: dict[str, float]) -> None:
    """Give every pin joint and every fixed pivot of each part the pin its load needs."""
    ctx = design.mechanism.ctx
    for where, part in _parts(design.mechanism):
        d = pin_diameter(loads.get(where, 0.0), ctx)
        for j in part.joints:
            if j.kind in PIN_JOINTS:
                j.pin_diameter = d
        for b in part.bodies:
            if b.kind in PIVOTED:
                b.pin_diameter = d


def _pins_of(part: Part) -> list[float]:
    return ([j.pin_diameter for j in part.joints if j.kind in PIN_JOINTS and j.pin_diameter]
            + [b.pin_diameter for b in part.bodies if b.kind in PIVOTED and b.pin_diameter])


def strength_checks(design: Design) -> list[Check]:
    """Size the pins, then check every part: axial stress, rod buckling, pin shear and bearing,
    spring wire stress."""
    mech = design.mechanism
    ctx = mech.ctx
    mat = material(ctx.material)
    loads = part_loads(design)
    size_pins(design, loads)
    allow = plate_allowable(mat)
    area = ctx.bar * ctx.thickness
    out: list[Check] = []
    for where, part in _parts(mech):
        load = loads.get(where, 0.0)
        out.append(Check(f"axial stress ({mat.name}, {ctx.bar:g} x {ctx.thickness:g} mm bars)",
                         where, load / area, allow, "<=", "MPa"))
        pins = _pins_of(part)
        if pins and load > 0.0:
            d = min(pins)
            out.append(Check(f"pin shear ({d:g} mm steel pins)", where,
                             load / (math.pi * d * d / 4), pin_shear_allowable(), "<=", "MPa"))
            out.append(Check(f"pin bearing ({d:g} mm pins in {ctx.thickness:g} mm {mat.name})",
                             where, load / (d * ctx.thickness), allow, "<=", "MPa"))
        for s in part.springs:
            if s.coil is not None:
                out.append(Check(f"spring wire stress ({s.coil.wire:g} mm music wire)", s.id,
                                 s.coil.stress, s.coil.allowable, "<=", "MPa"))
    for rod in push_rods(design, loads):
        if rod.load <= 0.0:
            continue
        p_cr = euler_load(mat.E, rod.width, rod.thickness, rod.length)
        out.append(Check(f"rod buckling (Euler, {rod.length:.4g} mm long) / load", rod.id,
                         p_cr / rod.load, BUCKLING_SAFETY, ">=", "x"))
    return out
