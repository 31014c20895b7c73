"""``mechc view``: one self-contained HTML page that animates a design (``animation.py``'s
model), with input toggles, play/pause, a time slider, outputs, planes, zoom and pan.

The page is the data (JSON in a ``<script type="application/json">``), the style and the
script (``viewer.css``, ``viewer.js``, shipped beside this module) inlined into one file: it
opens from disk in any browser, with no server and nothing fetched. The script draws the
bodies as SVG paths once and moves each by a transform per frame.
"""

from __future__ import annotations

import json
import math
from importlib import resources
from xml.sax.saxutils import escape

import numpy as np

from mechc import __version__
from mechc.backends.animation import HOLD_S, Animation, Segment


def page(anim: Animation) -> str:
    """The HTML text of the viewer for ``anim``."""
    data = json.dumps(to_json(anim), separators=(",", ":"), allow_nan=False)
    data = data.replace("</", "<\\/")  # never closes the script element early
    here = resources.files("mechc.backends")
    css = here.joinpath("viewer.css").read_text(encoding="utf-8")
    js = here.joinpath("viewer.js").read_text(encoding="utf-8")
    title = escape(anim.title or "mechc view")
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<title>{title}</title>\n"
        f"<meta name=\"generator\" content=\"mechc {__version__}\">\n"
        # nothing may be fetched: no network, no other file
        "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
        "script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:\">\n"
        f"<style>\n{css}</style>\n</head>\n<body>\n"
        f"<script type=\"application/json\" id=\"mechc-data\">{data}</script>\n"
        f"<script>\n{js}</script>\n</body>\n</html>\n")


def to_json(anim: Animation) -> dict:
    """The page's data: bodies (outlines per plane), cases (times and poses), the state graph
    and the tour."""
    outs = {t["body"] for t in anim.terminals["outputs"].values()}
    bodies = []
    for b in anim.bodies:
        planes = b.get("poly_layers") or [b["layer"]] * len(b["outline"])
        owner = b["owner"]
        cls = ("in" if owner.startswith("in:") else "net" if owner.startswith("net:")
               else "out" if b["id"] in outs else f"L{min(int(b['layer']), 4)}")
        bodies.append({"id": b["id"], "owner": owner, "kind": b["kind"], "role": b["role"],
                       "cls": cls, "ref": b["ref"],
                       "polys": [{"plane": int(p), "pts": poly}
                                 for p, poly in zip(planes, b["outline"])]})
    return {
        "title": anim.title, "generator": f"mechc {__version__}", "level": anim.level,
        "kind": anim.kind, "inputs": anim.inputs, "outputs": anim.outputs,
        "stroke": anim.stroke, "proof": anim.proof, "bodies": bodies,
        "terminals": anim.terminals, "cells": anim.cells,
        "planes": sorted({p["plane"] for b in bodies for p in b["polys"]}),
        "cases": [{"t": _nums(c["t"], 6), "poses": _poses(c["poses"])} for c in anim.cases],
        "nodes": anim.nodes,
        "edges": {str(k): v for k, v in anim.edges.items()},
        "tour": [_seg(s) for s in anim.tour],
        "hold": HOLD_S,
    }


def _seg(s: Segment) -> dict:
    return {"case": s.case, "rev": s.reverse, "start": s.start, "end": s.end, "hold": s.hold}


def _nums(a: np.ndarray, digits: int) -> list:
    return [round(float(v), digits) for v in a]


def _poses(p: np.ndarray) -> list:
    """Per body: one [dx, dy, angle] if the body stays put through the case (most bodies, in
    a change of one input), else one per sample; null where the trace has no pose."""
    p = np.array(p, dtype=float)
    p[..., :2] = np.round(p[..., :2], 4)
    p[..., 2] = np.round(p[..., 2], 6)
    p += 0.0  # no negative zeros
    still = np.all((p == p[:1]) | (np.isnan(p) & np.isnan(p[:1])), axis=(0, 2))
    rows = np.where(np.isfinite(p), p, np.nan).transpose(1, 0, 2).tolist()  # body, sample
    out = []
    for b, keep in enumerate(still):
        col = rows[b]
        out.append(_nulls(col[0]) if keep else [_nulls(v) for v in col])
    return out


def _nulls(v: list) -> list:
    return [None if x != x else x for x in v]


def _num(v: float, digits: int) -> float | None:
    return round(float(v), digits) + 0.0 if math.isfinite(v) else None
