"""Pose traces: every body's pose in every case a proof visits (``mechc simulate --trace``).

A :class:`TraceRecorder` is handed to a proof through ``ProofSettings.trace``; the engines
feed it where their poses are — the closed form's ``Poses`` (kinematic level) and the pymunk
scene's bodies (dynamic level, as the scene's ``FrameSink``) — and :meth:`TraceRecorder.to_json`
gives the document ``mechc/schema/trace.schema.json`` describes (docs/trace.md). Nothing is
recorded unless a recorder is given.

One pose per body and sample, the same at both levels: a body's reference point ``ref`` (its
pivot, or a slider's outline centroid: the point the pymunk body stands for) and (dx, dy,
angle), so that a point p of the body at the design pose stands at

    R(angle)·(p − ref) + ref + (dx, dy)

— sliders translate (angle 0), levers turn about their pivot (dx = dy = 0), links do both.
The closed form's pose is read through the body kind's own ``position`` (of ``ref`` and of
``ref + (1, 0)``), so every body kind, present or future, is traced the same way.
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any

import numpy as np

from mechc import __version__
from mechc.errors import UsageError
from mechc.ir.mechanism import Body, Mechanism, Terminal
from mechc.logic.cubes import DC
from mechc.parts import body_kind
from mechc.parts.base import position
from mechc.parts.poses import Poses

if TYPE_CHECKING:  # typing only: the scene calls the recorder, never the other way round
    from mechc.physics.scene import Scene
    from mechc.proofs.report import ProofReport

FORMAT = "mechc-trace"
VERSION = 1
#: Default spacing (s of simulated time) of the dynamic level's samples: 500 frames a second,
#: enough to animate an 80 ms input move in 40 frames; the sorter's default proof traces to
#: about 1 MB (docs/trace.md).
EVERY_S = 0.002
#: Most body poses (bodies × samples) one trace holds, about 100 MB of JSON: beyond, the proof
#: stops with a usage error rather than fill the memory (a kinematic trace of ten inputs and a
#: hundred bodies would hold 11 million).
MAX_POSES = 5_000_000
MM_DIGITS = 4  # 0.1 µm
RAD_DIGITS = 6  # 1 µrad: 0.1 µm at 100 mm from the reference point
TIME_DIGITS = 6


class TraceRecorder:
    """Collects the cases of one proof, each a list of samples of every body's pose."""

    def __init__(self, mech: Mechanism, every: float = EVERY_S, move_time: float = 0.08,
                 max_poses: int = MAX_POSES):
        self.mech = mech
        self.max_poses = max_poses
        self.poses = 0  # body poses recorded so far
        self.every = every  # dynamic level: s between samples (the scene's FrameSink)
        self.move_time = move_time  # kinematic level: nominal s for a whole change
        self.owner: dict[str, str] = {}
        bodies: list[Body] = []
        for name, part in mech.inputs.items():
            self._own(bodies, part.bodies, f"in:{name}")
        for cid in mech.order:
            self._own(bodies, mech.cells[cid].bodies, cid)
        for net, part in sorted(mech.nets.items()):
            self._own(bodies, part.bodies, f"net:{net}")
        self.bodies = bodies
        self.row = {b.id: i for i, b in enumerate(bodies)}
        self.ref = np.array([reference_point(b) for b in bodies], dtype=float).reshape(-1, 2)
        self.cases: list[dict] = []
        self._open: dict | None = None
        self._taken: list[np.ndarray] = []
        self._ids: list[str] | None = None
        self._rows = np.zeros(0, dtype=np.int64)

    def _count(self, samples: int) -> None:
        self.poses += samples * len(self.bodies)
        if self.poses > self.max_poses:
            raise UsageError(f"the trace would hold more than {self.max_poses:,} body poses "
                             f"({len(self.bodies)} bodies per sample): trace fewer cases "
                             "(--cases), sample less often (--trace-every) or a smaller design")

    def _own(self, bodies: list[Body], part_bodies: list[Body], owner: str) -> None:
        for b in part_bodies:
            self.owner[b.id] = owner
            bodies.append(b)

    # ---- the closed form (kinematic level) ------------------------------------------------
    def frames_of(self, poses: Poses, size: int) -> np.ndarray:
        """(size, bodies, 3) poses (dx, dy, angle) of every body in ``poses``' states; NaN for
        a body the closed form did not place (or could not, in a state)."""
        out = np.full((size, len(self.bodies), 3), np.nan)
        for i, b in enumerate(self.bodies):
            rx, ry = self.ref[i]
            try:
                x0, y0 = position(b, poses, (rx, ry))
                x1, y1 = position(b, poses, (rx + 1.0, ry))
            except KeyError:  # not solved by this method
                continue
            out[:, i, 0] = np.broadcast_to(x0 - rx, (size,))
            out[:, i, 1] = np.broadcast_to(y0 - ry, (size,))
            out[:, i, 2] = np.broadcast_to(np.arctan2(y1 - y0, x1 - x0), (size,))
        return out

    def take(self, poses: Poses, size: int) -> None:
        """Keep the poses of states the sweep evaluates, in its order (``add_sweep``)."""
        self._count(size)
        self._taken.append(self.frames_of(poses, size))

    def add_sweep(self, sw: dict, spec) -> None:
        """The cases of a kinematic sweep (``mechc.proofs.kinematic.sweep``, whose states
        were kept by ``take``): every rest state, then every single-input change from the
        moving input off to on at ``sw["samples"]`` points."""
        frames = np.concatenate(self._taken) if self._taken else np.zeros((0, 0, 3))
        self._taken = []
        names = sw["names"]
        rest_bits, edge_bits, e_k, samples = (sw["rest_bits"], sw["edge_bits"], sw["e_k"],
                                              sw["samples"])
        n_rest = rest_bits.shape[1]
        if len(frames) != n_rest + len(e_k) * samples:
            raise ValueError("the sweep's states and the recorded poses differ in number")
        rest_want = spec.values_at(rest_bits)
        hi_bits = edge_bits.copy()
        hi_bits[e_k, np.arange(len(e_k))] = True
        lo_want, hi_want = spec.values_at(edge_bits), spec.values_at(hi_bits)
        for i in range(n_rest):
            ins = _bits(rest_bits[:, i], names)
            want = {o: v[i] for o, v in rest_want.items()}
            self._append("rest", None, ins, ins, want, want, [0.0], [1.0], frames[i:i + 1])
        frac = np.linspace(0.0, 1.0, samples)
        for j in range(len(e_k)):
            s = n_rest + j * samples
            self._append("change", names[e_k[j]], _bits(edge_bits[:, j], names),
                         _bits(hi_bits[:, j], names), {o: v[j] for o, v in lo_want.items()},
                         {o: v[j] for o, v in hi_want.items()}, frac * self.move_time, frac,
                         frames[s:s + samples])

    def add(self, kind: str, moving: str | None, before: dict, after: dict,
            expected_before: dict, expected_after: dict, t, frac, frames: np.ndarray,
            **extra: Any) -> None:
        """One case with all its samples (``frames``: (samples, bodies, 3))."""
        self._count(len(frames))
        self._append(kind, moving, before, after, expected_before, expected_after, t, frac,
                     frames, **extra)

    def _append(self, kind: str, moving: str | None, before: dict, after: dict,
                expected_before: dict, expected_after: dict, t, frac, frames: np.ndarray,
                **extra: Any) -> None:
        self.cases.append({**_case_head(len(self.cases), kind, moving, before, after,
                                        expected_before, expected_after, extra),
                           "t": _round(np.asarray(t, dtype=float), TIME_DIGITS),
                           "frac": _round(np.asarray(frac, dtype=float), TIME_DIGITS),
                           "poses": _poses(frames)})

    # ---- the pymunk scene (dynamic level) ---------------------------------------------------
    def begin(self, kind: str, moving: str | None, before: dict, after: dict,
              expected_before: dict, expected_after: dict, **extra: Any) -> None:
        """Open a case; the scene's samples (``sample``) go to it until ``end``."""
        self._open = {"head": _case_head(len(self.cases), kind, moving, before, after,
                                         expected_before, expected_after, extra),
                      "t": [], "frac": [], "frames": []}

    def sample(self, scene: Scene, t: float, frac: float) -> None:
        """Every body's pose in ``scene`` now (the scene's ``FrameSink``); a body the scene
        does not hold is NaN."""
        if self._open is None:
            return
        self._count(1)
        ids, pos, ang = scene.frames()
        if ids is not self._ids:  # a new scene: where its bodies go in the trace's order
            self._ids = ids
            self._rows = np.array([self.row.get(b, -1) for b in ids], dtype=np.int64)
        keep = self._rows >= 0
        rows = self._rows[keep]
        frame = np.full((len(self.bodies), 3), np.nan)
        frame[rows, :2] = pos[keep] - self.ref[rows]
        frame[rows, 2] = ang[keep]
        self._open["t"].append(t)
        self._open["frac"].append(frac)
        self._open["frames"].append(frame)

    def end(self) -> None:
        c, self._open = self._open, None
        if c is None:
            return
        frames = np.array(c["frames"]).reshape(-1, len(self.bodies), 3)
        self.cases.append({**c["head"], "t": _round(np.array(c["t"]), TIME_DIGITS),
                           "frac": _round(np.array(c["frac"]), TIME_DIGITS),
                           "poses": _poses(frames)})

    # ---- the document -----------------------------------------------------------------------
    def to_json(self, report: ProofReport, inputs: list[str], outputs: list[str],
                source: dict | None = None) -> dict:
        """The trace document (``mechc/schema/trace.schema.json``)."""
        mech = self.mech
        settings = report.figures.get("settings") if report.level == "dynamic" else None
        return {
            "format": FORMAT, "version": VERSION, "generator": f"mechc {__version__}",
            "level": report.level, "kind": report.kind,
            "units": {"length": "mm", "angle": "rad", "time": "s"},
            "stroke_mm": mech.ctx.stroke,
            "sampling": ({"every_s": self.every, "settings": settings} if settings is not None
                         else {"move_time_s": self.move_time}),
            "proof": {"passed": report.passed, "cases": report.cases,
                      "failure_count": report.failure_count},
            "source": dict(source or {}),
            "inputs": list(inputs), "outputs": list(outputs),
            "bodies": [_body_json(b, self.owner[b.id], self.ref[i])
                       for i, b in enumerate(self.bodies)],
            "terminals": {
                "inputs": {n: _terminal_json(mech.inputs[n].terminals[n]) for n in inputs},
                "outputs": {o: _terminal_json(mech.owner_part(mech.outputs[o][0])
                                              .terminals[mech.outputs[o][1]])
                            for o in outputs},
            },
            "cases": self.cases,
        }


