"""``mechc draw``: a to-scale SVG of a compiled mechanism in one input state, for the person who
builds it.

Every body is drawn at the pose the kinematic solver gives for that state (not at the design
pose), so two drawings of the same design in two states show what moves and by how much. Ground
(pivots, spring anchors, stops) is hatched; grooves are slots with their pin; rods inside cells
are thin lines between pin circles; the nets' rods are bars of plate with a pin at each end,
drawn over the cells in the connectors' colours. Each part kind says which of these shapes it
shows (``mechc.parts``); this module says how a shape looks and in which order shapes are
painted. Coordinates are world millimetres times ``scale``, y flipped (SVG y grows downwards).
Symbols too small to see at the chosen scale (pins, pivots, hatches) get a minimum size in
pixels; outlines never do, so the drawing stays true to scale.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from mechc.cells.library import load_library
from mechc.errors import DesignError, UsageError
from mechc.ir.mechanism import GROUND, Body, Point
from mechc.parts import body_kind, joint_kind, position
from mechc.parts.base import Shape, direction
from mechc.physics.closed_form import KinematicsError
from mechc.physics.evaluate import evaluate, signal_of

SCALE_BAR_MM = 50.0
#: The widest a drawing is shown by default (px): one screen. A larger mechanism is shown
#: smaller, and its text drawn larger by as much, so that it reads at these sizes (px as shown).
DEFAULT_WIDTH = 1600.0
IO_PX = 18.0  # input and output labels, at the edges
LABEL_PX = 12.0  # cell and net names, legend
TITLE_PX = 16.0
NET_LABELS_DOWN_TO = 0.5  # nets are named on drawings shown at least this fraction of scale

# (fill, stroke, group opacity) per drawing class
_INPUT = ("#9ecae1", "#08519c", 0.95)
_LAYERS = [("#d9d9d9", "#525252", 0.95), ("#a1d99b", "#238b45", 0.85),
           ("#fdae6b", "#d94801", 0.8), ("#dadaeb", "#54278f", 0.8),
           ("#fcbba1", "#a50f15", 0.8)]
_CONNECTOR = ("#bcbddc", "#6a51a3", 0.85)
_SPRING = "#cb181d"
_GROUND = "#252525"
_BAD = "#e31a1c"
_TOP_LAYER = 1000  # drawing order of the fan-out bars nets add to driver bodies (rods: + 1)


@dataclass
class Drawing:
    """The SVG and what the state showed (for the command's summary and for tests)."""

    svg: str
    outputs: dict[str, float]  # output -> signal (0 off .. 1 on), NaN where not solved
    unsolved: list[str] = field(default_factory=list)  # bodies the solver could not pose
    size_mm: tuple[float, float] = (0.0, 0.0)


def draw_svg(design, state: dict[str, int], scale: float = 2.0, labels: bool = True,
             width: float | None = DEFAULT_WIDTH) -> str:
    """SVG text of ``design`` with its primary inputs at ``state`` (missing inputs are off),
    shown at most ``width`` px wide (None: its natural size, ``scale`` px per mm)."""
    return render(design, state, scale, labels, width=width).svg


# ---- state --------------------------------------------------------------------------------------

def parse_state(text: str, inputs: list[str]) -> dict[str, int]:
    """``"A=1,B=0"`` (commas or spaces; values 0/1/on/off) -> {input: 0|1}, others off."""
    state = {n: 0 for n in inputs}
    seen: set[str] = set()
    for item in text.replace(",", " ").split():
        name, eq, value = item.partition("=")
        if not eq or not name:
            raise UsageError(f"--state: expected NAME=0 or NAME=1, got '{item}'")
        if name not in state:
            raise UsageError(f"--state: unknown input '{name}' (inputs: {', '.join(inputs)})")
        if name in seen:
            raise UsageError(f"--state: input '{name}' given twice")
        v = {"0": 0, "1": 1, "off": 0, "on": 1}.get(value.lower())
        if v is None:
            raise UsageError(f"--state: value for {name} must be 0 or 1, got '{value}'")
        state[name] = v
        seen.add(name)
    return state


def _check_state(state: dict[str, int], inputs: list[str]) -> dict[str, int]:
    out = {n: 0 for n in inputs}
    for k, v in state.items():
        if k not in out:
            raise UsageError(f"state: unknown input '{k}' (inputs: {', '.join(inputs)})")
        if v not in (0, 1):
            raise UsageError(f"state: value for {k} must be 0 or 1, got {v!r}")
        out[k] = int(v)
    return out


# ---- poses --------------------------------------------------------------------------------------

class _Mover:
    """Moves design points of any body to the state's pose; unsolved bodies stay at design."""

    def __init__(self, bodies: dict[str, Body], poses):
        self.bodies, self.poses = bodies, poses
        self.unsolved: set[str] = set()
        for bid, b in bodies.items():
            val = getattr(poses, body_kind(b.kind).coordinate).get(bid)
            bad = poses.bad.get(bid)
            if val is None or not np.isfinite(val[0]) or (bad is not None and bool(bad[0])):
                self.unsolved.add(bid)

    def move(self, bid: str, xs, ys) -> tuple[np.ndarray, np.ndarray]:
        xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
        if bid == GROUND or bid in self.unsolved:
            return xs, ys
        x, y = position(self.bodies[bid], self.poses, (xs, ys))
        return np.broadcast_to(x, xs.shape), np.broadcast_to(y, ys.shape)

    def pt(self, bid: str, p: Point) -> Point:
        x, y = self.move(bid, [p[0]], [p[1]])
        return float(x[0]), float(y[0])

    def layer(self, bid: str) -> int:
        return 0 if bid == GROUND else self.bodies[bid].layer


def _pose(design, state: dict[str, int], library=None):
    mech = design.mechanism
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    values = {n: np.array([float(state[n])]) for n in design.netlist.inputs}
    try:
        poses = evaluate(mech, library or load_library(), types, values)
    except KinematicsError as e:
        raise DesignError(f"cannot pose the mechanism: {e}") from None
    mover = _Mover(mech.body_index(), poses)
    outs = {}
    for name, (owner, pin) in mech.outputs.items():
        t = mech.owner_part(owner).terminals[pin]
        outs[name] = (float("nan") if t.body in mover.unsolved
                      else float(signal_of(t, mover.bodies[t.body], poses)[0]))
    return mover, outs


# ---- the picture --------------------------------------------------------------------------------

@dataclass
class _Label:
    text: str
    at: Point  # world
    anchor: str = "start"  # start | middle | end
    cls: str = "lb"
    dx: float = 0.0  # px offsets after scaling
    dy: float = 0.0
    home: Point | None = None  # world anchor at the design pose (default: ``at``)
    sweep: Point = (0.0, 0.0)  # how far (mm) the anchor can move from home, either way
    widest: str = ""  # the longest text this label takes in any state

    def reserve(self, fs: float, px, py) -> tuple[float, float, float, float]:
        """The box (px) this label may occupy in any state, at its current lift."""
        tw = max(_text_w(self.text, fs, bold=self.cls in _BOLD),
                 _text_w(self.widest, fs, bold=True))
        hx, hy = self.home if self.home is not None else self.at
        x = px(hx) + self.dx
        x0 = x - (tw if self.anchor == "end" else tw / 2 if self.anchor == "middle" else 0.0)
        y = py(hy) + self.dy
        sx, sy = abs(px(hx + self.sweep[0]) - px(hx)), abs(py(hy + self.sweep[1]) - py(hy))
        return (x0 - sx, y - 0.8 * fs - sy, x0 + tw + sx, y + 0.25 * fs + sy)


def _connector_polys(mech) -> dict[str, set[int]]:
    """Polygons the assembler added to a driver body for a net (arm and fan-out bar): their
    right edge is the fan-out bar's right edge."""
    w = mech.ctx.bar
    bodies = mech.body_index()
    out: dict[str, set[int]] = {}
    for part in mech.nets.values():
        if not part.joints or "fanout_bar_x" not in part.data:
            continue
        xr = float(part.data["fanout_bar_x"]) + w / 2
        bid = part.joints[0].a
        if bid not in bodies:
            continue
        for i, poly in enumerate(bodies[bid].outline):
            if abs(max(p[0] for p in poly) - xr) < 1e-3:
                out.setdefault(bid, set()).add(i)
    return out


def _cell_bounds(part, conn: dict[str, set[int]]) -> tuple[float, float, float, float]:
    """Extent of a cell at its design pose, without the fan-out bars the nets added to it."""
    pts: list[Point] = []
    for b in part.bodies:
        for i, poly in enumerate(b.outline):
            if i not in conn.get(b.id, ()):
                pts.extend(poly)
        if b.pivot is not None:
            pts.append(b.pivot)
    for j in part.joints:
        pts.extend(p for p in (j.p0, j.p1, j.q, j.pa, j.pb) if p is not None)
    for s in part.springs:
        pts.extend((s.pa, s.pb))
    for t in part.terminals.values():
        pts.extend((t.off, t.on))
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)


