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

A fan-out bar is an arm (horizontal, from the driver to the channel) and a vertical bar. Taken
as one piece, every arm crosses the bars of the nets in the slots before it in its channel, so
a channel of k nets whose bars span the column needs k planes (216 on a 6x6 multiplier of
13,700 cells, its hazards left uncured), and every rod crossing a bar is an edge (18 million).
So the pieces are also coloured as two families on separate planes: the horizontal pieces
(rods, and the arms that meet another net's bar) and the vertical bars (each with its arm where
the arm meets none: one plate, as before). Bars of one channel are a slot apart or one above
the other (``assemble._channel_slots``) and never meet, and horizontal pieces meet only near
their own row, so both graphs stay sparse and their colourings small (that multiplier: 14
planes in all, the cells' included). An arm on a plane of its own is a plate fastened to its
bar where they overlap, as an arm is to its driver's slider.
The one graph of all pieces is still coloured while it is small (``ONE_GRAPH_EDGES``) and kept
where it needs no more planes, so small designs keep their planes.
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
    """A net's fan-out bar (neither ``rod`` nor ``arm``: the vertical bar), the arm from the
    driver to it (``arm``), or one rod (``rod``)."""

    key: str
    net: str
    rects: tuple[Rect, ...]  # at the design pose
    sweep: tuple[float, float]  # how far it can move from the design pose, either way, x and y
    rod: bool
    arm: bool = False

    @property
    def bar(self) -> bool:
        """The vertical fan-out bar, which the net's rods are pinned to."""
        return not (self.rod or self.arm)


def _gap(a: Rect, b: Rect, sx: float, sy: float) -> float:
    """Closest approach of two rectangles when they may shift by up to (sx, sy) relative to
    each other."""
    dx = max(a[0] - b[2], b[0] - a[2], 0.0)
    dy = max(a[1] - b[3], b[1] - a[3], 0.0)
    return math.hypot(max(0.0, dx - sx), max(0.0, dy - sy))


def conflict(p: Piece, q: Piece, clearance: float) -> bool:
    """Whether ``p`` and ``q`` could come within ``clearance`` of each other in some state."""
    if p.net == q.net:
        if (p.rod and q.bar) or (p.bar and q.rod):  # a rod and its own fan-out bar: pinned,
            return True  # one plate over the other
        sx = sy = 0.0  # one net moves as one
    else:
        sx, sy = p.sweep[0] + q.sweep[0], p.sweep[1] + q.sweep[1]
    return any(_gap(a, b, sx, sy) < clearance for a in p.rects for b in q.rects)


def assign_planes(pieces: list[Piece], clearance: float, base: int) -> dict[str, int]:
    """A plane per piece (``base`` and up) such that no two pieces that could meet share one,
    by greedy colourings of conflict graphs (see the module docstring): the split into a
    horizontal and a vertical family always, and one graph of all pieces (each arm with its
    bar) while that graph stays under ``ONE_GRAPH_EDGES`` edges per piece; the colouring of
    fewer planes is kept, the one graph's on a tie."""
    if not pieces:
        return {}
    bar_of = {p.net: p for p in pieces if p.bar}
    arm_of = {p.net: p for p in pieces if p.arm}
    split = _split_colouring(pieces, bar_of, clearance)
    whole = [p for p in pieces if p.rod] + [_merged(p, arm_of.get(p.net)) for p in pieces
                                            if p.bar]
    rank = {p.key: i for i, p in enumerate(pieces)}
    whole.sort(key=lambda p: rank[p.key])
    codes = _conflict_codes(whole, clearance, limit=ONE_GRAPH_EDGES * len(whole))
    if codes is not None:
        colour = dsatur_indexed(len(whole), codes // len(whole), codes % len(whole))
        if max(colour) + 1 <= max(split.values()) + 1:
            one = {p.key: c for p, c in zip(whole, colour)}
            one.update((a.key, one[bar_of[a.net].key]) for a in arm_of.values() if a.net in bar_of)
            return {k: base + c for k, c in one.items()}
    return {k: base + c for k, c in split.items()}


#: The one graph of all pieces is coloured too while it has fewer edges than this per piece
#: (rods crossing long fan-out bars make it grow with the square of the design: 470 per piece,
#: 18 million edges, on the 13,700-cell multiplier; 43 per piece on the 1322-cell ALU).
ONE_GRAPH_EDGES = 64


def _merged(bar: Piece, arm: Piece | None) -> Piece:
    """A net's arm and bar as one piece (one plane), keyed by the bar."""
    if arm is None:
        return bar
    return Piece(bar.key, bar.net, (*arm.rects, *bar.rects), bar.sweep, False)


def _split_colouring(pieces: list[Piece], bar_of: dict[str, Piece],
                     clearance: float) -> dict[str, int]:
    """Colours (from 0) of the two families: the horizontal pieces (rods, and arms that meet
    another net's bar), then, on colours above theirs, the vertical bars (each with its arm
    where the arm meets no other net's bar)."""
    bars = list(bar_of.values())
    arms = [p for p in pieces if p.arm]
    codes = _conflict_codes(arms + bars, clearance)
    n = len(arms) + len(bars)
    i, k = codes // max(n, 1), codes % max(n, 1)
    crossing = set(i[(i < len(arms)) & (k >= len(arms))].tolist())  # (arm, bar): arms first
    free = {p.net: p for j, p in enumerate(arms) if j not in crossing and p.net in bar_of}
    flat = [p for p in pieces if p.rod] + [p for p in arms if p.net not in free]
    vertical = [_merged(p, free.get(p.net)) for p in bars]
    out: dict[str, int] = {}
    first = 0
    for family in (flat, vertical):
        if not family:
            continue
        pairs = _conflict_codes(family, clearance)
        colour = dsatur_indexed(len(family), pairs // len(family), pairs % len(family))
        out.update((p.key, first + c) for p, c in zip(family, colour))
        first += max(colour) + 1
    out.update((p.key, out[bar_of[p.net].key]) for p in free.values())
    return out


#: Rectangles queried against the spatial index at once (bounds the candidate arrays).
_BLOCK = 4096


def conflicting_pairs(pieces: list[Piece], clearance: float) -> list[tuple[int, int]]:
    """Every pair (i < k) of pieces that :func:`conflict` says could meet (see
    :func:`_conflict_codes`)."""
    codes = _conflict_codes(pieces, clearance)
    n = max(len(pieces), 1)
    return list(zip((codes // n).tolist(), (codes % n).tolist()))


def _conflict_codes(pieces: list[Piece], clearance: float,
                    limit: int | None = None) -> np.ndarray | None:
    """Every pair (i < k) of pieces that :func:`conflict` says could meet, as ``i * n + k``
    in ascending order, found in bulk.

    Each piece's rectangles (not its bounding box: a fan-out bar's arm and bar make an L whose
    box covers a whole channel's height) go into one spatial index (shapely STRtree), each
    grown by its piece's sweep and half the clearance, so two rectangles are candidates only
    if they could come that near; :func:`conflict`'s gap test then runs on the candidate
    rectangle pairs at once (numpy), in blocks, so memory stays bounded by the block and the
    conflicts found. A rod and its own fan-out bar always conflict (pinned, on two plates)
    where their grown boxes meet, as :func:`conflict` on a candidate pair says. Boxes of whole
    pieces, all candidates tested at once, took 4.7 GB and minutes on a design of 13,700
    cells. None when more than ``limit`` conflicts are found (the search stops there)."""
    n = len(pieces)
    if n < 2:
        return np.zeros(0, dtype=np.int64)
    owner = np.array([i for i, p in enumerate(pieces) for _ in p.rects], dtype=np.int64)
    rects = np.array([r for p in pieces for r in p.rects], dtype=float).reshape(-1, 4)
    sw = np.array([p.sweep for p in pieces], dtype=float)
    nets = {net: j for j, net in enumerate(sorted({p.net for p in pieces}))}
    net = np.array([nets[p.net] for p in pieces], dtype=np.int64)
    rod = np.array([p.rod for p in pieces], dtype=bool)
    bar = np.array([p.bar for p in pieces], dtype=bool)
    grow = np.concatenate([sw, sw], axis=1) + clearance / 2 + 1e-9  # a little more: a superset
    sign = np.array([-1.0, -1.0, 1.0, 1.0])
    grown = rects + grow[owner] * sign
    geoms = shapely.box(*grown.T)
    tree = shapely.STRtree(geoms)
    found: list[np.ndarray] = []
    for lo in range(0, len(geoms), _BLOCK):
        qa, qb = tree.query(geoms[lo:lo + _BLOCK], predicate="intersects")
        qa = qa + lo
        a, b = owner[qa], owner[qb]
        keep = a < b
        qa, qb, a, b = qa[keep], qb[keep], a[keep], b[keep]
        same = net[a] == net[b]
        sx = np.where(same, 0.0, sw[a, 0] + sw[b, 0])  # one net moves as one
        sy = np.where(same, 0.0, sw[a, 1] + sw[b, 1])
        ra, rb = rects[qa], rects[qb]
        dx = np.maximum(np.maximum(ra[:, 0] - rb[:, 2], rb[:, 0] - ra[:, 2]), 0.0)
        dy = np.maximum(np.maximum(ra[:, 1] - rb[:, 3], rb[:, 1] - ra[:, 3]), 0.0)
        hit = np.hypot(np.maximum(0.0, dx - sx), np.maximum(0.0, dy - sy)) < clearance
        found.append(a[hit] * n + b[hit])
        if limit is not None and sum(map(len, found)) > limit:
            return None  # over the limit (a pair met by several rectangles counts more)
    # a rod and its own fan-out bar: pinned, on two plates, wherever their boxes, grown as
    # above, meet (the rod starts on its bar: they always do)
    box = np.array([_bbox(p) for p in pieces], dtype=float)
    gbox = box + grow * sign
    by_net: dict[int, list[int]] = {}
    for i in range(n):
        by_net.setdefault(int(net[i]), []).append(i)
    pa, pb = [], []
    for members in by_net.values():
        bars = [i for i in members if bar[i]]
        rods = [i for i in members if rod[i]]
        pa += [i for i in bars for _ in rods]
        pb += [k for _ in bars for k in rods]
    if pa:
        a, b = np.minimum(pa, pb), np.maximum(pa, pb)
        meet = ((gbox[a, 0] <= gbox[b, 2]) & (gbox[b, 0] <= gbox[a, 2])
                & (gbox[a, 1] <= gbox[b, 3]) & (gbox[b, 1] <= gbox[a, 3]))
        found.append(a[meet] * n + b[meet])
    return np.unique(np.concatenate(found)) if found else np.zeros(0, dtype=np.int64)


def dsatur(adj: dict[str, set[str]], order: list[str]) -> dict[str, int]:
    """:func:`dsatur_indexed` on a graph of named vertices (``order``: the tie-break)."""
    index = {k: i for i, k in enumerate(order)}
    a = np.array([index[k] for k in order for nb in adj[k] if index[nb] > index[k]],
                 dtype=np.int64)
    b = np.array([index[nb] for k in order for nb in adj[k] if index[nb] > index[k]],
                 dtype=np.int64)
    return dict(zip(order, dsatur_indexed(len(order), a, b)))


def dsatur_indexed(n: int, a: np.ndarray, b: np.ndarray) -> list[int]:
    """Greedy colouring of vertices ``0..n-1`` with edges ``a[i]-b[i]`` (no repeats) in
    DSATUR order (Brélaz): next the uncoloured vertex whose neighbours already use the most
    colours, then the one of most neighbours, then the lowest index; each takes the smallest
    colour none of its neighbours has. A heap with stale entries skipped keeps it
    O((V + E) log V) (networkx's DSATUR rescans every vertex per step: 16 s on a design of 856
    rods); the neighbours are arrays (CSR), not sets of names, so a million edges fit in tens
    of megabytes."""
    ends = np.concatenate([a, b])
    nbrs = np.concatenate([b, a])
    order = np.argsort(ends, kind="stable")
    start = np.searchsorted(ends[order], np.arange(n + 1)).tolist()
    flat = nbrs[order].tolist()
    degree = [start[k + 1] - start[k] for k in range(n)]
    seen: list[set[int]] = [set() for _ in range(n)]
    heap = [(0, -degree[k], k) for k in range(n)]
    heapq.heapify(heap)
    colour = [-1] * n
    while heap:
        sat, _, k = heapq.heappop(heap)
        if colour[k] >= 0 or -sat != len(seen[k]):
            continue  # coloured already, or an entry from before its saturation grew
        used = seen[k]
        c = 0
        while c in used:
            c += 1
        colour[k] = c
        for nb in flat[start[k]:start[k + 1]]:
            if colour[nb] < 0 and c not in seen[nb]:
                seen[nb].add(c)
                heapq.heappush(heap, (-len(seen[nb]), -degree[nb], nb))
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
