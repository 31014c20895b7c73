"""The animation of a design, read from pose traces: what the viewer page (``viewer.py``) and
the GIF (``gif.py``) both show.

A trace (``mechc simulate --trace``, docs/trace.md) lists cases: rest states and single-input
changes, each a run of samples of every body's pose. This module turns one or two traces into
a small graph a user can walk by clicking inputs:

- a *node* is a stable state: the input values (and, for a sequential design, the spec's state
  after them), with the output values the spec asks for there;
- an *edge* is a change of one input from a node: a case of the trace played forward, or (for
  a combinational design at the kinematic level, where a pose depends on the inputs alone) a
  change from the other side played backward;
- the *tour* is what "play" shows: every input state in Gray-code order for a combinational
  kinematic trace, else the proof's own cases in their order.

Poses are the trace's ``[dx, dy, angle]`` per body about the body's ``ref`` point; between two
samples a pose is interpolated linearly (the samples are 1/20 of a stroke apart).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: Seconds of simulated time a rest state is held between two changes of the tour.
HOLD_S = 0.04


@dataclass
class Segment:
    """One piece of the tour: a case played forward or backward, or a hold of one pose."""

    case: int  # index into Animation.cases
    reverse: bool
    start: int  # node before
    end: int  # node after
    hold: bool = False  # a still pose (the case's last sample, or its first if reversed)

    def duration(self, cases: list[dict]) -> float:
        t = cases[self.case]["t"]
        return HOLD_S if self.hold else max(float(t[-1] - t[0]), 1e-6)


@dataclass
class Animation:
    """Bodies, cases (the traces' samples) and the graph of states between them."""

    level: str
    kind: str
    inputs: list[str]
    outputs: list[str]
    stroke: float
    bodies: list[dict]  # the trace's bodies
    terminals: dict  # the trace's terminals
    cases: list[dict] = field(default_factory=list)  # {"t": array, "poses": (n, bodies, 3)}
    nodes: list[dict] = field(default_factory=list)  # inputs, state, expected, case, sample
    edges: dict[int, dict[str, dict]] = field(default_factory=dict)  # node -> input -> edge
    tour: list[Segment] = field(default_factory=list)
    cells: list[dict] = field(default_factory=list)  # id, type, box (design pose)
    title: str = ""
    proof: dict = field(default_factory=dict)

    # ---- poses ------------------------------------------------------------------------------
    def pose_at(self, seg: Segment, tau: float) -> np.ndarray:
        """(bodies, 3) poses ``tau`` seconds into ``seg``."""
        c = self.cases[seg.case]
        t, poses = c["t"], c["poses"]
        if seg.hold:
            return poses[0 if seg.reverse else -1]
        if seg.reverse:
            tau = float(t[-1]) - tau
        else:
            tau = float(t[0]) + tau
        k = int(np.searchsorted(t, tau, side="right"))
        if k <= 0:
            return poses[0]
        if k >= len(t):
            return poses[-1]
        w = (tau - t[k - 1]) / max(t[k] - t[k - 1], 1e-12)
        return poses[k - 1] * (1 - w) + poses[k] * w

    def world(self, poses: np.ndarray) -> list[list[np.ndarray]]:
        """Every body's polygons (world mm) at ``poses``; a body with no pose (NaN) stays at
        its design pose."""
        out = []
        for b, (dx, dy, a) in zip(self.bodies, poses):
            if not (math.isfinite(dx) and math.isfinite(dy) and math.isfinite(a)):
                dx = dy = a = 0.0
            c, s = math.cos(a), math.sin(a)
            rx, ry = b["ref"]
            polys = []
            for poly in b["outline"]:
                p = np.asarray(poly, dtype=float) - (rx, ry)
                polys.append(np.column_stack((c * p[:, 0] - s * p[:, 1] + rx + dx,
                                              s * p[:, 0] + c * p[:, 1] + ry + dy)))
            out.append(polys)
        return out

    def point_at(self, poses: np.ndarray, body: str, p) -> tuple[float, float]:
        """Where design point ``p`` of ``body`` stands at ``poses`` (its design place where
        the body has no pose)."""
        i = self._row()[body]
        dx, dy, a = poses[i]
        if not (math.isfinite(dx) and math.isfinite(dy) and math.isfinite(a)):
            return float(p[0]), float(p[1])
        rx, ry = self.bodies[i]["ref"]
        px, py = p[0] - rx, p[1] - ry
        return (math.cos(a) * px - math.sin(a) * py + rx + dx,
                math.sin(a) * px + math.cos(a) * py + ry + dy)

    def _row(self) -> dict[str, int]:
        return {b["id"]: i for i, b in enumerate(self.bodies)}

    def signals(self, poses: np.ndarray, which: str = "outputs") -> dict[str, float]:
        """Each terminal's signal (0 off, 1 on) at ``poses`` (the rule of docs/trace.md)."""
        out = {}
        for name, t in self.terminals[which].items():
            x, y = self.point_at(poses, t["body"], t["point"])
            (ox, oy), (nx, ny) = t["off"], t["on"]
            d2 = (nx - ox) ** 2 + (ny - oy) ** 2
            out[name] = ((x - ox) * (nx - ox) + (y - oy) * (ny - oy)) / d2
        return out

    def tour_duration(self) -> float:
        return sum(s.duration(self.cases) for s in self.tour)


def build(trace: dict, dynamic: dict | None = None, cell_types: dict[str, str] | None = None,
          title: str = "") -> Animation:
    """The animation of a kinematic ``trace`` (every state and change the proof visits); with
    a ``dynamic`` trace of the same design, its changes are played where it has them (the tour
    is its run) and the closed form's elsewhere."""
    if trace.get("level") != "kinematic":
        raise ValueError("the state graph is built from a kinematic trace")
    anim = Animation(level="dynamic" if dynamic else "kinematic", kind=trace["kind"],
                     inputs=list(trace["inputs"]), outputs=list(trace["outputs"]),
                     stroke=float(trace["stroke_mm"]), bodies=trace["bodies"],
                     terminals=trace["terminals"], title=title,
                     proof={"kinematic": trace["proof"]})
    nodes: dict[tuple, int] = {}

    def node(inputs: dict, state: str | None, expected: dict, case: int, sample: int) -> int:
        key = (tuple(int(inputs[n]) for n in anim.inputs), state)
        if key not in nodes:
            nodes[key] = len(anim.nodes)
            anim.nodes.append({"inputs": {n: int(inputs[n]) for n in anim.inputs},
                               "state": state, "expected": dict(expected),
                               "case": case, "sample": sample})
        return nodes[key]

    def add_case(c: dict) -> int:
        anim.cases.append({"t": np.asarray(c["t"], dtype=float),
                           "poses": np.asarray(c["poses"], dtype=float).reshape(
                               len(c["t"]), len(anim.bodies), 3)})
        return len(anim.cases) - 1

    def edge(a: int, name: str, case: int, reverse: bool, b: int, level: str) -> None:
        """The first case of a change is kept; a dynamic run's replaces the closed form's."""
        mine = anim.edges.setdefault(a, {})
        old = mine.get(name)
        if old is None or (old["level"] == "kinematic" and level == "dynamic"):
            mine[name] = {"case": case, "reverse": reverse, "to": b, "level": level}

    kin_cases = _walk(trace, add_case, node, edge, "kinematic", both_ways=(
        trace["kind"] == "combinational"))
    if dynamic is not None:
        anim.proof["dynamic"] = dynamic["proof"]
        if [b["id"] for b in dynamic["bodies"]] != [b["id"] for b in anim.bodies]:
            raise ValueError("the dynamic trace is of another design (its bodies differ)")
        dyn_cases = _walk(dynamic, add_case, node, edge, "dynamic", both_ways=False)
        anim.tour = _trace_tour(dyn_cases)
    elif trace["kind"] == "combinational" and len(anim.inputs) <= 10:
        anim.tour = _gray_tour(anim, nodes)
    else:
        anim.tour = _trace_tour(kin_cases)
    anim.cells = _cells(anim.bodies, cell_types or {})
    return anim


def _walk(trace: dict, add_case, node, edge, level: str, both_ways: bool) -> list[tuple]:
    """Add a trace's cases, nodes and edges; returns (case, start, end, kind) in its order."""
    seq = trace["kind"] == "sequential"
    out = []
    last_state: dict[int, str | None] = {}
    for c in trace["cases"]:
        ci = add_case(c)
        n = len(c["t"])
        state = c.get("expected_state") if seq else None
        if c["kind"] == "rest" or c.get("moving") is None:
            a = b = node(c["inputs_after"], state, c["expected_after"], ci, n - 1)
        else:
            before = last_state.get(c.get("sequence", 0)) if seq else None
            a = node(c["inputs_before"], before, c["expected_before"], ci, 0)
            b = node(c["inputs_after"], state, c["expected_after"], ci, n - 1)
            edge(a, c["moving"], ci, False, b, level)
            if both_ways:
                edge(b, c["moving"], ci, True, a, level)
        if seq:
            last_state[c.get("sequence", 0)] = state
        out.append((ci, a, b, c["kind"]))
    return out


def _gray_tour(anim: Animation, nodes: dict[tuple, int]) -> list[Segment]:
    """Every input state once, one input changing per step (reflected Gray code), each change
    followed by a hold; starts at every input off."""
    n = len(anim.inputs)
    segs: list[Segment] = []
    prev, prev_g = None, 0
    for i in range(1 << n):
        g = i ^ (i >> 1)
        key = (tuple((g >> (n - 1 - k)) & 1 for k in range(n)), None)
        cur = nodes.get(key)
        if cur is None:
            return segs
        if prev is not None:
            bit = (g ^ prev_g).bit_length() - 1  # 0: the last input
            name = anim.inputs[n - 1 - bit]
            e = anim.edges.get(prev, {}).get(name)
            if e is None:
                return segs
            segs.append(Segment(e["case"], e["reverse"], prev, cur))
        nd = anim.nodes[cur]
        segs.append(Segment(nd["case"], False, cur, cur, hold=True) if prev is None else
                    Segment(segs[-1].case, segs[-1].reverse, cur, cur, hold=True))
        prev, prev_g = cur, g
    return segs


def _trace_tour(cases: list[tuple]) -> list[Segment]:
    """The trace's cases in order, each change followed by a hold of its end."""
    segs = []
    if cases and cases[0][3] != "rest":  # begin still, at the first change's start
        segs.append(Segment(cases[0][0], True, cases[0][1], cases[0][1], hold=True))
    for ci, a, b, kind in cases:
        if kind != "rest":
            segs.append(Segment(ci, False, a, b))
        segs.append(Segment(ci, False, b, b, hold=True))
    return segs


def _cells(bodies: list[dict], types: dict[str, str]) -> list[dict]:
    """Each cell's box at the design pose (its own bodies' outlines), for labels."""
    boxes: dict[str, list[float]] = {}
    for b in bodies:
        own = b["owner"]
        if own.startswith(("in:", "net:")):
            continue
        planes = b.get("poly_layers") or [b["layer"]] * len(b["outline"])
        # not the fan-out bars a net adds to a cell's output body (on the net's plane)
        own_polys = [poly for pl, poly in zip(planes, b["outline"]) if pl == b["layer"]]
        pts = np.array([p for poly in own_polys or b["outline"] for p in poly], dtype=float)
        x0, y0 = pts.min(axis=0)
        x1, y1 = pts.max(axis=0)
        bx = boxes.setdefault(own, [x0, y0, x1, y1])
        bx[:] = [min(bx[0], x0), min(bx[1], y0), max(bx[2], x1), max(bx[3], y1)]
    return [{"id": cid, "type": types.get(cid, ""), "box": [round(v, 3) for v in bx]}
            for cid, bx in boxes.items()]
