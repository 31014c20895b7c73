"""Cell characterisation: a cell's timing measured once in pymunk, kept as a small table.

Electronic design times a chip from per-cell tables (delay and slew against input slew and
load) instead of simulating it whole; this module makes those tables for mechc's cells. A cell
(type x fan-in x parameters x stroke) is compiled alone (as :mod:`mechc.cells.prove_cell`
does), and every single-input change that switches its output is run on its pymunk scene over
a small grid of input move times (the input's speed) and masses added to the output body (the
load its net drives). Per grid point, the worst change gives:

- ``lag_s``: how much later the output crosses mid-stroke than the closed form (the
  quasi-static linkage) says, the dynamic part of its switching time;
- ``settle_extra_s``: how much later the output stays within ``SETTLED`` of its end
  position than the closed form's output does;
- ``overshoot``: the largest excursion beyond the end position (fraction of stroke);
- ``force_N``: the peak inertial force on the output body (its mass with the load times its
  peak acceleration), what the cell must deliver to switch its load at that speed.

A linkage gate is quasi-static, so the table of the cell compiled alone serves every instance:
the stdlib's ship with mechc (``characterised.json``, written by ``mechc cells characterise``,
each with the SHA-256 of the cell file measured), any other is measured on first use and
cached in ``$MECHC_CACHE_DIR`` (default ``$XDG_CACHE_HOME/mechc/cells`` or
``~/.cache/mechc/cells``). A cell with a switching delay of its own (a powered AMPLIFIER) lands
as the springs and dashpot compile sized for its loads make it: it is measured as the design
built it, on a scene of that cell in the design, and cached under the hash of that geometry
less its placement (:func:`table_key`).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mechc.cells.cell import Cell
from mechc.cells.library import Library
from mechc.cells.prove_cell import alone
from mechc.parts.poses import Poses
from mechc.physics.scene import MOVE_SAMPLES, DynSettings, Scene

#: Bump when what is measured or how changes: older tables are then measured again.
VERSION = 4
#: Input move times (s) of the grid: 2x faster and 2x slower than the proofs' default 0.08 s.
MOVE_TIMES = (0.04, 0.08, 0.16)
#: Masses (kg) added to the output body: none, about one load's slider and rod, about three.
LOADS = (0.0, 0.03, 0.09)
#: An output within this fraction of stroke of its end position has settled (the dynamic
#: proof's own threshold, ``mechc.physics.scene.Scene.move``).
SETTLED = 0.005
#: Logic types a cell cannot be characterised alone for: stateful, or without inputs.
UNTIMED = frozenset({"MEMORY", "CONST"})
SHIPPED = Path(__file__).with_name("characterised.json")
FIGURES = ("lag_s", "settle_extra_s", "overshoot", "force_N")
#: Figures also kept per direction of the output's switch, ``lag_on_s`` for the output
#: switching on, ``lag_off_s`` off (a bar moved by its spring one way and pushed by its inputs
#: the other lags differently each way; ``lag_s`` is the worse of the two). A table without
#: them (an older one) serves both directions with the worse.
DIRECTED = ("lag_s", "settle_extra_s")
#: Times (s) from the output's mid-stroke crossing at which a cell's *landing* is kept: its
#: output's share of the way from start to end (``CellTable.shapes``). A cell timed as built
#: (an amplifier) is a step in the closed form; what follows it is driven by this shape.
SHAPE_T = tuple(round(-0.06 + 0.005 * k, 3) for k in range(63))

#: Called as (done, total) while a cell is measured.
OnProgress = Callable[[int, int], None]


@dataclass
class CellTable:
    """One cell's timing table: ``values[figure]`` is a (move times x loads) grid."""

    key: str
    cell: str
    type: str
    n: int
    params: dict
    stroke: float
    move_times: tuple[float, ...]
    loads: tuple[float, ...]
    values: dict[str, list[list[float]]]
    changes: int  # switching changes measured per grid point
    seconds: float = 0.0
    sha: str = ""  # the cell file's SHA-256 when it was measured
    as_built: bool = False  # measured on the cell as a design built it (not compiled alone)
    #: per direction ("on", "off"): a (move times x loads) grid of the output's landing, its
    #: share of the way at each of ``SHAPE_T`` from its crossing (None: not measured)
    shapes: dict[str, list[list[list[float]]]] | None = None

    def at(self, move_time: float, load: float) -> dict[str, float]:
        """Every figure at ``move_time`` and ``load``, bilinear between grid points and held
        at the grid's edge outside it (a cell is never extrapolated)."""
        w = _weights(self.move_times, self.loads, move_time, load)
        return {name: float(sum(f * grid[i][j] for (i, j), f in w))
                for name, grid in self.values.items()}

    def shape(self, on: bool, move_time: float, load: float) -> np.ndarray | None:
        """The output's landing switching ``on`` (or off) at ``move_time`` and ``load``, at
        each of ``SHAPE_T`` from its crossing; bilinear between grid points as :meth:`at`
        (None when the table has none)."""
        if not self.shapes:
            return None
        # a way no move measured lands like the other (a table shared by geometry)
        grid = self.shapes.get("on" if on else "off") or next(iter(self.shapes.values()))
        w = _weights(self.move_times, self.loads, move_time, load)
        return sum(f * np.asarray(grid[i][j], dtype=float) for (i, j), f in w)

    def to_json(self) -> dict:
        return {"key": self.key, "cell": self.cell, "type": self.type, "n": self.n,
                "params": self.params, "stroke": self.stroke,
                "move_times_s": list(self.move_times), "loads_kg": list(self.loads),
                "values": self.values, "changes": self.changes,
                "seconds": round(self.seconds, 3), "source_sha256": self.sha,
                "as_built": self.as_built,
                **({"shapes": self.shapes} if self.shapes is not None else {})}

    @staticmethod
    def from_json(d: dict) -> CellTable:
        return CellTable(d["key"], d["cell"], d["type"], int(d["n"]), dict(d["params"]),
                         float(d["stroke"]), tuple(d["move_times_s"]), tuple(d["loads_kg"]),
                         {k: [list(map(float, r)) for r in v] for k, v in d["values"].items()},
                         int(d["changes"]), float(d.get("seconds", 0.0)),
                         d.get("source_sha256", ""), bool(d.get("as_built", False)),
                         d.get("shapes"))


