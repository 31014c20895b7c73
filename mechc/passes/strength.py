"""Strength: the loads every part of a mechanism can see, its pins sized for them, and the
checks that no part yields, breaks or buckles (docs/mechanism.md, "Strength").

Loads. The kinematic model has no stress analysis; each part is given the largest force of the
force budget that passes through it (``mechc/passes/assemble.py``): a net's load is its demand
(``data["demand"]``, the larger of towards on and towards off: the springs and loads it moves,
with their 1.3 margin and 30 % rise, plus guide friction), for its fan-out bar and pins; each
rod of a net carries what its own load asks (``push_rods``); an input slider carries its net's
load; a cell's parts carry the largest of its own output demand, the demand of the net it
drives (its output slider moves that net's fan-out bar) and, for each net it loads, what its
own input asks of that net (the one rod between them: the net's other loads pull on their
own rods, not through this cell). The actuators are position-controlled and limited
to their rating: they stop at the end of the stroke, before any load reaches its stop (2 % of
the stroke beyond), so in service no part sees the actuator's full rating. A jam (a load
blocked mid-stroke while the actuator pushes on) is NOT designed for: it would put up to the
rating (default 100 N) on a rod.

Every bar, slider, lever and rod has the cross-section ``ctx.bar`` x ``ctx.thickness``.

Checks (each a :class:`~mechc.ir.check.Check`), with the safety factors below:

- axial stress of every cell, input slider and net: load / (bar x thickness) against the plate's
  yield strength / ``YIELD_SAFETY`` (a brittle plate: its tensile strength / ``BRITTLE_SAFETY``);
- Euler buckling of every rod (pinned-pinned, K = 1) about its weak axis, under its largest
  compressive load: P_cr / load >= ``BUCKLING_SAFETY``. A net rod translates (both its ends
  ride on parallel slider lines), so one too long for that gets guides along its line, as many
  as keep each span within its Euler length (``guide_rods``); a cell's rods are not guided;
- bending of every lever: the part's load at the farthest joint from its pivot, on a bar of
  width ``ctx.bar`` in the plane: 6 F a / (t w^2) against the same allowable;
- pin shear (single shear, steel pins) and bearing of the plate on its pins, per part;
- the wire stress of every designed spring against its allowable (``mechc/cells/springs.py``).

Sizing, at assembly (``size_parts``): each part's pins from its load, guides along the net rods
too long to carry theirs.

Not checked: contact (Hertz) stress of rollers and cams, the bending of cams and sectors along
their profiles, fatigue.
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
from mechc.ir.mechanism import Mechanism, Part, SynthContext
from mechc.parts.pushrod import net_rods

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
class LoadedRod:
    """A rod as the strength checks see it: a pinned-pinned strut."""

    id: str
    where: str  # the part it belongs to ("net n3", a cell id)
    length: float  # mm, pin to pin
    width: float  # mm, in the plane
    thickness: float  # mm, the plate
    load: float  # N, its largest compressive load
    guides: int = 0  # guides along it (a net rod only: it translates), spans length/(guides+1)
    guidable: bool = False  # it translates (both ends on parallel slider lines): may be guided

    @property
    def span(self) -> float:
        """Its buckling length: pin to pin, or between neighbouring guides."""
        return self.length / (self.guides + 1)


def _demand(d: dict) -> tuple[float, float]:
    """(towards on, towards off) of a Demand's JSON."""
    return float(d.get("right_N", 0.0)), float(d.get("left_N", 0.0))


def part_loads(mech: Mechanism) -> dict[str, float]:
    """Design load (N) of every net (``net NAME``), cell (its id) and input (``input NAME``):
    the largest force of the force budget through it, either way."""
    net = {name: max(_demand(part.data.get("demand", {}))) for name, part in mech.nets.items()}
    out = {f"net {k}": v for k, v in net.items()}
    out.update({f"input {k}": net.get(k, 0.0) for k in mech.inputs})
    for cid in mech.order:
        out[cid] = max(_demand(mech.cells[cid].data.get("output_demand", {})))
    for name, part in mech.nets.items():
        drv = part.data.get("driver", "")  # the driver moves the whole net
        if drv in mech.cells:
            out[drv] = max(out[drv], net[name])
        for load in part.data.get("loads", []):  # a load carries only its own rod's pull
            cid = load.rsplit(".", 1)[0]
            if cid in mech.cells:
                out[cid] = max(out[cid], *_share(mech, load))
    return out