def _shapes(mech, mover: _Mover, conn: dict[str, set[int]]):
    """Every part as shapes in world mm at the state's pose; cell boxes (design pose)."""
    shapes: list[Shape] = []
    boxes: dict[str, tuple[float, float, float, float]] = {}
    owners: list[tuple[str, object]] = [(f"in:{k}", p) for k, p in mech.inputs.items()]
    owners += [(c, mech.cells[c]) for c in mech.order]
    for owner, part in owners:
        for b in part.bodies:
            own, extra = [], []
            for i, poly in enumerate(b.outline):
                xs, ys = mover.move(b.id, [p[0] for p in poly], [p[1] for p in poly])
                moved = list(zip(xs.tolist(), ys.tolist()))
                (extra if i in conn.get(b.id, ()) else own).append(moved)
            if b.id in mover.unsolved:
                cls = "bad"
            elif owner.startswith("in:"):
                cls = "in"
            else:
                cls = f"L{max(0, min(b.layer, len(_LAYERS) - 1))}"
            for poly in own:
                shapes.append(Shape("body", poly, cls, b.id, b.layer))
            for poly in extra:  # fan-out bars: drawn over every layer, in connector colours
                shapes.append(Shape("body", poly, "bad" if cls == "bad" else "cn", b.id,
                                    _TOP_LAYER))
            shapes += body_kind(b.kind).symbols(b)
        for j in part.joints:
            shapes += joint_kind(j.kind).shapes(j, mover)
        for s in part.springs:
            pa, pb = mover.pt(s.a, s.pa), mover.pt(s.b, s.pb)
            g = (s.a == GROUND, s.b == GROUND)
            shapes.append(Shape("spring", [pa, pb], ground=None))
            for is_ground, p, q in ((g[0], pa, pb), (g[1], pb, pa)):
                if is_ground:
                    shapes.append(Shape("anchor", [p], ground=direction((p[0] - q[0],
                                                                         p[1] - q[1]))))
        if not owner.startswith("in:"):
            # the box stays at the design pose in every state: a fixed frame that shows how far
            # the parts have moved (by up to half a stroke)
            x0, y0, x1, y1 = _cell_bounds(part, conn)
            pad = 0.3 * mech.ctx.bar
            boxes[owner] = (x0 - pad, y0 - pad, x1 + pad, y1 + pad)
    for part in mech.nets.values():  # the nets' rods, over every cell and fan-out bar
        for b in part.bodies:
            cls = "bad" if b.id in mover.unsolved else "cn"
            for poly in b.outline:
                xs, ys = mover.move(b.id, [p[0] for p in poly], [p[1] for p in poly])
                shapes.append(Shape("body", list(zip(xs.tolist(), ys.tolist())), cls, b.id,
                                    _TOP_LAYER + 1))
        for j in part.joints:
            if j.kind == "pin":  # a rod's pin, at the driver's (or the load's) copy of it
                shapes.append(Shape("pin", [mover.pt(j.a, j.pa)], ref=j.id))
            shapes += joint_kind(j.kind).shapes(j, mover)
    return shapes, boxes


