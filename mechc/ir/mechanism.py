"""The geometry data model: what a compiled design's JSON holds for every part.

Coordinates are millimetres in one world frame, given at each body's *design pose*: the pose
with every signal at half stroke (levers then stand symmetric about their centre lines, as the
dissertation draws its ternary links). A slider's displacement ``u`` and a lever's rotation
``theta`` are measured from that pose; a terminal's off and on positions are world points.
Forces are newtons, rates N/mm, masses kg.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from mechc.ir.check import Check

Point = tuple[float, float]
GROUND = "ground"


def _pt(p) -> Point:
    return (float(p[0]), float(p[1]))


def _r(p: Point | None, nd: int = 4):
    return None if p is None else [round(p[0], nd), round(p[1], nd)]


@dataclass
class Body:
    id: str
    kind: str  # "slider" (along axis) | "lever" (turns about pivot) | "link" (free in the
    #            plane; pivot is its reference point) | "rotor" (powered: turns at `speed`)
    outline: list[list[Point]]  # polygons, world mm at the design pose
    mass: float  # kg
    axis: Point | None = None  # slider: unit direction of travel, off -> on
    pivot: Point | None = None  # lever: fixed pivot
    layer: int = 0  # plane (parts on different layers may cross)
    role: str = ""
    poly_layers: list[int] | None = None  # per polygon, where pieces sit on other planes
    speed: float | None = None  # rotor: rad/s, counter-clockwise positive
    pin_diameter: float | None = None  # lever, rotor: mm, the pin of its fixed pivot

    def layer_of(self, i: int) -> int:
        return self.poly_layers[i] if self.poly_layers else self.layer

    def to_json(self) -> dict:
        d = {"id": self.id, "kind": self.kind, "role": self.role, "layer": self.layer,
             "mass_kg": round(self.mass, 7),
             "outline": [[_r(p, 3) for p in poly] for poly in self.outline]}
        if self.poly_layers:
            d["poly_layers"] = list(self.poly_layers)
        if self.axis is not None:
            d["axis"] = _r(self.axis, 6)
        if self.pivot is not None:
            d["pivot"] = _r(self.pivot)
        if self.speed is not None:
            d["speed_rad_s"] = round(self.speed, 6)
        if self.pin_diameter is not None:
            d["pin_diameter_mm"] = round(self.pin_diameter, 4)
        return d

    @staticmethod
    def from_json(d: dict) -> Body:
        return Body(d["id"], d["kind"], [[_pt(p) for p in poly] for poly in d["outline"]],
                    float(d["mass_kg"]), _pt(d["axis"]) if d.get("axis") else None,
                    _pt(d["pivot"]) if d.get("pivot") else None, int(d.get("layer", 0)),
                    d.get("role", ""), d.get("poly_layers"),
                    float(d["speed_rad_s"]) if d.get("speed_rad_s") is not None else None,
                    float(d["pin_diameter_mm"]) if d.get("pin_diameter_mm") is not None
                    else None)


@dataclass
class Joint:
    """A constraint between two bodies (``a`` or ``b`` may be ``"ground"``).

    - ``groove``: a straight slot on body a from ``p0`` to ``p1``; a pin on body b at ``q``.
    - ``rod``: a link of ``length`` pinned at ``pa`` on a and ``pb`` on b.
    - ``contact``: one-sided: the faces at ``pa`` (on a) and ``pb`` (on b) keep
      ``(pb - pa) . normal >= 0`` (a stop is a contact with the ground). ``driven`` names the
      body the contact positions (the other side's spring budget is the stronger one).
    - ``pin``: a and b turn about one shared point ``pa`` (a revolute pair between two bodies).
    - ``touch``: a shape contact with friction: on a, the polyline ``profile`` (a cam, a face) or
      a circle of ``radius_a`` about ``pa``; on b, a roller of radius ``length`` about ``q``.
      Used where the contact point travels (cams, friction rollers); the cell that owns it
      supplies the kinematics.

    ``pin_diameter``: the diameter (mm) of the pins a rod, pin or groove joint is made with
    (sized by the strength pass, ``mechc/passes/strength.py``).
    """

    id: str
    kind: str
    a: str
    b: str
    p0: Point | None = None
    p1: Point | None = None
    q: Point | None = None
    pa: Point | None = None
    pb: Point | None = None
    normal: Point | None = None
    length: float | None = None
    driven: str | None = None
    profile: list[Point] | None = None
    radius_a: float | None = None
    friction: float | None = None
    pin_diameter: float | None = None

    def to_json(self) -> dict:
        d = {"id": self.id, "kind": self.kind, "a": self.a, "b": self.b}
        if self.profile is not None:
            d["profile"] = [_r(p) for p in self.profile]
        if self.radius_a is not None:
            d["radius_a_mm"] = round(self.radius_a, 4)
        if self.friction is not None:
            d["friction"] = round(self.friction, 4)
        if self.driven is not None:
            d["driven"] = self.driven
        for k in ("p0", "p1", "q", "pa", "pb"):
            v = getattr(self, k)
            if v is not None:
                d[k] = _r(v)
        if self.normal is not None:
            d["normal"] = _r(self.normal, 6)
        if self.length is not None:
            d["length_mm"] = round(self.length, 4)
        if self.pin_diameter is not None:
            d["pin_diameter_mm"] = round(self.pin_diameter, 4)
        return d

    @staticmethod
    def from_json(d: dict) -> Joint:
        return Joint(d["id"], d["kind"], d["a"], d["b"],
                     *(_pt(d[k]) if d.get(k) is not None else None
                       for k in ("p0", "p1", "q", "pa", "pb", "normal")),
                     float(d["length_mm"]) if d.get("length_mm") is not None else None,
                     d.get("driven"),
                     [_pt(p) for p in d["profile"]] if d.get("profile") else None,
                     float(d["radius_a_mm"]) if d.get("radius_a_mm") is not None else None,
                     float(d["friction"]) if d.get("friction") is not None else None,
                     float(d["pin_diameter_mm"]) if d.get("pin_diameter_mm") is not None
                     else None)


@dataclass(frozen=True)
class Coil:
    """A helical spring as bought: music wire of diameter ``wire`` wound at mean diameter
    ``mean_diameter`` with ``active_coils`` turns; ``stress`` is the Wahl-corrected shear stress
    at the spring's largest force, ``allowable`` the torsional yield divided by the spring safety
    factor (see mechc/cells/springs.py)."""

    wire: float  # d, mm
    mean_diameter: float  # D, mm
    active_coils: float  # n
    free_length: float  # mm, body and hooks of an extension spring
    max_force: float  # N, the largest force it works at (preload + rate x travel)
    stress: float  # MPa at max_force
    allowable: float  # MPa
    kind: str = "extension"  # or "compression"

    @property
    def index(self) -> float:
        return self.mean_diameter / self.wire

    def to_json(self) -> dict:
        return {"wire_mm": round(self.wire, 4), "mean_diameter_mm": round(self.mean_diameter, 4),
                "index": round(self.index, 4), "active_coils": round(self.active_coils, 3),
                "free_length_mm": round(self.free_length, 3),
                "max_force_N": round(self.max_force, 4), "stress_MPa": round(self.stress, 3),
                "allowable_MPa": round(self.allowable, 3), "kind": self.kind,
                "wire": "music wire ASTM A228"}

    @staticmethod
    def from_json(d: dict) -> Coil:
        return Coil(float(d["wire_mm"]), float(d["mean_diameter_mm"]), float(d["active_coils"]),
                    float(d["free_length_mm"]), float(d["max_force_N"]), float(d["stress_MPa"]),
                    float(d["allowable_MPa"]), d.get("kind", "extension"))


@dataclass
class Spring:
    """A linear spring between ``pa`` on a and ``pb`` on b (tension if stretched past rest).

    ``max_force``: the largest force it sees in its working range (preload + rate x travel), set
    by whoever designs it; ``coil``: the wire and coils that give its rate at that force."""

    id: str
    a: str
    b: str
    pa: Point
    pb: Point
    rate: float  # N/mm
    rest: float  # mm
    damping: float = 0.0  # N s / mm
    preload: float = 0.0  # N at the spring's lightest working position (for the report)
    max_force: float | None = None  # N at its heaviest working position
    coil: Coil | None = None

    def to_json(self) -> dict:
        d = {"id": self.id, "a": self.a, "b": self.b, "pa": _r(self.pa), "pb": _r(self.pb),
             "rate_N_per_mm": round(self.rate, 6), "rest_length_mm": round(self.rest, 4),
             "damping_Ns_per_mm": round(self.damping, 7),
             "preload_N": round(self.preload, 4)}
        if self.max_force is not None:
            d["max_force_N"] = round(self.max_force, 4)
        if self.coil is not None:
            d["coil"] = self.coil.to_json()
        return d

    @staticmethod
    def from_json(d: dict) -> Spring:
        return Spring(d["id"], d["a"], d["b"], _pt(d["pa"]), _pt(d["pb"]),
                      float(d["rate_N_per_mm"]), float(d["rest_length_mm"]),
                      float(d.get("damping_Ns_per_mm", 0.0)), float(d.get("preload_N", 0.0)),
                      float(d["max_force_N"]) if d.get("max_force_N") is not None else None,
                      Coil.from_json(d["coil"]) if d.get("coil") else None)


@dataclass
class Terminal:
    """A pin of a cell: the point on ``body`` that carries the signal, off and on positions."""

    pin: str
    body: str
    kind: str  # "translating" | "rotating"
    off: Point
    on: Point
    at: Point | None = None  # the point at the design pose, when not midway (a toggle's throw)

    @property
    def design_point(self) -> Point:
        if self.at is not None:
            return self.at
        return ((self.off[0] + self.on[0]) / 2, (self.off[1] + self.on[1]) / 2)

    def to_json(self) -> dict:
        d = {"pin": self.pin, "body": self.body, "kind": self.kind, "off": _r(self.off),
             "on": _r(self.on)}
        if self.at is not None:
            d["at"] = _r(self.at)
        return d

    @staticmethod
    def from_json(d: dict) -> Terminal:
        return Terminal(d["pin"], d["body"], d.get("kind", "translating"), _pt(d["off"]),
                        _pt(d["on"]), _pt(d["at"]) if d.get("at") else None)


@dataclass
class Part:
    """Bodies, joints and springs: a cell's mechanism, or the connecting parts of a net."""

    bodies: list[Body] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    springs: list[Spring] = field(default_factory=list)
    terminals: dict[str, Terminal] = field(default_factory=dict)
    data: dict = field(default_factory=dict)  # cell-specific numbers (e.g. forces, cams)

    def to_json(self) -> dict:
        return {"bodies": [b.to_json() for b in self.bodies],
                "joints": [j.to_json() for j in self.joints],
                "springs": [s.to_json() for s in self.springs],
                "terminals": {k: t.to_json() for k, t in self.terminals.items()},
                "data": self.data}

    @staticmethod
    def from_json(d: dict) -> Part:
        return Part([Body.from_json(b) for b in d.get("bodies", [])],
                    [Joint.from_json(j) for j in d.get("joints", [])],
                    [Spring.from_json(s) for s in d.get("springs", [])],
                    {k: Terminal.from_json(t) for k, t in d.get("terminals", {}).items()},
                    dict(d.get("data", {})))

    def body(self, bid: str) -> Body:
        for b in self.bodies:
            if b.id == bid:
                return b
        raise KeyError(bid)


@dataclass(frozen=True)
class Demand:
    """Force (N) needed to move a signal body towards on (``right``) and towards off (``left``),
    beyond the body's own guide friction."""

    right: float = 0.0
    left: float = 0.0

    def __add__(self, o: Demand) -> Demand:
        return Demand(self.right + o.right, self.left + o.left)

    def reversed(self) -> Demand:
        return Demand(self.left, self.right)

    def to_json(self) -> dict:
        return {"right_N": round(self.right, 4), "left_N": round(self.left, 4)}


@dataclass(frozen=True)
class SynthContext:
    """Design rules shared by all cells (mm, N, kg)."""

    stroke: float = 20.0
    friction: float = 0.02  # N, guide friction of every slider (Coulomb)
    margin: float = 1.3  # spring preload >= margin x what it must move
    min_preload: float = 0.2  # N
    spring_range: float = 0.3  # k*S / preload: the force rises 30 % over the stroke
    thickness: float = 3.0  # mm plate
    density: float = 2.7e-6  # kg/mm^3 (aluminium; the plate material's, mechc/cells/materials.py)
    material: str = "aluminium"  # the plate material's name (--material)
    pin_diameter: float = 3.0  # mm, the smallest pin (pivots, rod ends, slot pins) made
    damping_ratio: float = 0.4
    overtravel: float = 0.02  # fraction of stroke a bar may pass its working range (a stop)
    clearance: float = 1.0  # mm between parts on one plane in every state (interference)
    angle_margin: float = 0.0  # degrees of transmission angle a cell that can keeps beyond
    # its design limit (robust design asks the threshold generators for it)

    @property
    def bar(self) -> float:
        """Width of bars and sliders."""
        return max(5.0, 0.3 * self.stroke)

    @property
    def pitch(self) -> float:
        """Vertical distance between input rows inside a cell."""
        return max(14.0, 0.9 * self.stroke)

    @property
    def arm(self) -> float:
        """Lever arm (pivot to pin): 1.5 S keeps the swing at ±19.5° (transmission ≥ 70°)."""
        return 1.5 * self.stroke

    def mass(self, polys: list[list[Point]]) -> float:
        return sum(abs(_area(p)) for p in polys) * self.thickness * self.density


def _area(poly: list[Point]) -> float:
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]))


@dataclass
class Mechanism:
    ctx: SynthContext
    cells: dict[str, Part]  # placed cell mechanisms
    inputs: dict[str, Part]  # input sliders (terminal pin = the input's name)
    nets: dict[str, Part]  # rods of each net (joints between bodies of different parts)
    outputs: dict[str, tuple[str, str]]  # output -> (owner: cell id or "in:NAME", pin)
    actuators: dict[str, dict]  # input -> rating and requirement
    order: list[str]  # cells in topological order
    checks: list[Check] = field(default_factory=list)

    def synthesis_checks(self) -> list[Check]:
        """The checks decided when the mechanism was sized (forces), not by a kinematic sweep."""
        return [c for c in self.checks if c.name in SYNTHESIS_CHECKS]

    def owner_part(self, owner: str) -> Part:
        return self.inputs[owner[3:]] if owner.startswith("in:") else self.cells[owner]

    def all_parts(self):
        yield from self.inputs.values()
        yield from (self.cells[c] for c in self.order)
        yield from self.nets.values()

    def body_index(self) -> dict:
        return {b.id: b for p in self.all_parts() for b in p.bodies}


SYNTHESIS_CHECKS = ("actuator force", "force budget converged")