def _parts(mech: Mechanism):
    """(where, part) for every part: inputs, cells, nets."""
    yield from ((f"input {k}", p) for k, p in mech.inputs.items())
    yield from ((cid, mech.cells[cid]) for cid in mech.order)
    yield from ((f"net {k}", p) for k, p in sorted(mech.nets.items()))


def push_rods(mech: Mechanism, loads: dict[str, float] | None = None) -> list[LoadedRod]:
    """Every rod of the mechanism (the nets' and the cells' own) with its length, cross-section
    and largest compressive load: the one place the strength checks read rods from.

    A net's rod ``rodK`` drives the net's K-th load (``data["loads"]``) and carries what that
    load asks in the force budget (its cell's input load plus guide friction): towards on it
    is pushed (compressed) when the load lies right of the fan-out bar (``pb`` right of
    ``pa``), towards off when the load lies left (a feedback rod). A cell's rods take the
    cell's load."""
    loads = part_loads(mech) if loads is None else loads
    ctx = mech.ctx
    rods = []
    for where, part in _parts(mech):
        ends = part.data.get("loads", [])
        if where.startswith("net "):  # a net's rods, pin to pin (pushrod bodies, or the
            for k, r in enumerate(net_rods(part)):  # rod joints of an earlier version)
                right, left = (_share(mech, ends[k]) if k < len(ends)
                               else (loads.get(where, 0.0),) * 2)
                guides = int(part.data.get("rod_guides", {}).get(r.id, 0))
                rods.append(LoadedRod(r.id, where, float(r.length), ctx.bar, ctx.thickness,
                                    right if r.pb[0] >= r.pa[0] else left, guides, True))
            continue
        for j in part.joints:
            if j.kind != "rod" or not j.length:
                continue
            load = loads.get(where, 0.0)
            net_rod = where.startswith("net ")
            if net_rod and len(ends) == len(part.joints):
                right, left = _share(mech, ends[part.joints.index(j)])
                load = right if j.pb[0] >= j.pa[0] else left
            guides = int(part.data.get("rod_guides", {}).get(j.id, 0)) if net_rod else 0
            rods.append(LoadedRod(j.id, where, float(j.length), ctx.bar, ctx.thickness, load,
                                guides, net_rod))
    return rods


def guides_needed(rod: LoadedRod, E: float) -> int:
    """Fewest guides that keep every span of a translating rod within its Euler length at
    ``BUCKLING_SAFETY``: L_max = pi sqrt(E I / (3 P)); none for a rod that holds as it is."""
    if not rod.guidable or rod.load <= 0.0:
        return 0
    b, h = max(rod.width, rod.thickness), min(rod.width, rod.thickness)
    l_max = math.pi * math.sqrt(E * b * h ** 3 / 12.0 / (BUCKLING_SAFETY * rod.load))
    return max(0, math.ceil(rod.length / l_max - 1e-9) - 1)


def guide_rods(mech: Mechanism, loads: dict[str, float]) -> None:
    """Give each net rod that would buckle over its whole length the guides it needs
    (``data["rod_guides"]`` of its net: rod id -> guides); a net rod translates, so a guide
    along its line constrains nothing the kinematics does not already hold."""
    E = material(mech.ctx.material).E
    for part in mech.nets.values():
        part.data.pop("rod_guides", None)
    for rod in push_rods(mech, loads):
        n = guides_needed(rod, E)
        if n:
            mech.nets[rod.where[4:]].data.setdefault("rod_guides", {})[rod.id] = n


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


def size_pins(mech: Mechanism, loads: dict[str, float]) -> None:
    """Give every pin joint and every fixed pivot of each part the pin its load needs."""
    ctx = mech.ctx
    for where, part in _parts(mech):
        set_pins(part, pin_diameter(loads.get(where, 0.0), ctx))