def _labels(design, mover: _Mover, boxes, conn: dict[str, set[int]]) -> list[_Label]:
    """Cells at their boxes, nets at their fan-out bars; each knows where it sits at the
    design pose and how far it can move. Inputs and outputs are labelled at the drawing's
    edges (``_edge_labels``)."""
    mech = design.mechanism
    labels: list[_Label] = []
    w = mech.ctx.bar
    for cid, (x0, _y0, _x1, y1) in boxes.items():
        c = design.netlist.cells[cid]
        labels.append(_Label(f"{cid} {c.type}", (x0, y1), "start", "lc", dx=-2, dy=-4))
    for net, part in mech.nets.items():
        xb = part.data.get("fanout_bar_x")
        if xb is None or not part.joints:
            continue
        bid = part.joints[0].a
        top = max(j.pa[1] for j in part.joints)
        if bid in conn:
            top = max(p[1] for i in conn[bid] for p in mover.bodies[bid].outline[i])
        x, y = mover.pt(bid, (float(xb), top))
        if net in mech.inputs:
            continue  # the input's own label names it
        labels.append(_Label(net, (x, y + w * 0.2), "middle", "ln", dy=-3,
                             home=(float(xb), top + w * 0.2),
                             sweep=_sweep(mover.bodies[bid], mech.ctx.stroke)))
    return labels


@dataclass
class _EdgeLabel:
    """An input's or output's label in the column at the drawing's left or right edge, on its
    terminal's row, with a leader line to the part it names."""

    text: str
    cls: str
    side: str  # "left" (inputs) or "right" (outputs)
    row: float  # world y of the terminal's row (design pose: the same in every state)
    to: Point  # world point the leader line ends at (the part, at this state's pose)
    widest: str  # the longest text this label takes in any state
    y: float = 0.0  # px baseline, once placed


def _edge_labels(design, mover: _Mover, outs: dict[str, float], state: dict[str, int],
                 conn: dict[str, set[int]]) -> list[_EdgeLabel]:
    """Every input (left edge) and output (right edge) with its value in this state."""
    mech = design.mechanism
    out: list[_EdgeLabel] = []
    for name, part in mech.inputs.items():
        t = part.terminals[name]
        b = part.body(t.body)
        x_home = min(p[0] for p in b.outline[0])
        on = state[name] == 1
        out.append(_EdgeLabel(f"{name} {'on' if on else 'off'}", "li1" if on else "li0", "left",
                              t.off[1], mover.pt(b.id, (x_home, t.off[1])), f"{name} off"))
    for name, (owner, pin) in mech.outputs.items():
        t = mech.owner_part(owner).terminals[pin]
        sig = outs.get(name, float("nan"))
        if sig != sig:
            text, cls = f"{name} = ? (not solved)", "lbad"
        else:
            on = sig > 0.5
            text, cls = f"{name} = {int(on)} ({'on' if on else 'off'})", "lo1" if on else "lo0"
        b = mover.bodies[t.body]
        mid = t.design_point
        # the output body's tip on the terminal's row (not the fan-out bars nets add to it)
        tip = max([mid] + [p for i, poly in enumerate(b.outline) if i not in conn.get(b.id, ())
                           for p in poly if abs(p[1] - mid[1]) < mech.ctx.bar])
        out.append(_EdgeLabel(text, cls, "right", t.off[1], mover.pt(b.id, tip),
                              f"{name} = ? (not solved)"))
    return out


