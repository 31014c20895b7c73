"""Routing of the nets: which plane each fan-out bar and each rod sits on.

Every net is a fan-out bar on its driver's output slider (an arm to a vertical bar in the
channel) and one straight horizontal rod per load. These pieces sit on planes above every plane
a cell uses, so a rod may pass over cells (a feedback rod runs back over the columns it skips)
and cross the channels freely. Two pieces may share a plane only when they can never come within
the clearance of each other in any state:

- pieces of one net move together (the driver's travel, carried unchanged by horizontal rods
  between horizontal sliders), so two rods of one net meet only if their outlines at the design
  pose do; a rod and its own fan-out bar always conflict: the pin that joins them passes through
  two plates, so the rod's end and the bar it is pinned to lie on different planes (a rod on its
  bar's plane would overlap it at the pin);
- pieces of two nets move independently along their axes by up to ``sweep`` either way, so they
  meet if their outlines, each stretched by its sweep, come within the clearance.

Each conflict is an edge of a graph whose vertices are the pieces; a greedy colouring of that
graph (DSATUR order: the most constrained piece first) gives the planes, colour c on
plane ``base + c``. The rectangles are the pieces' bounding boxes (exact for these
axis-aligned bars), so the test is conservative only in the sweep, never short.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np
import shapely

from mechc.ir.mechanism import Mechanism
from mechc.parts.pushrod import net_rods

Rect = tuple[float, float, float, float]  # x0, y0, x1, y1


@dataclass(frozen=True)
class Piece:
    """A net's fan-out bar (``rod`` empty: the arm and vertical bar, one body) or one rod."""

    key: str
    net: str
    rects: tuple[Rect, ...]  # at the design pose
    sweep: tuple[float, float]  # how far it can move from the design pose, either way, x and y
    rod: bool


def _gap(a: Rect, b: Rect, sx: float, sy: float) -> float:
    """Closest approach of two rectangles when they may shift by up to (sx, sy) relative to
    each other."""
    dx = max(a[0] - b[2], b[0] - a[2], 0.0)
    dy = max(a[1] - b[3], b[1] - a[3], 0.0)
    return math.hypot(max(0.0, dx - sx), max(0.0, dy - sy))


def conflict(p: Piece, q: Piece, clearance: float) -> bool:
    """Whether ``p`` and ``q`` could come within ``clearance`` of each other in some state."""
    if p.net == q.net:
        if p.rod != q.rod:  # a rod and its own fan-out bar: pinned, one plate over the other
            return True
        sx = sy = 0.0  # one net moves as one
    else:
        sx, sy = p.sweep[0] + q.sweep[0], p.sweep[1] + q.sweep[1]
    return any(_gap(a, b, sx, sy) < clearance for a in p.rects for b in q.rects)


def assign_planes(pieces: list[Piece], clearance: float, base: int) -> dict[str, int]:
    """A plane per piece (``base`` and up) such that no two pieces that could meet share one;
    few planes by a greedy colouring of the conflict graph."""
    adj: dict[str, set[str]] = {p.key: set() for p in pieces}
    if not pieces:
        return {}
    for i, k in conflicting_pairs(pieces, clearance):
        adj[pieces[i].key].add(pieces[k].key)
        adj[pieces[k].key].add(pieces[i].key)
    colour = dsatur(adj, [p.key for p in pieces])
    return {k: base + c for k, c in colour.items()}