def _weights(move_times, loads, move_time: float, load: float
             ) -> list[tuple[tuple[int, int], float]]:
    """The grid points and weights of a bilinear read-out at (``move_time``, ``load``), held
    at the grid's edge outside it."""
    mt = np.asarray(move_times, dtype=float)
    ld = np.asarray(loads, dtype=float)
    x = float(np.clip(move_time, mt[0], mt[-1]))
    y = float(np.clip(load, ld[0], ld[-1]))
    i = int(np.clip(np.searchsorted(mt, x) - 1, 0, len(mt) - 2))
    j = int(np.clip(np.searchsorted(ld, y) - 1, 0, len(ld) - 2))
    fx = (x - mt[i]) / (mt[i + 1] - mt[i])
    fy = (y - ld[j]) / (ld[j + 1] - ld[j])
    return [((i, j), (1 - fx) * (1 - fy)), ((i + 1, j), fx * (1 - fy)),
            ((i, j + 1), (1 - fx) * fy), ((i + 1, j + 1), fx * fy)]


def cache_dir() -> Path:
    """Where measured tables of user cells are kept (``MECHC_CACHE_DIR`` overrides)."""
    env = os.environ.get("MECHC_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "mechc" / "cells"


#: Keys of a part's JSON that say where it stands, not what it is (left out of its hash).
PLACEMENT_KEYS = frozenset({"outline", "pivot", "p0", "p1", "q", "pa", "pb", "profile", "off",
                            "on", "at", "id", "a", "b", "body"})


def geometry_of(part_json: dict) -> object:
    """A part's geometry less its placement: masses, axes, lengths, springs, the cell's own
    numbers (two instances sized alike hash alike wherever they are placed)."""
    if isinstance(part_json, dict):
        return {k: geometry_of(v) for k, v in sorted(part_json.items())
                if k not in PLACEMENT_KEYS}
    if isinstance(part_json, list):
        return [geometry_of(v) for v in part_json]
    if isinstance(part_json, float):
        return round(part_json, 6)
    return part_json


def table_key(cls: type[Cell], type_name: str, n: int, params: dict, stroke: float,
              part_json: dict) -> str:
    """The hash a table is kept under: the cell's file and name, what it is asked to be, and
    the geometry it was built with (a changed spring or lever gets a new table)."""
    text = json.dumps({"v": VERSION, "cell": cls.name, "sha": cls.source_sha256,
                       "type": type_name, "n": n, "params": params, "stroke": stroke,
                       "grid": [MOVE_TIMES, LOADS], "geometry": geometry_of(part_json)},
                      sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def switching_changes(table: np.ndarray, n: int) -> list[tuple[int, int]]:
    """(from row, to row) of every single-input change that moves the output."""
    out = []
    for row in range(1 << n):
        for k in range(n):
            to = row ^ (1 << (n - 1 - k))
            if table[row] != table[to]:
                out.append((row, to))
    return out


@dataclass
class Move:
    """One change a cell is timed on: the whole design's inputs at the start, the input that
    moves and where to."""

    start: dict[str, float]
    name: str
    target: float
    #: the closed form of the cell's inputs jumps on this move (a cell timed as built, whose
    #: closed form is a step, switches before it): the scene's boundary is then driven along
    #: a straight ramp from the move's start pose to its end pose, so that the cell is timed
    #: on inputs that move over the move time as the grid says, not all at once
    ramp: bool = False


def measure(cls: type[Cell], lib: Library, type_name: str, n: int, params: dict,
            stroke: float, progress: OnProgress | None = None) -> CellTable:
    """The cell compiled alone, timed over the grid on every change that switches it."""
    design, truth = alone(cls, lib, type_name, n, params, stroke)
    names = [f"i{k}" for k in range(n)]
    moves = []
    for row, to in switching_changes(np.asarray(truth), n):
        k = n - (row ^ to).bit_length()
        moves.append(Move({nm: float((row >> (n - 1 - q)) & 1) for q, nm in enumerate(names)},
                          names[k], float((to >> (n - 1 - k)) & 1)))
    return measure_in(design, lib, "c1", moves, progress)


def measure_in(design, lib: Library, cid: str, moves: list[Move],
               progress: OnProgress | None = None, shapes: bool = False) -> CellTable:
    """Cell ``cid`` of ``design`` timed over the grid: a scene of that cell alone (its output
    body carrying the grid's load), run through ``moves``, the worst of them kept per grid
    point; with ``shapes`` also its landing each way (the first move each way)."""
    t0 = time.perf_counter()
    mech = design.mechanism
    c = design.netlist.cells[cid]
    cls = lib[c.cell]
    part = mech.cells[cid]
    key = table_key(cls, c.type, len(c.inputs), dict(c.params), mech.ctx.stroke,
                    _unprefixed(part.to_json(), cid))
    types = {x.id: x.cell for x in design.netlist.cells.values()}
    out_body = part.terminals[cls.outputs[0]].body
    names = [*FIGURES, *(directed(f, on) for f in DIRECTED for on in (True, False))]
    values = {f: [[0.0] * len(LOADS) for _ in MOVE_TIMES] for f in names}
    total, done = len(MOVE_TIMES) * len(LOADS), 0
    taken = {"on": False, "off": False}  # a move switched the output that way
    landing: dict[str, list[list[list[float] | None]]] = {
        way: [[None] * len(LOADS) for _ in MOVE_TIMES] for way in ("on", "off")}
    for i, mt in enumerate(MOVE_TIMES):
        for j, load in enumerate(LOADS):
            worst = dict.fromkeys(names, 0.0)
            for mv in moves:
                got = _one_change(mech, lib, types, cid, mv, mt, load, out_body,
                                  cls.outputs[0])
                way = "on" if got["on"] else "off"
                taken[way] = True
                if landing[way][i][j] is None:
                    landing[way][i][j] = got["shape"]
                for f in FIGURES:
                    worst[f] = max(worst[f], got[f])
                for f in DIRECTED:
                    k = directed(f, got["on"])
                    worst[k] = max(worst[k], got[f])
            for f in names:
                values[f][i][j] = round(worst[f], 6)
            done += 1
            if progress is not None:
                progress(done, total)
    for way in ("on", "off"):  # a way no move took: the worse of the measured, not 0
        if not taken[way]:
            for f in DIRECTED:
                values[directed(f, way == "on")] = [row[:] for row in values[f]]
    kept = {way: grid for way, grid in landing.items()
            if all(x is not None for row in grid for x in row)} if shapes else None
    return CellTable(key, c.cell, c.type, len(c.inputs), dict(c.params), mech.ctx.stroke,
                     MOVE_TIMES, LOADS, values, len(moves), time.perf_counter() - t0,
                     cls.source_sha256, shapes=kept or None)


def _unprefixed(part_json: dict, cid: str) -> dict:
    """The part's JSON with its cell id taken out of body and joint names."""
    return json.loads(json.dumps(part_json).replace(f'"{cid}.', '"'))


def _one_change(mech, lib, types, cid: str, mv: Move, move_time: float, load: float,
                out_body: str, out_pin: str) -> dict:
    st = DynSettings(move_time=move_time, violation_limit=0.005 * mech.ctx.stroke)
    sc = Scene.build(mech, lib, types, st, dict(mv.start), cells=[cid])
    body = sc.bodies[out_body]
    body.mass = body.mass + load
    # the cell's output signal, read from the scene (a design's outputs are what it records)
    key = f"__cell_{cid}"
    mech.outputs[key] = (cid, out_pin)
    try:
        r = sc.move(mv.name, mv.target, reference=_ramp(sc, mv) if mv.ramp else None)
    finally:
        del mech.outputs[key]
    out, ref, t = r.outputs[key], r.reference[key], r.t
    t = np.concatenate([[0.0], t])
    out, ref = np.concatenate([[out[0]], out]), np.concatenate([[ref[0]], ref])
    lag = crossing(t, out) - crossing(t, ref)
    extra = settled_at(t, out) - settled_at(t, ref)
    end = out[-1]
    direction = 1.0 if ref[-1] >= ref[0] else -1.0
    over = max(0.0, float(np.max(direction * (out - end))))
    u = out * mech.ctx.stroke  # mm
    acc = np.gradient(np.gradient(u, t), t)  # mm / s^2
    force = body.mass * float(np.max(np.abs(acc))) / 1000.0  # kg mm/s^2 -> N
    cross = crossing(t, out)
    way = float(end - out[0]) or 1.0
    shape = (np.interp(cross + np.asarray(SHAPE_T), t, (out - out[0]) / way)
             if math.isfinite(cross) else np.full(len(SHAPE_T), np.nan))
    return {"lag_s": lag if math.isfinite(lag) else 0.0,
            "settle_extra_s": extra if math.isfinite(extra) else 0.0,
            "overshoot": over, "force_N": force, "on": bool(ref[-1] > ref[0]),
            "shape": [round(float(v), 5) for v in shape]}


def _ramp(sc: Scene, mv: Move) -> Poses:
    """The closed form along ``mv`` with every body carried along a straight ramp from its
    start pose to its end pose (see :attr:`Move.ramp`), as ``Scene.move`` samples it."""
    k = np.linspace(0.0, 1.0, MOVE_SAMPLES)
    vals = {nm: np.full(len(k), v) for nm, v in mv.start.items()}
    vals[mv.name] = mv.start[mv.name] + (mv.target - mv.start[mv.name]) * k
    cf = sc._kinematic(vals)

    def line(a: np.ndarray) -> np.ndarray:
        return a[0] + (a[-1] - a[0]) * k

    return Poses(u={b: line(v) for b, v in cf.u.items()},
                 theta={b: line(cf.theta[b]) for b in cf.theta},
                 xy={b: (line(x), line(y)) for b, (x, y) in cf.xy.items()},
                 state=dict(cf.state))


def directed(figure: str, on: bool) -> str:
    """The name of ``figure`` (one of ``DIRECTED``) for the output switching on or off."""
    return figure.replace("_s", "_on_s" if on else "_off_s", 1)


def crossing(t: np.ndarray, x: np.ndarray, level: float = 0.5) -> float:
    """First time ``x`` crosses ``level`` (linear between samples; nan if it never does)."""
    s = np.sign(np.asarray(x) - level)
    idx = np.flatnonzero(s[1:] != s[:-1])
    if not len(idx):
        return math.nan
    i = int(idx[0])
    x0, x1 = x[i], x[i + 1]
    f = 0.0 if x1 == x0 else (level - x0) / (x1 - x0)
    return float(t[i] + f * (t[i + 1] - t[i]))


def settled_at(t: np.ndarray, x: np.ndarray, end: float | None = None,
               within: float = SETTLED) -> float:
    """The time from which ``x`` stays within ``within`` of ``end`` (default its last
    value), linear between the last sample outside and the next one."""
    x = np.asarray(x)
    e = float(x[-1]) if end is None else end
    out = np.flatnonzero(np.abs(x - e) > within)
    if not len(out):
        return float(t[0])
    i = int(out[-1])
    if i + 1 >= len(t):
        return float(t[-1])
    d0, d1 = abs(x[i] - e), abs(x[i + 1] - e)
    f = 1.0 if d0 == d1 else (d0 - within) / (d0 - d1)
    return float(t[i] + min(max(f, 0.0), 1.0) * (t[i + 1] - t[i]))


class Tables:
    """The tables a design's cells need: shipped with mechc (a stdlib cell whose file is
    the one measured), cached on disk, or measured now with the cell compiled alone."""

    def __init__(self, lib: Library, progress: Callable[[str, int, int], None] | None = None,
                 cache: Path | None = None):
        self.lib = lib
        self.progress = progress
        self.cache = cache or cache_dir()
        self.shipped = _read_shipped()
        self._mem: dict[tuple, CellTable | None] = {}
        self.measured: list[str] = []
        self.found = {"shipped": 0, "cached": 0, "measured": 0}

    def get(self, cell: str, type_name: str, n: int, params: dict,
            stroke: float) -> CellTable | None:
        """The table of ``cell`` as a ``type_name`` of fan-in ``n``; None for a cell that is
        not timed alone (stateful, constant)."""
        cls = self.lib[cell]
        if cls.stateful or type_name in UNTIMED:
            return None
        mk = (cell, type_name, n, json.dumps(params, sort_keys=True, default=str), stroke)
        if mk in self._mem:
            return self._mem[mk]
        for d in self.shipped:
            if (d["cell"] == cell and d["type"] == type_name and d["n"] == n
                    and d["params"] == params and d["stroke"] == stroke
                    and d.get("source_sha256") == cls.source_sha256):
                tab = CellTable.from_json(d)
                self._mem[mk] = tab
                self.found["shipped"] += 1
                return tab
        name = hashlib.sha256(json.dumps([mk, cls.source_sha256, VERSION],
                                         default=str).encode()).hexdigest()[:24]
        path = self.cache / f"{cell}-{name}.json"
        tab = self._from_cache(mk, path)
        if tab is not None:
            return tab
        say = self.progress
        tab = measure(cls, self.lib, type_name, n, params, stroke,
                      None if say is None else (lambda d, t: say(cell, d, t)))
        self.measured.append(cell)
        self.found["measured"] += 1
        try:
            self.cache.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(tab.to_json()))
        except OSError:
            pass  # an unwritable cache costs a measurement next time, nothing else
        self._mem[mk] = tab
        return tab

    def _from_cache(self, key, path: Path) -> CellTable | None:
        """The table cached on disk at ``path`` (kept in memory under ``key``); None when
        there is none or it is damaged (then it is measured again)."""
        if not path.exists():
            return None
        try:
            tab = CellTable.from_json(json.loads(path.read_text()))
        except (OSError, ValueError, KeyError):
            return None
        self._mem[key] = tab
        self.found["cached"] += 1
        return tab

    def instance(self, design, cid: str, moves: Callable[[], list[Move]]) -> CellTable | None:
        """The table of cell ``cid`` as ``design`` built it (its own springs, dashpot and
        masses; keyed by that geometry's hash, cached), measured on a scene of that cell in
        the design on ``moves``; None when no move switches it."""
        c = design.netlist.cells[cid]
        key = table_key(self.lib[c.cell], c.type, len(c.inputs), dict(c.params),
                        design.mechanism.ctx.stroke,
                        _unprefixed(design.mechanism.cells[cid].to_json(), cid))
        if key in self._mem:
            return self._mem[key]
        path = self.cache / f"{c.cell}-{key}.json"
        tab = self._from_cache(key, path)
        if tab is not None:
            return tab
        mv = moves()
        if not mv:
            return None
        say = self.progress
        tab = measure_in(design, self.lib, cid, mv,
                         None if say is None else (lambda d, t: say(cid, d, t)), shapes=True)
        tab.as_built = True
        self.measured.append(cid)
        self.found["measured"] += 1
        try:
            self.cache.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(tab.to_json()))
        except OSError:
            pass  # an unwritable cache costs a measurement next time, nothing else
        self._mem[key] = tab
        return tab


