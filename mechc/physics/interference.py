"""Interference: parts on one plane must keep apart in every state the mechanism passes through.

pymunk collides only the contacts a design declares, and the closed forms place each body from
its joints alone, so two bars that cross on one plane would pass every other check and proof.
This measures, over the kinematic states the design-check sweep visits (every rest state and
samples along every single-input change, or the sequential walks), the smallest distance between
every pair of bodies whose polygons share a plane, and the overlap (area, and depth: the width of
the overlap region) where they pass through each other.

Cheap first, exact last (all vectorised over states):

1. per body, the distinct poses among the states (a cell's bodies move with a few inputs, so
   thousands of states hold a few dozen poses of each body), and each polygon's bounding box in
   each of those poses;
2. an STRtree on the boxes each polygon sweeps over the chunk gives the candidate pairs of
   polygons: same plane, different bodies, not exempt, swept boxes within the clearance (plus
   ``REPORT_BAND_MM``, so a passing design still shows its margin);
3. per candidate pair, the distinct pose pairs whose boxes come that near get the exact
   shapely distance (and intersection area and depth where they touch); the rest are clear by
   their boxes, whose distance never exceeds the polygons'.

What is exempt is decided by ``exempt_pairs`` (see its docstring and docs/mechanism.md).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import shapely

from mechc.ir.check import Check
from mechc.ir.mechanism import GROUND, Body, Mechanism
from mechc.parts.poses import Poses
from mechc.physics.closed_form import position

DEFAULT_CLEARANCE_MM = 1.0
NAME = "interference"
# two contact faces abut by design: they may touch, but not pass into each other further than
# this (rounding of the closed forms and of the written outlines, 1e-3 mm, stays far below)
CONTACT_OVERLAP_MM = 0.01
# pairs within the clearance plus this are measured exactly, so a passing design still reports
# its closest gap (its margin) when that is near the limit
REPORT_BAND_MM = 1.0
# small chunks (a sequential walk feeds one transition at a time) are measured together: the
# cost of a chunk is mostly per body, not per state
BATCH_STATES = 1024
_KEY_DECIMALS = 9  # poses equal to 1e-9 mm / rad are one pose


#: joint kinds whose two bodies overlap at the joint by construction (the outlines are solid
#: plates: a pin's bearing and a groove's slot are not cut out of them)
BEARING_JOINTS = frozenset({"pin", "groove"})
#: joint kinds whose two bodies' faces meet by design (a lug pushing a bar, a hook holding one
#: back, a roller on a cam): they may touch, not pass into each other
ABUTTING_JOINTS = frozenset({"contact", "touch"})


def exempt_pairs(mech: Mechanism) -> dict[frozenset[str], str]:
    """Pairs of bodies the clearance does not apply to: ``"bearing"`` (exempt entirely) or
    ``"abut"`` (may touch, must not overlap by more than ``CONTACT_OVERLAP_MM``).

    A pair joined by a pin or a groove is a bearing: exempt. A pair joined only by contacts or
    touches abuts. Everything else is held to the clearance: bodies joined by a rod (the rod
    lies between them: they are separate plates that must not meet), bodies joined by a spring
    only (a wire between anchors), and joint kinds this check does not know. The ground has no
    outline (stops and guides are joints to it), so it is never one of a pair."""
    out: dict[frozenset[str], str] = {}
    for part in mech.all_parts():
        for j in part.joints:
            if GROUND in (j.a, j.b) or j.a == j.b:
                continue
            key = frozenset((j.a, j.b))
            if j.kind in BEARING_JOINTS:
                out[key] = "bearing"
            elif j.kind in ABUTTING_JOINTS:
                out.setdefault(key, "abut")
    return out


@dataclass
class PairResult:
    """The worst state of one pair of bodies on one plane."""

    gap: float  # mm: distance where apart, minus the overlap depth where they overlap
    area: float  # mm^2 of overlap in that state
    layer: int
    state: str  # the inputs (and memory states) of that state, in words
    limit: float  # the clearance, or minus the contact tolerance for abutting pairs
    failed_states: int = 0  # states in which the pair is closer than the limit


class Interference:
    """Running closest approach of every pair of bodies sharing a plane, over chunks of
    kinematic states (fed like ``CheckStats``: ``add(poses)`` per chunk, ``checks()`` at the
    end)."""

    def __init__(self, mech: Mechanism, clearance: float = DEFAULT_CLEARANCE_MM):
        self.mech = mech
        self.clearance = float(clearance)
        self.near = self.clearance + REPORT_BAND_MM  # measured exactly within this
        self.bodies = mech.body_index()
        self.exempt = exempt_pairs(mech)
        self._results: dict[tuple[str, str], PairResult] = {}
        self.states = 0
        self.seconds = 0.0
        S = mech.ctx.stroke
        self._inputs = {name: (part.terminals[name].body, S) for name, part in mech.inputs.items()}
        # one row per polygon: its body, its plane, its vertices at the design pose
        self._poly_body: list[str] = []
        self._poly_layer: list[int] = []
        self._verts: list[np.ndarray] = []
        for b in self.bodies.values():
            for i, poly in enumerate(b.outline):
                if len(poly) >= 3:
                    self._poly_body.append(b.id)
                    self._poly_layer.append(b.layer_of(i))
                    self._verts.append(np.asarray(poly, dtype=float))
        self._layer_arr = np.asarray(self._poly_layer)
        ids = {bid: k for k, bid in enumerate(self.bodies)}
        self._body_arr = np.asarray([ids[b] for b in self._poly_body], dtype=np.int64)
        self._counts: dict | None = None
        self._held: list[tuple[Poses, int]] = []  # small chunks waiting to be measured

    # ---- measuring ---------------------------------------------------------------------------
    def add(self, poses: Poses) -> None:
        """Measure one chunk of states (small chunks are held and measured together)."""
        n = _size(poses)
        if not n or not self._verts:
            return
        self.states += n
        if self._held and _keys(self._held[0][0]) != _keys(poses):
            self.flush()
        self._held.append((poses, n))
        if sum(k for _, k in self._held) >= BATCH_STATES:
            self.flush()

    def flush(self) -> None:
        """Measure the chunks held so far."""
        if not self._held:
            return
        t0 = time.perf_counter()
        poses, n = _joined(self._held)
        self._held = []
        self._measure(poses, n)
        self.seconds += time.perf_counter() - t0

    def _measure(self, poses: Poses, n: int) -> None:
        per_body: dict[str, _BodyPoses] = {}
        for bid, body in self.bodies.items():
            per_body[bid] = _BodyPoses.of(body, poses, n)
        # each polygon's boxes in each distinct pose of its body, and the box it sweeps
        boxes: list[np.ndarray] = []
        swept = np.full((len(self._verts), 4), np.nan)
        offsets: dict[str, int] = {}
        for k, bid in enumerate(self._poly_body):
            bp = per_body[bid]
            first = offsets.setdefault(bid, k)
            xs, ys = bp.vertices[k - first]
            box = np.stack([xs.min(0), ys.min(0), xs.max(0), ys.max(0)], axis=1)  # (M, 4)
            boxes.append(box)
            ok = bp.valid
            if ok.any():
                swept[k] = (box[ok, 0].min(), box[ok, 1].min(), box[ok, 2].max(),
                            box[ok, 3].max())
        have = ~np.isnan(swept).any(axis=1)
        idx = np.flatnonzero(have)
        if len(idx) < 2:
            return
        # one spatial index per plane: an index of every plane at once handed each rod every
        # cell polygon it passes over (other planes), quadratic on a design of thousands
        found_i, found_j = [], []
        boxes_all = shapely.box(*swept[idx].T)
        layer = self._layer_arr[idx]
        for lay in np.unique(layer):
            on = np.flatnonzero(layer == lay)
            if len(on) < 2:
                continue
            geoms = boxes_all[on]
            qi, qj = shapely.STRtree(geoms).query(geoms, predicate="dwithin",
                                                  distance=self.near)
            found_i.append(idx[on[qi]])
            found_j.append(idx[on[qj]])
        if not found_i:
            return
        pi, pj = np.concatenate(found_i), np.concatenate(found_j)
        keep = (pi < pj) & (self._body_arr[pi] != self._body_arr[pj])
        pi, pj = pi[keep], pj[keep]
        order = np.lexsort((pj, pi))  # a fixed order, whatever the indexes' traversal
        pi, pj = pi[order], pj[order]
        by_pair: dict[tuple[str, str], list[tuple[int, int]]] = {}
        for a, b in zip(pi.tolist(), pj.tolist()):
            ba, bb = self._poly_body[a], self._poly_body[b]
            if self.exempt.get(frozenset((ba, bb))) == "bearing":
                continue
            if ba > bb:
                a, b, ba, bb = b, a, bb, ba
            by_pair.setdefault((ba, bb), []).append((a, b))
        for (ba, bb), polys in sorted(by_pair.items()):
            self._pair(ba, bb, polys, per_body, boxes, offsets, poses)

    def _pair(self, ba: str, bb: str, polys: list[tuple[int, int]],
              per_body: dict[str, _BodyPoses], boxes: list[np.ndarray],
              offsets: dict[str, int], poses: Poses) -> None:
        """One pair of bodies: exact distances in the distinct pose pairs their boxes allow."""
        A, B = per_body[ba], per_body[bb]
        both = A.valid[A.inverse] & B.valid[B.inverse]
        states = np.flatnonzero(both)
        if not len(states):
            return
        code = A.inverse[states] * len(B.valid) + B.inverse[states]
        _, first, inverse = np.unique(code, return_index=True, return_inverse=True)
        rep = states[first]  # one state per distinct pose pair
        ca, cb = A.inverse[rep], B.inverse[rep]
        contact = self.exempt.get(frozenset((ba, bb))) == "abut"
        limit = -CONTACT_OVERLAP_MM if contact else self.clearance
        best_gap, best_area, best_state, best_layer = np.inf, 0.0, -1, 0
        bad = np.zeros(len(rep), dtype=bool)  # pose pairs closer than the limit
        for a, b in polys:
            box_a, box_b = boxes[a][ca], boxes[b][cb]
            dx = np.maximum(np.maximum(box_a[:, 0] - box_b[:, 2], box_b[:, 0] - box_a[:, 2]), 0)
            dy = np.maximum(np.maximum(box_a[:, 1] - box_b[:, 3], box_b[:, 1] - box_a[:, 3]), 0)
            bound = np.hypot(dx, dy)  # never more than the polygons' distance
            # boxes near the limit (touching boxes, for faces that may abut)
            near = np.flatnonzero(bound <= 0.0 if contact else bound < self.near)
            gap = bound.copy()
            area = np.zeros(len(bound))
            if len(near):
                ga = A.geometry(a - offsets[ba])[ca[near]]
                gb = B.geometry(b - offsets[bb])[cb[near]]
                d = shapely.distance(ga, gb)
                gap[near] = d
                hit = np.flatnonzero(d <= 0.0)
                if len(hit):
                    inter = shapely.intersection(ga[hit], gb[hit])
                    ar = shapely.area(inter)
                    deep = ar > 0.0  # else they only touch (gap 0)
                    gap[near[hit[deep]]] = -overlap_depth(inter[deep])
                    area[near[hit[deep]]] = ar[deep]
            bad |= gap < limit
            k = int(np.argmin(gap))
            if gap[k] < best_gap:
                best_gap, best_area, best_state = float(gap[k]), float(area[k]), int(rep[k])
                best_layer = self._poly_layer[a]
        n_bad = int(np.count_nonzero(bad[inverse.reshape(-1)]))  # states
        old = self._results.get((ba, bb))
        if old is None or best_gap < old.gap:
            state = self._state_text(poses, best_state, len(both))
            self._results[(ba, bb)] = PairResult(best_gap, best_area, best_layer, state, limit,
                                                 (old.failed_states if old else 0) + n_bad)
        else:
            old.failed_states += n_bad

    def _state_text(self, poses: Poses, i: int, n: int) -> str:
        """The inputs of state ``i`` in words: ``A=1 B=0``, a moving input with where along
        its change it is, and the memories' states of a sequential design."""
        words, moving = [], []
        for name, (bid, S) in self._inputs.items():
            u = poses.u.get(bid)
            if u is None:
                continue
            v = float(np.broadcast_to(u, (n,))[i]) / S + 0.5
            if abs(v - round(v)) < 1e-9:
                words.append(f"{name}={int(round(v))}")
            else:
                words.append(f"{name}={v:.2f}")
                moving.append(f"{name} at {100 * v:.0f} % of its stroke")
        for cid, st in sorted(poses.state.items()):
            q = float(np.broadcast_to(st, (n,))[i])
            words.append(f"{cid}={int(q)}" if np.isfinite(q) else f"{cid}=?")
        text = " ".join(words)
        if moving:
            return f"{', '.join(moving)} (during a change; inputs {text})"
        return f"at rest, inputs {text}"

    # ---- verdicts ----------------------------------------------------------------------------
    @property
    def results(self) -> dict[tuple[str, str], PairResult]:
        """Every pair measured exactly (came within the clearance plus the report band)."""
        self.flush()
        return self._results

    def failing(self) -> list[tuple[tuple[str, str], PairResult]]:
        return [(k, r) for k, r in sorted(self.results.items()) if r.gap < r.limit]

    def checks(self) -> list[Check]:
        """One check per pair closer than its limit (its worst state), and one passing check
        for all the other pairs on one plane: the closest gap among them."""
        out: list[Check] = []
        for (ba, bb), r in self.failing():
            if r.limit < 0:
                what = (f"contact faces overrun by {-r.gap:.3g} mm (overlap {r.area:.3g} mm²) "
                        f"on plane {r.layer}")
            elif r.gap < 0:
                what = (f"overlap {r.area:.3g} mm², {-r.gap:.3g} mm deep, on plane {r.layer}")
            else:
                what = f"{r.gap:.3g} mm apart on plane {r.layer}"
            detail = (f"{what}; worst {r.state}; closer than the limit in {r.failed_states} of "
                      f"{self.states} states")
            out.append(Check(NAME, f"{ba} / {bb}", r.gap, r.limit, ">=", "mm", detail))
        counts = self.summary()
        others = counts["pairs_on_one_plane"] - counts["bearing_pairs"] - len(out)
        if others <= 0:
            return out
        clear = [(r.gap, k) for k, r in sorted(self.results.items())
                 if r.limit > 0 and r.gap >= r.limit]
        if clear:
            gap, (ba, bb) = min(clear)
            detail = (f"the closest gap, {ba} / {bb}; {len(clear)} pairs come within "
                      f"{self.near:g} mm in some state")
        else:
            gap = self.near
            detail = f"no two come within {self.near:g} mm (the value is that bound)"
        out.append(Check(NAME, f"{others} other pairs on one plane", gap, self.clearance, ">=",
                         "mm", detail))
        return out

    def summary(self) -> dict:
        """Counts for the design's stats: pairs of bodies sharing a plane, those exempt
        (``bearing``) or abutting, those measured exactly (``near``), those failing."""
        if self._counts is None:
            layers: dict[str, frozenset[int]] = {}
            for b, lay in zip(self._poly_body, self._poly_layer):
                layers[b] = layers.get(b, frozenset()) | {int(lay)}
            kinds = {"bearing": 0, "abut": 0}
            for pair, kind in self.exempt.items():
                a, b = tuple(pair)
                if a in layers and b in layers and layers[a] & layers[b]:
                    kinds[kind] += 1
            self._counts = {"pairs_on_one_plane": pairs_sharing_a_plane(list(layers.values())),
                            "bearing_pairs": kinds["bearing"], "abutting_pairs": kinds["abut"]}
        return {"clearance_mm": self.clearance, "states": self.states, **self._counts,
                "near_pairs": len(self.results), "failed_pairs": len(self.failing())}


