"""The DXF back end: cut sheets for a laser or water-jet cutter, written with ezdxf.

One layer per plane (``plane 0``, ``plane 1``, ...) holds the cut lines of that plane's parts:
each part's outline as a closed polyline, its pin holes as circles (slots as rounded
polylines); ``plane N labels`` holds each part's name (engrave it, or hide the layer), and
``sheets`` the stock sheets' borders and titles (never cut). Every plane is cut from the same
plate, so all parts are nested together (mechc/backends/nest.py) on as few sheets as the
packing finds, side by side in the drawing; ``by_plane`` gives each plane sheets of its own,
one row per plane. The links of rod joints go on the planes the parts list gives them
(mechc/backends/fabrication.py), and the frame's plates (base plate, stop blocks) on layer
``frame``. Millimetres, set in the header ($INSUNITS 4, $MEASUREMENT 1).

Every outline carries, as XDATA of the application ``MECHC``, the part's name, plane and the
placement that put it on the sheet (turn in degrees about the design's origin, then the
move), so a reader can put any part back where the design has it. Two runs on one design give
identical files.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import ezdxf
from ezdxf import units
from ezdxf.enums import TextEntityAlignment
from shapely.geometry import LineString, Point

from mechc.backends.fabrication import Fabrication, Hole, Piece
from mechc.backends.nest import Placement, nest

APPID = "MECHC"
FRAME = "frame"
SHEETS = "sheets"
#: Room between rows and columns of sheets in the drawing (titles sit in it), mm.
SHEET_SPACING = 60.0
#: Plane colours (AutoCAD colour index), so planes read apart on screen.
COLOURS = (1, 5, 94, 6, 30, 150, 200, 12, 8, 3)


@dataclass(frozen=True)
class SheetInfo:
    group: str  # "all planes", or with by_plane a cut layer: "plane N" or "frame"
    index: int  # sheet number within its group, from 0 (XDATA's sheet: the index in the list)
    origin: tuple[float, float]  # lower left in the drawing, mm
    size: tuple[float, float]
    parts: int


@dataclass
class DxfResult:
    text: str
    sheets: list[SheetInfo]
    oversize: list[str]


def layer_name(piece: Piece) -> str:
    """The cut layer of ``piece``: its plane's, or the frame's."""
    return FRAME if piece.kind == "frame" or piece.plane is None else f"plane {piece.plane}"


def write_dxf(fab: Fabrication, sheet: tuple[float, float] = (1000.0, 600.0),
              gap: float = 3.0, by_plane: bool = False) -> DxfResult:
    """The cut sheets of ``fab`` as DXF text (see the module docstring). All parts share the
    sheets (they are one plate stock), each on its plane's layer; ``by_plane``: each plane's
    parts on sheets of their own, one row of sheets per plane. The same text on every run:
    ezdxf's fixed metadata (no dates, no random GUIDs) while this document is made."""
    was = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    try:
        return _write(fab, sheet, gap, by_plane)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = was


def _write(fab: Fabrication, sheet: tuple[float, float], gap: float,
           by_plane: bool) -> DxfResult:
    doc = ezdxf.new("R2010", setup=True, units=units.MM)
    doc.header["$MEASUREMENT"] = 1  # metric
    doc.header["$LUNITS"] = 2  # decimal
    doc.appids.add(APPID)
    doc.layers.add(SHEETS, color=8)
    msp = doc.modelspace()
    planes = sorted({p.plane for p in fab.pieces if layer_name(p) != FRAME})
    layers = [f"plane {k}" for k in planes]
    if any(layer_name(p) == FRAME for p in fab.pieces):
        layers.append(FRAME)
    for i, name in enumerate(layers):
        colour = COLOURS[i % len(COLOURS)]
        doc.layers.add(name, color=colour)
        doc.layers.add(f"{name} labels", color=colour)
    groups: dict[str, list[Piece]] = {}
    for p in fab.pieces:
        groups.setdefault(layer_name(p) if by_plane else "all planes", []).append(p)
    order = layers if by_plane else ["all planes"]
    infos: list[SheetInfo] = []
    oversize: list[str] = []
    y = 0.0
    for group in (g for g in order if g in groups):
        pieces = {p.id: p for p in groups[group]}
        nested = nest({k: p.outline for k, p in pieces.items()}, sheet, gap)
        oversize += nested.oversize
        row_h = max(h for _, h in nested.sizes)
        x = 0.0
        origins = []
        for s, (w, h) in enumerate(nested.sizes):
            origins.append((x, y - h))
            n = sum(1 for pl in nested.placements.values() if pl.sheet == s)
            infos.append(SheetInfo(group, s, (x, y - h), (w, h), n))
            _sheet_frame(msp, (x, y - h), (w, h),
                         f"{group}: sheet {s + 1} of {len(nested.sizes)}, {w:.0f} x {h:.0f} mm, "
                         f"{fab.thickness:g} mm {fab.material}, {n} parts")
            x += w + SHEET_SPACING
        for pid, pl in nested.placements.items():
            ox, oy = origins[pl.sheet]
            piece = pieces[pid]
            _part(msp, piece, Placement(pl.sheet, pl.angle, pl.dx + ox, pl.dy + oy),
                  layer_name(piece), len(infos) - len(nested.sizes) + pl.sheet)
        y -= row_h + SHEET_SPACING
    return DxfResult(_text(doc), infos, oversize)