def _stack(rows: list[float], gap: float) -> list[float]:
    """Baselines for labels wanted at ``rows`` (px, any order): each as near its row as the
    ones before allow, at least ``gap`` apart, the run centred on the rows it serves."""
    order = sorted(range(len(rows)), key=lambda i: rows[i])
    ys = [rows[i] for i in order]
    for k in range(1, len(ys)):
        ys[k] = max(ys[k], ys[k - 1] + gap)
    if ys:  # pull the whole run back up by half of what it was pushed down
        shift = (sum(ys) - sum(rows[i] for i in order)) / len(ys)
        ys = [y - shift for y in ys]
    out = [0.0] * len(rows)
    for k, i in enumerate(order):
        out[i] = ys[k]
    return out


def _reach(mech) -> list[Point]:
    """Points that bound every state: sliders' outlines one stroke either way along their
    axis (their stops allow at most 0.65 S), levers' squares of their largest radius, and the
    ground ends of stops and springs."""
    S = mech.ctx.stroke
    out: list[Point] = []
    for part in mech.all_parts():
        for b in part.bodies:
            out += body_kind(b.kind).reach(b, S)
        for j in part.joints:
            if j.a == GROUND and j.pa is not None:
                out.append(j.pa)
            if j.b == GROUND and j.pb is not None:
                out.append(j.pb)
        for s in part.springs:
            out += [s.pa] if s.a == GROUND else []
            out += [s.pb] if s.b == GROUND else []
    return out


def _attr(text: str) -> str:
    return escape(text, {'"': "&quot;"})


_BOLD = {"li1", "lo1", "lbad", "tt"}
_ON_ROW = {"li0", "li1", "lo0", "lo1", "lbad"}  # labels centred on a slider's row


def _place_labels(labs: list[_Label], fs: float, px, py) -> list[tuple[float, ...]]:
    """Fix each label's baseline and lift it (up to four lines) off labels already placed.
    Collisions are judged on the boxes a label may occupy in any state, so the lifts and the
    margins they need are the same in every state. Returns those boxes (px from the origin)."""
    placed: list[tuple[float, ...]] = []
    for lb in labs:
        if lb.cls in _ON_ROW:
            lb.dy += 0.35 * fs
        for _ in range(5):
            box = lb.reserve(fs, px, py)
            if not any(box[0] < b[2] + 2 and b[0] < box[2] + 2 and box[1] < b[3] and
                       b[1] < box[3] for b in placed):
                break
            lb.dy -= 1.05 * fs
        placed.append(box)
    return placed


def _sweep(b: Body, stroke: float) -> Point:
    """How far a point of ``b`` may move from its design pose (half a stroke on a slider)."""
    return body_kind(b.kind).sweep(b, stroke)


def _text_w(text: str, size: float, bold: bool = False) -> float:
    """Rough advance width of ``text`` in a sans-serif face (for margins, not layout)."""
    return (0.66 if bold else 0.6) * size * len(text)


def render(design, state: dict[str, int], scale: float = 2.0, labels: bool = True,
           library=None, width: float | None = DEFAULT_WIDTH) -> Drawing:
    """Pose the mechanism in ``state`` and draw it; see :func:`draw_svg`. ``library``: the
    cell library the design was compiled with (default: the standard one). ``width``: the
    widest the drawing is shown (px; None: its natural size, ``scale`` px per mm); the text
    is sized for the size it is shown at."""
    if design.mechanism is None:
        raise UsageError("this design has no mechanism geometry (compiled by an older mechc?); "
                         "recompile the spec")
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise UsageError(f"--scale must be a positive number of px per mm, got {scale}")
    if width is not None and not (math.isfinite(width) and width >= 200):
        raise UsageError(f"--width must be at least 200 px, got {width}")
    inputs = list(design.netlist.inputs)
    state = _check_state(state, inputs)
    mover, outs = _pose(design, state, library)
    mech = design.mechanism
    conn = _connector_polys(mech)
    shapes, boxes = _shapes(mech, mover, conn)
    edge = _edge_labels(design, mover, outs, state, conn) if labels else []

    # The frame depends on the design, not on the state (where it can), so that drawings of
    # two states overlay exactly: every slider's outline one stroke either way, every lever's
    # swept square, the ground points; then whatever this state actually reaches.
    pts = _reach(mech) + [p for s in shapes for p in s.pts] + [
        p for b in boxes.values() for p in ((b[0], b[1]), (b[2], b[3]))]
    X0, X1 = min(p[0] for p in pts), max(p[0] for p in pts)
    Y0, Y1 = min(p[1] for p in pts), max(p[1] for p in pts)
    unsolved = sorted(mover.unsolved)
    title = _title(design, state, outs, mech.ctx.stroke, scale)
    # Text is sized in px as shown: a drawing wider than ``width`` is shown smaller, so its
    # text is drawn larger in its own units, by the factor it will be shrunk (found in a few
    # rounds, since the margins the text needs widen the drawing)
    k = 1.0
    for _ in range(6):
        lay = _layout(design, mover, boxes, conn, edge, labels, title, bool(unsolved), shapes,
                      (X0, X1, Y0, Y1), scale, k)
        fit = 1.0 if width is None or lay.W * k <= width else width / lay.W
        if abs(fit - k) <= 0.01 * k:
            break
        k = fit
    show = min(1.0, fit)
    return Drawing(_svg(lay, shapes, boxes, edge, lay.title, unsolved, scale, show,
                        mech.ctx.bar),
                   outs, unsolved, (X1 - X0, Y1 - Y0))