def pairs_sharing_a_plane(layers: list[frozenset[int]]) -> int:
    """How many pairs of bodies share at least one plane, counted without listing the pairs
    (a big design has thousands of bodies on the cells' planes: millions of pairs). Bodies on
    one plane count C(n, 2) per plane; the few on several planes (a driver with its fan-out
    bar) are counted against every body on each of their planes, once per pair, and against
    each other by their distinct sets of planes (a matrix of those bodies against each other
    was quadratic in the nets: gigabytes on a design of thousands)."""
    single: dict[int, int] = {}
    multi = [ls for ls in layers if len(ls) > 1]
    for ls in layers:
        if len(ls) == 1:
            (lay,) = ls
            single[lay] = single.get(lay, 0) + 1
    count = sum(n * (n - 1) // 2 for n in single.values())
    count += sum(single.get(lay, 0) for ls in multi for lay in ls)
    groups: dict[frozenset[int], int] = {}  # bodies on several planes, by their set of planes
    for ls in multi:
        groups[ls] = groups.get(ls, 0) + 1
    sets = list(groups.items())
    for i, (a, na) in enumerate(sets):
        count += na * (na - 1) // 2
        count += sum(na * nb for b, nb in sets[i + 1:] if a & b)
    return count


def overlap_depth(inter: np.ndarray) -> np.ndarray:
    """How deep two polygons overlap (``inter``: their overlap regions, each of positive
    area): the width of the region, the shorter side of the smallest rectangle around it (for
    two bars crossing, the narrower bar's width)."""
    rect = shapely.oriented_envelope(inter)  # rectangles: their rings start with two sides
    xy = shapely.get_coordinates(rect)
    count = shapely.get_num_coordinates(rect)
    start = np.cumsum(count) - count
    out = np.zeros(len(inter))
    ok = count >= 3
    if ok.any():
        s = start[ok]
        a = np.hypot(*(xy[s + 1] - xy[s]).T)
        b = np.hypot(*(xy[s + 2] - xy[s + 1]).T)
        out[ok] = np.minimum(a, b)
    return out


def _keys(poses: Poses) -> tuple:
    return tuple(tuple(sorted(getattr(poses, k))) for k in ("u", "theta", "xy", "state"))


def _joined(held: list[tuple[Poses, int]]) -> tuple[Poses, int]:
    """Chunks with the same bodies as one chunk."""
    if len(held) == 1:
        return held[0]
    n = sum(k for _, k in held)

    def cat(arrays):
        return np.concatenate([np.broadcast_to(np.asarray(a, dtype=float), (k,))
                               for a, (_, k) in zip(arrays, held)])

    first = held[0][0]
    out = Poses()
    for field in ("u", "theta", "state"):
        for key in getattr(first, field):
            getattr(out, field)[key] = cat([getattr(p, field)[key] for p, _ in held])
    for key in first.xy:
        out.xy[key] = (cat([p.xy[key][0] for p, _ in held]), cat([p.xy[key][1] for p, _ in held]))
    return out, n


def _size(poses: Poses) -> int:
    n = 0
    for d in (poses.u, poses.theta):
        for v in d.values():
            n = max(n, int(np.size(v)))
    return n


@dataclass
class _BodyPoses:
    """One body's distinct poses among a chunk's states."""

    body: Body
    inverse: np.ndarray  # state -> pose index
    valid: np.ndarray  # pose index -> solved (no NaN)
    vertices: list[tuple[np.ndarray, np.ndarray]]  # per polygon, (V, M) x and y
    _geoms: dict[int, np.ndarray]

    @staticmethod
    def of(body: Body, poses: Poses, n: int) -> _BodyPoses:
        cols = []
        if body.id in poses.u:
            cols.append(poses.u[body.id])
        if body.id in poses.theta:
            cols.append(poses.theta[body.id])
        if body.id in poses.xy:
            cols.extend(poses.xy[body.id])
        if not cols:  # nothing places it: it stays at the design pose
            key = np.zeros((n, 1))
        else:
            key = np.stack([np.broadcast_to(np.asarray(c, dtype=float), (n,)) for c in cols],
                           axis=1)
        bad = np.isnan(key).any(axis=1)
        key = np.where(np.isnan(key), np.inf, np.round(key, _KEY_DECIMALS))
        first, inverse = _distinct_rows(key)
        inverse = inverse.reshape(-1)
        valid = ~bad[first]
        polys = [np.asarray(p, dtype=float) for p in body.outline if len(p) >= 3]
        vertices = []
        if cols:
            sub = _sub_poses(body.id, poses, first, n)
            allv = np.concatenate(polys)
            x, y = position(body, sub, (allv[:, :1], allv[:, 1:]))
            x = np.broadcast_to(x, (len(allv), len(first)))
            y = np.broadcast_to(y, (len(allv), len(first)))
            s = 0
            for p in polys:
                vertices.append((x[s:s + len(p)], y[s:s + len(p)]))
                s += len(p)
        else:
            vertices = [(p[:, :1].copy(), p[:, 1:].copy()) for p in polys]
        return _BodyPoses(body, inverse, valid, vertices, {})

    def geometry(self, k: int) -> np.ndarray:
        """Polygon ``k`` of the body in each distinct pose (shapely, made once per chunk)."""
        g = self._geoms.get(k)
        if g is None:
            xs, ys = self.vertices[k]
            coords = np.stack([xs.T, ys.T], axis=2)  # (M, V, 2)
            coords = np.where(np.isfinite(coords), coords, 0.0)
            g = shapely.polygons(coords)
            self._geoms[k] = g
        return g


#: up to this many distinct poses a body's are told apart by comparing every state with each
#: (a body of a big design takes two or three); more go to ``np.unique``'s sort
FEW_POSES = 16


def _distinct_rows(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of ``key`` (states x coordinates, no NaN) as ``np.unique(key,
    axis=0, return_index=True, return_inverse=True)`` gives them (rows in ascending
    lexicographic order, the first state of each, each state's row), found without sorting
    the states when they are few: ``np.unique`` sorts rows of several columns as records,
    which took most of the interference check's time on a design of thousands of bodies."""
    n = len(key)
    firsts: list[int] = []
    masks: list[np.ndarray] = []
    left = np.ones(n, dtype=bool)
    i = 0
    while True:
        same = (key == key[i]).all(axis=1)
        firsts.append(i)
        masks.append(same)
        left &= ~same
        if not left.any():
            break
        if len(firsts) >= FEW_POSES:
            if key.shape[1] == 1:
                _, first, inverse = np.unique(key[:, 0], return_index=True,
                                              return_inverse=True)
            else:
                _, first, inverse = np.unique(key, axis=0, return_index=True,
                                              return_inverse=True)
            return first, inverse.reshape(-1)
        i = int(np.argmax(left))
    rows = key[firsts]
    order = np.lexsort(rows.T[::-1])  # first column first
    inverse = np.empty(n, dtype=np.intp)
    for rank, j in enumerate(order.tolist()):
        inverse[masks[j]] = rank
    return np.asarray(firsts, dtype=np.intp)[order], inverse


def _sub_poses(bid: str, poses: Poses, idx: np.ndarray, n: int) -> Poses:
    """The poses of body ``bid`` in the states ``idx`` only."""
    sub = Poses()
    if bid in poses.u:
        sub.u[bid] = np.broadcast_to(poses.u[bid], (n,))[idx]
    if bid in poses.theta:
        sub.theta[bid] = np.broadcast_to(poses.theta[bid], (n,))[idx]
    if bid in poses.xy:
        sub.xy[bid] = tuple(np.broadcast_to(c, (n,))[idx] for c in poses.xy[bid])
    return sub