def reference_point(b: Body) -> tuple[float, float]:
    """The point a body's pose is given about: the one its pymunk body stands for (a lever's
    or link's pivot, a slider's outline centroid), else its outline centroid."""
    ref = body_kind(b.kind).scene_ref(b)
    if ref is None:
        pts = [p for poly in b.outline for p in poly]
        ref = (sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts))
    return (float(ref[0]), float(ref[1]))


def dumps(doc: dict) -> str:
    """Compact JSON with one case per line (a trace is mostly numbers; indenting each one
    would multiply its size)."""
    head = {k: v for k, v in doc.items() if k != "cases"}
    text = json.dumps(head, ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    cases = ",\n".join(json.dumps(c, ensure_ascii=False, separators=(",", ":"),
                                  allow_nan=False) for c in doc.get("cases", []))
    return text[:-1] + ',\n"cases":[\n' + cases + "\n]}\n"


@lru_cache(maxsize=1)
def schema() -> dict:
    """The trace's JSON Schema, shipped with the package."""
    return json.loads(resources.files("mechc").joinpath("schema/trace.schema.json").read_text())


def _case_head(index: int, kind: str, moving: str | None, before: dict, after: dict,
               expected_before: dict, expected_after: dict, extra: dict) -> dict:
    return {"index": index, "kind": kind, **extra, "moving": moving,
            "inputs_before": {k: int(v) for k, v in before.items()},
            "inputs_after": {k: int(v) for k, v in after.items()},
            "expected_before": {k: _value(v) for k, v in expected_before.items()},
            "expected_after": {k: _value(v) for k, v in expected_after.items()}}


def _value(v) -> int | None:
    return None if v is None or int(v) == DC else int(v)


def _bits(column: np.ndarray, names: list[str]) -> dict[str, int]:
    return {nm: int(column[k]) for k, nm in enumerate(names)}


def _round(a: np.ndarray, digits: int) -> list:
    r = np.round(a, digits)
    if np.isfinite(r).all():
        return r.tolist()
    return np.where(np.isfinite(r), r, None).tolist()


def _poses(frames: np.ndarray) -> list:
    """[[[dx, dy, angle] per body] per sample], mm rounded to 0.1 µm, rad to 1 µrad."""
    f = np.array(frames, dtype=float)
    f[..., :2] = np.round(f[..., :2], MM_DIGITS)
    f[..., 2] = np.round(f[..., 2], RAD_DIGITS)
    f += 0.0  # no negative zeros
    if np.isfinite(f).all():
        return f.tolist()
    return np.where(np.isfinite(f), f, None).tolist()


def _pt(p) -> list[float]:
    return [round(float(p[0]), 6), round(float(p[1]), 6)]


def _body_json(b: Body, owner: str, ref) -> dict:
    d = {"id": b.id, "kind": b.kind, "role": b.role, "owner": owner, "layer": b.layer,
         "ref": _pt(ref),
         "outline": [[_pt(p) for p in poly] for poly in b.outline]}
    if b.poly_layers:
        d["poly_layers"] = list(b.poly_layers)
    if b.axis is not None:
        d["axis"] = _pt(b.axis)
    if b.pivot is not None:
        d["pivot"] = _pt(b.pivot)
    return d


def _terminal_json(t: Terminal) -> dict:
    return {"body": t.body, "point": _pt(t.design_point), "off": _pt(t.off), "on": _pt(t.on)}