def _text(doc) -> str:
    """The document's DXF text. ezdxf registers some CLASS records in an order that follows
    Python's string hashing, which changes between runs; sorted, the file does not (the order
    of CLASS records means nothing to a reader)."""
    doc.classes.add_required_classes(doc.dxfversion)  # what write adds (again: no-op)
    doc.classes.classes = dict(sorted(doc.classes.classes.items()))
    out = io.StringIO()
    doc.write(out)
    return out.getvalue()


def _sheet_frame(msp, origin, size, title: str) -> None:
    x, y = origin
    w, h = size
    msp.add_lwpolyline([(x, y), (x + w, y), (x + w, y + h), (x, y + h)], close=True,
                       dxfattribs={"layer": SHEETS})
    msp.add_text(title, height=8.0, dxfattribs={"layer": SHEETS}).set_placement(
        (x, y + h + 6.0), align=TextEntityAlignment.BOTTOM_LEFT)


def _part(msp, piece: Piece, pl: Placement, layer: str, sheet: int) -> None:
    g = pl.apply(piece.outline)
    e = msp.add_lwpolyline(list(g.exterior.coords)[:-1], close=True,
                           dxfattribs={"layer": layer})
    e.set_xdata(APPID, [(1000, piece.id), (1071, -1 if piece.plane is None else piece.plane),
                        (1040, pl.angle), (1040, pl.dx), (1040, pl.dy), (1071, sheet)])
    for ring in g.interiors:
        msp.add_lwpolyline(list(ring.coords)[:-1], close=True, dxfattribs={"layer": layer})
    for h in piece.holes:
        _hole(msp, h, pl, layer)
    _label(msp, piece.id, pl.apply(piece.solid()), f"{layer} labels")


def _placed_point(p, pl: Placement) -> tuple[float, float]:
    q = pl.apply(Point(p))
    return (q.x, q.y)


def _hole(msp, h: Hole, pl: Placement, layer: str) -> None:
    c = _placed_point(h.centre, pl)
    if h.end is None:
        msp.add_circle(c, h.diameter / 2, dxfattribs={"layer": layer})
        return
    e = _placed_point(h.end, pl)  # a slot: two half circles joined by straight sides
    dx, dy = e[0] - c[0], e[1] - c[1]
    n = math.hypot(dx, dy) or 1.0
    r = h.diameter / 2
    nx, ny = -dy / n * r, dx / n * r
    pts = [(c[0] - nx, c[1] - ny, 0, 0, 0), (e[0] - nx, e[1] - ny, 0, 0, 1),
           (e[0] + nx, e[1] + ny, 0, 0, 0), (c[0] + nx, c[1] + ny, 0, 0, 1)]
    msp.add_lwpolyline(pts, format="xyseb", close=True, dxfattribs={"layer": layer})


def _label(msp, text: str, g, layer: str) -> None:
    """The part's name along the longest horizontal run through it (clear of its holes), at a
    height that fits that run (text about 0.6 x its height wide per character) and the part,
    never taller than 4 mm."""
    x0, y0, x1, y1 = g.bounds
    runs = []  # (length, middle x, y)
    for k in range(1, 32):  # horizontal lines across the part
        y = y0 + (y1 - y0) * k / 32
        cut = g.intersection(LineString([(x0 - 1, y), (x1 + 1, y)]))
        for seg in getattr(cut, "geoms", [cut]):
            if seg.geom_type == "LineString" and not seg.is_empty:
                (ax, _), (bx, _) = seg.coords[0], seg.coords[-1]
                runs.append((abs(bx - ax), (ax + bx) / 2, y))
    if not runs:
        return
    run, x, _ = max(runs)
    band = sorted(r[2] for r in runs if r[0] > run - 0.5 and abs(r[1] - x) < 0.5)
    y = (band[0] + band[-1]) / 2  # the middle of the band of longest runs
    height = min(4.0, 0.6 * (y1 - y0), 0.9 * run / (0.6 * max(1, len(text))))
    msp.add_text(text, height=max(height, 0.5), dxfattribs={"layer": layer}).set_placement(
        (x, y), align=TextEntityAlignment.MIDDLE_CENTER)