@dataclass
class _Layout:
    """Where everything goes, in the drawing's own units (``scale`` px per mm)."""

    W: float
    H: float
    f: _Frame
    fs: float  # cell and net labels, legend
    fs_io: float  # inputs and outputs
    fs_title: float
    k: float  # the display factor the text was sized for
    title: str
    labs: list
    legend: str
    legend_y: float  # the scale bar's and the legend's first baseline
    io_x: tuple[float, float]  # the left column's right end, the right column's left end


def _layout(design, mover: _Mover, boxes, conn, edge: list[_EdgeLabel], labels: bool,
            title: str, warn: bool, shapes, ext, scale: float, k: float) -> _Layout:
    X0, X1, Y0, Y1 = ext
    fs = LABEL_PX / k
    fs_io = IO_PX / k
    fs_title = TITLE_PX / k
    labs = _labels(design, mover, boxes, conn) if labels else []
    if k < NET_LABELS_DOWN_TO:  # shown this small, net names would bury the cells' names
        labs = [lb for lb in labs if lb.cls != "ln"]
    boxes_px = _place_labels(labs, fs, lambda x: (x - X0) * scale, lambda y: (Y1 - y) * scale)
    gap = 1.5 * fs_io  # between the mechanism and the label columns (leader lines)
    lw = [_text_w(e.widest, fs_io, bold=True) for e in edge if e.side == "left"]
    rw = [_text_w(e.widest, fs_io, bold=True) for e in edge if e.side == "right"]
    left = max([10.0 / k] + [10.0 / k - b[0] for b in boxes_px]
               + [10.0 / k + w + gap for w in lw])
    right = max([10.0 / k] + [b[2] + 10.0 / k - (X1 - X0) * scale for b in boxes_px]
                + [10.0 / k + w + gap for w in rw])
    above = max([10.0 / k] + [6.0 / k - b[1] for b in boxes_px])
    top = fs_title * (2.8 if warn else 1.8) + above
    # the io columns: baselines on their rows, spread where rows are closer than a line
    for side in ("left", "right"):
        mine = [e for e in edge if e.side == side]
        ys = _stack([top + (Y1 - e.row) * scale + 0.35 * fs_io for e in mine], 1.25 * fs_io)
        for e, y in zip(mine, ys):
            e.y = y
    above_io = max([0.0] + [top - (e.y - fs_io) for e in edge])
    top += above_io
    for e in edge:
        e.y += above_io
    W = (X1 - X0) * scale + left + right
    W = max(W, SCALE_BAR_MM * scale + 300 / k)
    if _text_w(title, fs_title, bold=True) + 20 / k > W:  # a long state: it is at the edges
        title = _short_title(title)
    W = max(W, _text_w(title, fs_title, bold=True) + 20 / k)
    legend, rows = _legend(10.0 / k + SCALE_BAR_MM * scale + 40 / k, fs, sorted(
        {s.cls for s in shapes if s.kind == "body"}), any(s.kind == "spring" for s in shapes),
        W - 10 / k, k)
    below_io = max([0.0] + [e.y + 0.4 * fs_io - (top + (Y1 - Y0) * scale) for e in edge])
    bottom = 2.4 * fs + 1.6 * fs * rows + 16 / k + below_io
    H = (Y1 - Y0) * scale + top + bottom
    f = _Frame(X0, Y1, scale, left, top)
    legend_y = top + (Y1 - Y0) * scale + below_io + 1.4 * fs + 8 / k
    return _Layout(W, H, f, fs, fs_io, fs_title, k, title, labs, legend, legend_y,
                   (left - gap, left + (X1 - X0) * scale + gap))