def per_instance(cls: type[Cell]) -> bool:
    """Whether a cell is timed as each design builds it rather than from the table of the
    cell compiled alone: a cell with a switching delay of its own (a powered AMPLIFIER),
    whose landing depends on the springs and dashpot compile sizes for its loads. A linkage
    gate is quasi-static: its alone table serves every instance."""
    return float(getattr(cls, "switching_delay_s", 0.0) or 0.0) > 0.0


def measuring(progress: Callable[..., None] | None) -> Callable[[str, int, int], None] | None:
    """A proof's ``progress`` (told ``(done, total, what)``) as :class:`Tables` calls it while
    a cell is measured, the cell named."""
    if progress is None:
        return None
    return lambda cell, done, total: progress(done, total, f"measuring the timing of cell "
                                                           f"{cell!r} (first use)")


def _read_shipped() -> list[dict]:
    if not SHIPPED.exists():
        return []
    return json.loads(SHIPPED.read_text())["tables"]


#: The stdlib cells shipped with tables: (cell, logic type, fan-in), default parameters.
STANDARD = [("and", "AND", 2), ("and", "AND", 3), ("or", "OR", 2), ("or", "OR", 3),
            ("nand", "NAND", 2), ("nor", "NOR", 2), ("and_not", "AND_NOT", 2),
            ("or_not", "OR_NOT", 2), ("not", "NOT", 1), ("xor", "XOR", 2)]


def characterise_standard(lib: Library, stroke: float = 20.0,
                          say: Callable[[str], None] | None = None) -> dict:
    """The shipped file's content: every ``STANDARD`` cell measured at ``stroke``."""
    tables = []
    for cell, type_name, n in STANDARD:
        tab = measure(lib[cell], lib, type_name, n, {}, stroke)
        tables.append(tab.to_json())
        if say is not None:
            say(f"{cell} {type_name}/{n}: {tab.changes} changes, {tab.seconds:.1f} s")
    return {"format": "mechc-cell-timing", "version": VERSION, "tables": tables}
