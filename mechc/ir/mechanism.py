"""The geometry data model: what a compiled design's JSON holds for every part.

Coordinates are millimetres in one world frame, given at each body's *design pose*: the pose
with every signal at half stroke (levers then stand symmetric about their centre lines, as the
dissertation draws its ternary links). A slider's displacement ``u`` and a lever's rotation
``theta`` are measured from that pose; a terminal's off and on positions are world points.
Forces are newtons, rates N/mm, masses kg.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

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
        return d

    @staticmethod
    def from_json(d: dict) -> Body:
        return Body(d["id"], d["kind"], [[_pt(p) for p in poly] for poly in d["outline"]],
                    float(d["mass_kg"]), _pt(d["axis"]) if d.get("axis") else None,
                    _pt(d["pivot"]) if d.get("pivot") else None, int(d.get("layer", 0)),
                    d.get("role", ""), d.get("poly_layers"),
                    float(d["speed_rad_s"]) if d.get("speed_rad_s") is not None else None)


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
                     float(d["friction"]) if d.get("friction") is not None else None)


@dataclass
class Spring:
    """A linear spring between ``pa`` on a and ``pb`` on b (tension if stretched past rest)."""

    id: str
    a: str
    b: str
    pa: Point
    pb: Point
    rate: float  # N/mm
    rest: float  # mm
    damping: float = 0.0  # N s / mm
    preload: float = 0.0  # N at the spring's lightest working position (for the report)

    def to_json(self) -> dict:
        return {"id": self.id, "a": self.a, "b": self.b, "pa": _r(self.pa), "pb": _r(self.pb),
                "rate_N_per_mm": round(self.rate, 6), "rest_length_mm": round(self.rest, 4),
                "damping_Ns_per_mm": round(self.damping, 7),
                "preload_N": round(self.preload, 4)}

    @staticmethod
    def from_json(d: dict) -> Spring:
        return Spring(d["id"], d["a"], d["b"], _pt(d["pa"]), _pt(d["pb"]),
                      float(d["rate_N_per_mm"]), float(d["rest_length_mm"]),
                      float(d.get("damping_Ns_per_mm", 0.0)), float(d.get("preload_N", 0.0)))


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
class Check:
    """A design check with the number that decides it."""

    name: str
    where: str
    value: float
    limit: float
    sense: str  # ">=" or "<="
    unit: str = ""

    @property
    def passed(self) -> bool:
        v = self.value
        if v != v:  # NaN never passes
            return False
        return bool(v >= self.limit if self.sense == ">=" else v <= self.limit)

    def to_json(self) -> dict:
        return {"name": self.name, "where": self.where, "value": round(float(self.value), 4),
                "limit": self.limit, "sense": self.sense, "unit": self.unit,
                "passed": self.passed}

    def text(self) -> str:
        return (f"{self.name} at {self.where}: {self.value:.4g}{self.unit} "
                f"(limit {self.sense} {self.limit:g}{self.unit})")


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


def check_list_json(checks: list[Check]) -> list[dict]:
    return [c.to_json() for c in checks]


def asjson(obj) -> dict:
    return asdict(obj)