def _svg(lay: _Layout, shapes, boxes, edge: list[_EdgeLabel], title: str, unsolved: list[str],
         scale: float, show: float, bar: float) -> str:
    """The SVG text of a laid-out drawing, shown at ``show`` times its own size."""
    W, H, f, fs, k = lay.W, lay.H, lay.f, lay.fs, lay.k
    sym = max(0.9 * bar * scale, 8.0 / k)  # symbol size: pivots, hatches
    pin_r = max(0.2 * bar * scale, 2.0 / k)
    sw = max(0.12 * scale, 0.8 / k)  # outline stroke
    out: list[str] = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{W * show:.0f}" '
        f'height="{H * show:.0f}" viewBox="0 0 {W:.0f} {H:.0f}" '
        'font-family="DejaVu Sans, Arial, sans-serif">',
        f"<title>{escape(title)}</title>",
        "<style>" + _css(sw, fs, lay.fs_title, k, lay.fs_io) + "</style>",
        f'<rect width="{W:.0f}" height="{H:.0f}" fill="white"/>',
        '<g class="box">',  # faint cell boxes
    ]
    for cid, (x0, y0, x1, y1) in boxes.items():
        out.append(f'<rect data-cell="{_attr(cid)}" x="{f.X(x0):.1f}" y="{f.Y(y1):.1f}" '
                   f'width="{(x1 - x0) * scale:.1f}" height="{(y1 - y0) * scale:.1f}"/>')
    out.append("</g>")
    out += _svg_bodies(shapes, f, pin_r)
    out += _svg_mechanics(shapes, f, sym, pin_r)
    out.append('<g class="lbl">')
    for lb in lay.labs:
        attrs = (f'x="{f.X(lb.at[0]) + lb.dx:.1f}" y="{f.Y(lb.at[1]) + lb.dy:.1f}" '
                 f'text-anchor="{lb.anchor}"')
        # a white halo under each label (paint-order is not understood by every renderer)
        out.append(f'<text class="{lb.cls} halo" {attrs}>{escape(lb.text)}</text>'
                   f'<text class="{lb.cls}" {attrs}>{escape(lb.text)}</text>')
    out.append("</g>")
    out.append('<g class="io">')  # inputs at the left edge, outputs at the right
    xl, xr = lay.io_x
    for e in edge:
        px, py = f.X(e.to[0]), f.Y(e.to[1])
        x = xl if e.side == "left" else xr
        end = x + (0.3 if e.side == "left" else -0.3) * lay.fs_io
        out.append(f'<path class="ld" d="M{end:.1f},{e.y - 0.35 * lay.fs_io:.1f}'
                   f'L{px:.1f},{py:.1f}"/>')
        out.append(f'<text class="{e.cls} io{e.side[0]}" x="{x:.1f}" y="{e.y:.1f}" '
                   f'text-anchor="{"end" if e.side == "left" else "start"}">'
                   f"{escape(e.text)}</text>")
    out.append("</g>")
    # title, warning, scale bar, legend
    out.append(f'<text class="tt" x="{10 / k:.1f}" y="{lay.fs_title + 4 / k:.1f}">'
               f"{escape(title)}</text>")
    if unsolved:
        msg = (f"NOT SOLVED in this state, drawn dashed red at the design pose: "
               f"{', '.join(unsolved[:8])}{' ...' if len(unsolved) > 8 else ''}")
        out.append(f'<text class="lbad" x="{10 / k:.1f}" y="{2.2 * lay.fs_title + 4 / k:.1f}">'
                   f"{escape(msg)}</text>")
    yb = lay.legend_y
    out.append(_scale_bar(10.0 / k, yb, scale, fs, k))
    out.append(f'<g transform="translate(0 {yb:.1f})">{lay.legend}</g>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


@dataclass(frozen=True)
class _Frame:
    """World mm -> SVG px: scaled, y flipped, offset by the margins."""

    x0: float
    y1: float
    scale: float
    left: float
    top: float

    def X(self, x: float) -> float:
        return (x - self.x0) * self.scale + self.left

    def Y(self, y: float) -> float:
        return (self.y1 - y) * self.scale + self.top

    def path(self, poly) -> str:
        return "M" + "L".join(f"{self.X(x):.1f},{self.Y(y):.1f}" for x, y in poly) + "Z"


def _svg_bodies(shapes: list[Shape], f: _Frame, pin_r: float) -> list[str]:
    """Bodies grouped by body, lower layers first; each layer's slots right after it."""
    out: list[str] = []
    bodies: dict[tuple[int, str, str], list] = {}
    for s in shapes:
        if s.kind == "body":
            bodies.setdefault((s.layer, s.cls, s.ref), []).append(s.pts)
    slots = [s for s in shapes if s.kind == "slot"]
    for layer in sorted({k[0] for k in bodies} | {s.layer for s in slots}):
        for (lay, cls, ref), polys in sorted(bodies.items(), key=lambda kv: kv[0][2]):
            if lay != layer:
                continue
            d = "".join(f.path(p) for p in polys)
            # outline drawn wide, then the fill over it: seams between a body's own
            # rectangles vanish and only its outer edge shows
            out.append(f'<g class="{cls}" data-body="{_attr(ref)}"><path class="o" d="{d}"/>'
                       f'<path class="f" d="{d}"/></g>')
        for s in slots:
            if s.layer == layer:
                (ax, ay), (bx, by) = s.pts
                line = (f'x1="{f.X(ax):.1f}" y1="{f.Y(ay):.1f}" x2="{f.X(bx):.1f}" '
                        f'y2="{f.Y(by):.1f}"')
                out.append(f'<line class="slo" data-joint="{_attr(s.ref)}" {line} '
                           f'stroke-width="{2 * pin_r + 2.5:.1f}"/>'
                           f'<line class="sli" {line} stroke-width="{2 * pin_r + 0.5:.1f}"/>')
    return out


def _svg_mechanics(shapes: list[Shape], f: _Frame, sym: float, pin_r: float) -> list[str]:
    """Springs, rods, pins, pivots and ground marks, over the bodies."""
    out = [f'<path class="sp" d="{_zigzag(s.pts, f.X, f.Y, sym)}"/>' for s in shapes
           if s.kind == "spring"]
    for s in shapes:
        if s.kind == "rod":
            (ax, ay), (bx, by) = s.pts
            out.append(f'<line class="rod" data-joint="{_attr(s.ref)}" x1="{f.X(ax):.1f}" '
                       f'y1="{f.Y(ay):.1f}" x2="{f.X(bx):.1f}" y2="{f.Y(by):.1f}"/>')
            out += [f'<circle class="rp" cx="{f.X(x):.1f}" cy="{f.Y(y):.1f}" r="{pin_r:.1f}"/>'
                    for x, y in s.pts]
    for s in shapes:
        x, y = f.X(s.pts[0][0]), f.Y(s.pts[0][1])
        if s.kind == "pin":
            out.append(f'<circle class="pin" data-joint="{_attr(s.ref)}" cx="{x:.1f}" '
                       f'cy="{y:.1f}" r="{pin_r:.1f}"/>')
        elif s.kind == "pivot":
            out.append(_ground(x, y, (0.0, -1.0), sym, base=0.9 * sym))
            out.append(f'<circle class="pv" data-body="{_attr(s.ref)}" cx="{x:.1f}" '
                       f'cy="{y:.1f}" r="{0.4 * sym:.1f}"/>')
        elif s.kind in ("stop", "anchor"):
            out.append(_ground(x, y, s.ground, 0.8 * sym))
    return out


def _title(design, state, outs, S, scale) -> str:
    name = Path(design.spec.path).name if getattr(design.spec, "path", None) else "design"
    ins = " ".join(f"{k}={v}" for k, v in state.items())
    res = " ".join(f"{k}={int(v > 0.5) if v == v else '?'}" for k, v in outs.items())
    return (f"{name}  |  inputs {ins}  ->  outputs {res}  |  stroke {S:g} mm  |  "
            f"{scale:g} px/mm")


def _short_title(title: str) -> str:
    """The title without its list of input and output values (they are at the edges)."""
    parts = title.split("  |  ")
    return "  |  ".join([parts[0], "input and output values at the edges"] + parts[2:])


def _css(sw: float, fs: float, ft: float, k: float = 1.0, fio: float = 16.0) -> str:
    """The style, with every width and font in the drawing's units (``k``: the display
    factor, so that lines and text keep their width in px as shown)."""
    u = 1.0 / k
    rules = [f".box rect{{fill:#f7f7f7;stroke:#969696;stroke-width:{0.8 * u:.2f};"
             f"stroke-dasharray:{4 * u:.1f} {3 * u:.1f}}}",
             f".o{{fill:none;stroke-width:{2 * sw:.2f};stroke-linejoin:round}}",
             ".f{stroke:none}"]
    classes = {"in": _INPUT, "cn": _CONNECTOR, "bad": ("#fee0d2", _BAD, 0.7)}
    classes.update({f"L{i}": c for i, c in enumerate(_LAYERS)})
    for cls, (fill, stroke, op) in classes.items():
        rules.append(f".{cls}{{opacity:{op}}}.{cls} .o{{stroke:{stroke}}}.{cls} .f{{fill:{fill}}}")
    rules += [
        ".bad .o{stroke-dasharray:5 3}",
        ".slo{stroke:#252525;stroke-linecap:round}.sli{stroke:white;stroke-linecap:round}",
        f".sp{{fill:none;stroke:{_SPRING};stroke-width:{1.2 * u:.2f};stroke-linejoin:round}}",
        f".rod{{stroke:{_CONNECTOR[1]};stroke-width:{1.6 * u:.2f}}}",
        f".rp{{fill:white;stroke:{_CONNECTOR[1]};stroke-width:{1.2 * u:.2f}}}",
        f".pin{{fill:#252525}}.pv{{fill:white;stroke:#252525;stroke-width:{1.4 * u:.2f}}}",
        f".gd{{fill:none;stroke:{_GROUND};stroke-width:{u:.2f}}}",
        f".gb{{fill:none;stroke:{_GROUND};stroke-width:{1.8 * u:.2f}}}",
        f"text{{font-size:{fs:.1f}px;fill:#252525}}",
        f".lbl .halo{{fill:white;stroke:white;stroke-width:{3 * u:.2f}px;stroke-linejoin:round}}",
        f".tt{{font-size:{ft:.1f}px;font-weight:bold}}",
        f".io text{{font-size:{fio:.1f}px}}",
        f".ld{{fill:none;stroke:#969696;stroke-width:{0.8 * u:.2f};"
        f"stroke-dasharray:{2 * u:.1f} {2 * u:.1f}}}",
        ".lc{fill:#525252}.ln{fill:#54278f;font-style:italic}",
        ".li0{fill:#08519c;font-weight:bold}.li1{fill:#08519c;font-weight:bold;"
        "text-decoration:underline}",
        ".lo0{fill:#252525;font-weight:bold}.lo1{fill:#006d2c;font-weight:bold}",
        f".lbad{{fill:{_BAD};font-weight:bold}}",
    ]
    return "".join(rules)


def _zigzag(pts, X, Y, sym: float) -> str:
    """A spring between two points: straight leads, then a zigzag of about one coil per 6 px."""
    (ax, ay), (bx, by) = ((X(x), Y(y)) for x, y in pts)
    L = math.hypot(bx - ax, by - ay)
    if L < 1e-6:
        return f"M{ax:.1f},{ay:.1f}"
    ux, uy = (bx - ax) / L, (by - ay) / L
    nx, ny = -uy, ux
    lead = min(0.15 * L, 2 * sym)
    n = max(4, min(40, int((L - 2 * lead) / 6)))
    amp = 0.45 * sym
    d = [f"M{ax:.1f},{ay:.1f}", f"L{ax + ux * lead:.1f},{ay + uy * lead:.1f}"]
    step = (L - 2 * lead) / n
    for i in range(n):
        t = lead + (i + 0.5) * step
        s = amp if i % 2 == 0 else -amp
        d.append(f"L{ax + ux * t + nx * s:.1f},{ay + uy * t + ny * s:.1f}")
    d.append(f"L{bx - ux * lead:.1f},{by - uy * lead:.1f}L{bx:.1f},{by:.1f}")
    return "".join(d)


def _ground(x: float, y: float, into: Point | None, size: float, base: float = 0.0) -> str:
    """A ground mark at (x, y) px: a bar across ``into`` (world direction towards the ground,
    here flipped to SVG) at ``base`` px from the point, hatched on the ground side."""
    gx, gy = into if into is not None else (0.0, -1.0)
    gx, gy = gx, -gy  # world -> SVG
    px, py = -gy, gx  # along the bar
    cx, cy = x + gx * base, y + gy * base
    h = size / 2
    parts = [f"M{cx - px * h:.1f},{cy - py * h:.1f}L{cx + px * h:.1f},{cy + py * h:.1f}"]
    if base > 0:  # a bearing: lines from the pivot to the bar ends
        parts.append(f"M{x:.1f},{y:.1f}L{cx - px * h * 0.6:.1f},{cy - py * h * 0.6:.1f}"
                     f"M{x:.1f},{y:.1f}L{cx + px * h * 0.6:.1f},{cy + py * h * 0.6:.1f}")
    hatch = []
    k = 4
    for i in range(k + 1):
        t = -h + 2 * h * i / k
        sx, sy = cx + px * t, cy + py * t
        hatch.append(f"M{sx:.1f},{sy:.1f}L{sx + (gx - px) * h * 0.6:.1f},"
                     f"{sy + (gy - py) * h * 0.6:.1f}")
    return (f'<path class="gb" d="{parts[0]}"/><path class="gd" d="{"".join(parts[1:])}'
            f'{"".join(hatch)}"/>')


def _scale_bar(x: float, y: float, scale: float, fs: float, k: float = 1.0) -> str:
    """A 50 mm bar with 10 mm ticks; its ``x2 - x1`` is exactly 50 mm at the drawing's scale."""
    L = SCALE_BAR_MM * scale
    u = 1.0 / k
    ticks = "".join(f"M{x + i * 10 * scale:.2f},{y - 4 * u:.1f}v{8 * u:.1f}" for i in range(6))
    return (f'<g class="scale"><line id="scalebar" x1="{x:.2f}" y1="{y:.1f}" x2="{x + L:.2f}" '
            f'y2="{y:.1f}" stroke="black" stroke-width="{2 * u:.2f}"/>'
            f'<path d="{ticks}" stroke="black" stroke-width="{u:.2f}"/>'
            f'<text x="{x:.1f}" y="{y + fs + 6 * u:.1f}">0</text>'
            f'<text x="{x + L:.1f}" y="{y + fs + 6 * u:.1f}" text-anchor="middle">'
            f"{SCALE_BAR_MM:g} mm</text></g>")


def _legend(x: float, fs: float, classes: list[str], springs: bool,
            max_x: float, k: float = 1.0) -> tuple[str, int]:
    """Colour key from ``x`` on the baseline y = 0, wrapped into rows that end by ``max_x``;
    returns the SVG and the number of rows."""
    names = {"in": "input slider", "cn": "fan-out bar, rod", "bad": "not solved"}
    names.update({"L0": "cell slider (layer 0)", "L1": "bar (layer 1)",
                  "L2": "lever (layer 2)", "L3": "layer 3", "L4": "layer 4+"})
    order = ["in", "L0", "L1", "L2", "L3", "L4", "cn", "bad"]
    items = [(c, names[c]) for c in order if c in classes]
    items += [("spring", "spring")] if springs else []
    items += [("ground", "ground (pivot, anchor, stop)")]
    items += [("cell", "cell: id TYPE"), ("io", "inputs left, outputs right")]
    out = ['<g class="legend">']
    cx, row = x, 0
    for key, text in items:
        step = fs * 2.6 + _text_w(text, fs)
        if cx > x and cx + step > max_x:
            cx, row = x, row + 1
        y = row * 1.6 * fs
        if key == "spring":
            out.append(f'<path class="sp" d="M{cx:.1f},{y - fs * 0.3:.1f}' + "".join(
                f"L{cx + 3 * (i + 1):.1f},{y - fs * 0.3 + (3 if i % 2 else -3):.1f}"
                for i in range(6)) + '"/>')
        elif key == "ground":
            out.append(_ground(cx + fs * 0.8, y - fs * 0.6, (0.0, -1.0), fs * 1.2))
        elif key == "cell":
            out.append(f'<g class="box"><rect x="{cx:.1f}" y="{y - fs * 0.8:.1f}" '
                       f'width="{fs * 1.6:.1f}" height="{fs:.1f}"/></g>')
        elif key == "io":
            out.append(f'<text x="{cx:.1f}" y="{y:.1f}" fill="#08519c" font-weight="bold">'
                       f'A</text><text x="{cx + fs:.1f}" y="{y:.1f}" fill="#006d2c" '
                       'font-weight="bold">Z</text>')
        else:
            box = (f'x="{cx:.1f}" y="{y - fs * 0.8:.1f}" width="{fs * 1.6:.1f}" '
                   f'height="{fs:.1f}"')
            out.append(f'<g class="{key}"><rect class="o" {box}/><rect class="f" {box}/></g>')
        out.append(f'<text x="{cx + fs * 2:.1f}" y="{y:.1f}">{text}</text>')
        cx += step
    out.append("</g>")
    return "".join(out), row + 1