def conflicting_pairs(pieces: list[Piece], clearance: float) -> list[tuple[int, int]]:
    """Every pair (i < k) of pieces that :func:`conflict` says could meet, found in bulk:
    a spatial index (shapely STRtree) on each piece's box grown by its sweep and half the
    clearance gives the candidates, then :func:`conflict`'s test on every candidate at once
    (numpy). Thousands of rods make millions of pairs; a test per pair in Python took
    seconds per assembly."""
    box = np.array([_bbox(p) for p in pieces])
    sw = np.array([p.sweep for p in pieces], dtype=float)
    grow = np.concatenate([sw, sw], axis=1) + clearance / 2 + 1e-9  # a little more: a superset
    grown = box + grow * np.array([-1.0, -1.0, 1.0, 1.0])
    geoms = shapely.box(*grown.T)
    qi, qk = shapely.STRtree(geoms).query(geoms, predicate="intersects")
    keep = qi < qk
    qi, qk = qi[keep], qk[keep]
    if not len(qi):
        return []
    order = np.lexsort((qk, qi))
    qi, qk = qi[order], qk[order]
    nets = {net: j for j, net in enumerate(sorted({p.net for p in pieces}))}
    net = np.array([nets[p.net] for p in pieces])
    rod = np.array([p.rod for p in pieces])
    width = max(len(p.rects) for p in pieces)
    rects = np.array([[*p.rects, *[p.rects[0]] * (width - len(p.rects))] for p in pieces],
                     dtype=float)  # (n, width, 4): a piece's first rectangle repeats
    same = net[qi] == net[qk]
    hit = same & (rod[qi] != rod[qk])  # a rod and its own fan-out bar: pinned, on two plates
    sx = np.where(same, 0.0, sw[qi, 0] + sw[qk, 0])  # one net moves as one
    sy = np.where(same, 0.0, sw[qi, 1] + sw[qk, 1])
    for u in range(width):
        a = rects[qi, u]
        for v in range(width):
            b = rects[qk, v]
            dx = np.maximum(np.maximum(a[:, 0] - b[:, 2], b[:, 0] - a[:, 2]), 0.0)
            dy = np.maximum(np.maximum(a[:, 1] - b[:, 3], b[:, 1] - a[:, 3]), 0.0)
            hit |= np.hypot(np.maximum(0.0, dx - sx), np.maximum(0.0, dy - sy)) < clearance
    return list(zip(qi[hit].tolist(), qk[hit].tolist()))


def dsatur(adj: dict[str, set[str]], order: list[str]) -> dict[str, int]:
    """Greedy colouring in DSATUR order (Brélaz): next the uncoloured vertex whose neighbours
    already use the most colours, then the one of most neighbours, then the first in
    ``order``; each takes the smallest colour none of its neighbours has. A heap with stale
    entries skipped keeps it O((V + E) log V) (networkx's DSATUR rescans every vertex per step:
    16 s on a design of 856 rods)."""
    rank = {k: i for i, k in enumerate(order)}
    seen: dict[str, set[int]] = {k: set() for k in order}
    heap = [(0, -len(adj[k]), rank[k], k) for k in order]
    heapq.heapify(heap)
    colour: dict[str, int] = {}
    while heap:
        sat, _, _, k = heapq.heappop(heap)
        if k in colour or -sat != len(seen[k]):
            continue  # coloured already, or an entry from before its saturation grew
        c = 0
        while c in seen[k]:
            c += 1
        colour[k] = c
        for nb in adj[k]:
            if nb not in colour and c not in seen[nb]:
                seen[nb].add(c)
                heapq.heappush(heap, (-len(seen[nb]), -len(adj[nb]), rank[nb], nb))
    return colour


def _bbox(p: Piece) -> Rect:
    return (min(r[0] for r in p.rects), min(r[1] for r in p.rects),
            max(r[2] for r in p.rects), max(r[3] for r in p.rects))


def interconnect_stats(mech: Mechanism) -> dict:
    """The routing figures of a mechanism: the planes its parts use, the total length of its
    net rods (pin to pin) and their bends (every rod is straight: 0)."""
    planes: set[int] = set()
    for part in mech.all_parts():
        for b in part.bodies:
            planes.update(b.poly_layers or [b.layer])
    rods = [r for part in mech.nets.values() for r in net_rods(part)]
    return {"planes": {"count": len(planes), "used": sorted(planes)},
            "rods": len(rods),
            "rod_length_mm": round(sum(r.length for r in rods), 3),
            "bends": 0}
