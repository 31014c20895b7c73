"""Nesting: where each part goes on the stock sheets, without overlap.

Every part is first turned so that its smallest enclosing rectangle lies along x (long side
horizontal), or stood upright where only that fits the sheet; the rectangles are then packed in
shelves, first fit by decreasing height (rows across the sheet, a new sheet when the rows are
full). The parts of this compiler are bars, sliders and levers, near rectangles, so packing
their rectangles loses little against a true shape nester, and a rectangle packing keeps every
pair of parts at least ``gap`` apart by construction; shapely then checks the placed outlines
themselves. A part larger than the sheet gets a sheet of its own, sized to it, and is listed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from shapely import STRtree
from shapely.affinity import rotate, translate
from shapely.geometry import Polygon


@dataclass(frozen=True)
class Placement:
    """A part on a sheet: turned by ``angle`` degrees (counter-clockwise about the world
    origin), then moved by (dx, dy), sheet coordinates with the sheet's lower left at 0, 0."""

    sheet: int
    angle: float
    dx: float
    dy: float

    def apply(self, g):
        return translate(rotate(g, self.angle, origin=(0, 0)), self.dx, self.dy)


@dataclass
class Sheets:
    size: tuple[float, float]  # the stock sheet, mm
    placements: dict[str, Placement]
    sizes: list[tuple[float, float]]  # per sheet (an oversize part's sheet is larger)
    oversize: list[str] = field(default_factory=list)


def upright_angle(g: Polygon) -> float:
    """Degrees to turn ``g`` so that the long side of its smallest rectangle is along x."""
    xs, ys = g.minimum_rotated_rectangle.exterior.coords.xy
    sides = [(math.hypot(xs[i + 1] - xs[i], ys[i + 1] - ys[i]),
              math.atan2(ys[i + 1] - ys[i], xs[i + 1] - xs[i])) for i in range(2)]
    _, a = max(sides)
    deg = -math.degrees(a)
    deg = (deg + 90.0) % 180.0 - 90.0  # the smallest turn that lays it along x
    return 0.0 if abs(deg) < 1e-9 else round(deg, 9)


def nest(parts: dict[str, Polygon], sheet: tuple[float, float], gap: float) -> Sheets:
    """Place ``parts`` (id -> outline) on sheets of ``sheet`` (width, height) mm, every part
    ``gap`` mm from the others and from the sheet's edge."""
    W, H = sheet
    boxes = []  # (id, angle, polygon turned, width, height)
    oversize = []
    for pid, g in parts.items():
        a = upright_angle(g)
        t = rotate(g, a, origin=(0, 0))
        x0, y0, x1, y1 = t.bounds
        w, h = x1 - x0, y1 - y0
        if h + 2 * gap > H and w + 2 * gap <= H and h + 2 * gap <= W:  # stand it upright
            a = a + 90.0
            t = rotate(g, a, origin=(0, 0))
            x0, y0, x1, y1 = t.bounds
            w, h = x1 - x0, y1 - y0
        if w + 2 * gap > W or h + 2 * gap > H:
            oversize.append(pid)
        boxes.append((pid, a, t, w, h))
    boxes.sort(key=lambda b: (-b[4], -b[3], b[0]))
    placements: dict[str, Placement] = {}
    sizes: list[tuple[float, float]] = []
    shelves: list[list[float]] = []  # per shelf: sheet, y of its floor, height, x used
    top: list[float] = []  # per sheet: y of the highest shelf's top
    for pid, a, t, w, h in boxes:
        x0, y0 = t.bounds[:2]
        if pid in oversize:
            sizes.append((w + 2 * gap, h + 2 * gap))
            top.append(math.inf)
            placements[pid] = Placement(len(sizes) - 1, a, gap - x0, gap - y0)
            continue
        for sh in shelves:
            s, floor, height, used = sh
            if h <= height and used + w + gap <= sizes[int(s)][0]:
                placements[pid] = Placement(int(s), a, used - x0, floor - y0)
                sh[3] = used + w + gap
                break
        else:
            s = next((i for i in range(len(sizes)) if top[i] + h + gap <= sizes[i][1]), None)
            if s is None:
                sizes.append((W, H))
                top.append(gap)
                s = len(sizes) - 1
            floor = top[s]
            top[s] = floor + h + gap
            shelves.append([s, floor, h, gap + w + gap])
            placements[pid] = Placement(s, a, gap - x0, floor - y0)
    result = Sheets((W, H), placements, sizes, sorted(oversize))
    check_clear(parts, result, gap)
    return result


def check_clear(parts: dict[str, Polygon], sheets: Sheets, gap: float) -> None:
    """Every placed part inside its sheet and ``gap`` (less 1 µm) from every other part of it:
    an AssertionError names a pair otherwise (a bug of the packing, never of the design)."""
    by_sheet: dict[int, list[tuple[str, Polygon]]] = {}
    for pid, pl in sheets.placements.items():
        by_sheet.setdefault(pl.sheet, []).append((pid, pl.apply(parts[pid])))
    for s, placed in by_sheet.items():
        w, h = sheets.sizes[s]
        frame = Polygon([(0, 0), (w, 0), (w, h), (0, h)])
        geoms = [g for _, g in placed]
        tree = STRtree(geoms)
        for i, (pid, g) in enumerate(placed):
            if not frame.buffer(1e-6).contains(g):
                raise AssertionError(f"nesting: {pid} leaves sheet {s + 1}")
            for k in tree.query(g, predicate="dwithin", distance=gap - 1e-3):
                if k > i:
                    raise AssertionError(f"nesting: {pid} and {placed[k][0]} closer than "
                                         f"{gap} mm on sheet {s + 1}")