def set_pins(part: Part, d: float) -> None:
    """Every pin joint and every fixed pivot of ``part`` gets a pin of diameter ``d`` (mm)."""
    for j in part.joints:
        if j.kind in PIN_JOINTS:
            j.pin_diameter = d
    for b in part.bodies:
        if b.kind in PIVOTED:
            b.pin_diameter = d


def lever_arm(part: Part, lever: str, pivot: tuple[float, float]) -> float:
    """Farthest point (mm) from ``pivot`` at which a joint (rod, pin, slot, contact) acts on
    the lever ``lever``; cam and roller profiles (touch joints) are not bars and are left out."""
    pts = []
    for j in part.joints:
        if j.kind == "touch":
            continue
        if j.a == lever:
            pts += [p for p in (j.pa, j.p0, j.p1) if p is not None]
        if j.b == lever:
            pts += [p for p in (j.pb, j.q) if p is not None]
    return max((math.hypot(x - pivot[0], y - pivot[1]) for x, y in pts), default=0.0)


def _pins_of(part: Part) -> list[float]:
    return ([j.pin_diameter for j in part.joints if j.kind in PIN_JOINTS and j.pin_diameter]
            + [b.pin_diameter for b in part.bodies if b.kind in PIVOTED and b.pin_diameter])


def size_parts(mech: Mechanism) -> None:
    """Sizing for strength, at assembly: every part's pins from its load, guides along the net
    rods too long to carry theirs. The checks then judge the design as sized (and as loaded
    back from a file), so a part changed afterwards is judged, not sized again."""
    loads = part_loads(mech)
    size_pins(mech, loads)
    guide_rods(mech, loads)


def part_checks(where: str, part: Part, load: float, ctx: SynthContext) -> list[Check]:
    """One part's checks under its design load: axial stress, lever bending, pin shear and
    bearing (its pins as sized), spring wire stress."""
    mat = material(ctx.material)
    allow = plate_allowable(mat)
    out = [Check(f"axial stress ({mat.name}, {ctx.bar:g} x {ctx.thickness:g} mm bars)",
                 where, load / (ctx.bar * ctx.thickness), allow, "<=", "MPa")]
    for b in part.bodies:
        if b.kind == "lever" and b.pivot is not None and load > 0.0:
            arm = lever_arm(part, b.id, b.pivot)
            out.append(Check(f"lever bending ({arm:.3g} mm arm)", b.id,
                             6 * load * arm / (ctx.thickness * ctx.bar ** 2), allow, "<=",
                             "MPa"))
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
    return out


def rod_check(rod: LoadedRod, E: float) -> Check:
    """Euler buckling of one rod (over its span between guides) against its load."""
    p_cr = euler_load(E, rod.width, rod.thickness, rod.span)
    guided = (f", {rod.guides} guide{'s' if rod.guides > 1 else ''}: span "
              f"{rod.span:.4g} mm") if rod.guides else ""
    return Check(f"rod buckling (Euler, {rod.length:.4g} mm long{guided}) / load", rod.id,
                 p_cr / rod.load, BUCKLING_SAFETY, ">=", "x")


def cell_holds(where: str, part: Part, load: float, ctx: SynthContext) -> bool:
    """Whether a cell's part, alone, passes its strength checks under ``load`` (its pins
    sized for it, its own rods unguided): how the amplifier planner asks whether a cell can
    drive a net's demand before the mechanism is assembled."""
    set_pins(part, pin_diameter(load, ctx))
    if not all(c.passed for c in part_checks(where, part, load, ctx)):
        return False
    E = material(ctx.material).E
    return all(rod_check(LoadedRod(j.id, where, float(j.length), ctx.bar, ctx.thickness,
                                   load), E).passed
               for j in part.joints if j.kind == "rod" and j.length and load > 0.0)


def strength_checks(mech: Mechanism) -> list[Check]:
    """Every part: axial stress, lever bending, rod buckling, pin shear and bearing, spring wire
    stress."""
    ctx = mech.ctx
    E = material(ctx.material).E
    loads = part_loads(mech)
    out: list[Check] = []
    for where, part in _parts(mech):
        out += part_checks(where, part, loads.get(where, 0.0), ctx)
    out += [rod_check(rod, E) for rod in push_rods(mech, loads) if rod.load > 0.0]
    return out
