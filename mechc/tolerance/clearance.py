"""Interference under tolerance, as a bound: which pairs of parts on one plane that keep
apart at nominal may touch in a sample.

The nominal design is interference-checked (``mechc.physics.interference``) over the states
a tolerance run proves it in: that gives every pair of bodies on one plane its closest gap g
(pairs joined by a pin or a groove are bearings, pairs that meet at a contact abut by
design: neither is held to a gap). A sample moves each body from its nominal poses; the most
any point of a body moves in any state is at most

- its pose error, per sample, from the run's own solve: a slider's travel error |du|, a
  lever's turn error |dtheta| times its largest radius, a link's reference error plus its turn
  error times its radius (a net's rod: the larger of the bodies at its two ends, a straight
  rigid bar between them);
- plus its own drawing error: a hole or pivot placed off by up to ``tol`` in x and y (sqrt 2
  ``tol``) and its outline cut up to ``tol`` larger all round;
- plus half the pin clearance of its own pins (the play of the chain before it is in its pose
  only through its pins' positions, not their play: not covered).

A sequential design's bodies are compared at the end of every step of its walks (at rest):
mid-step a sample's MEMORY may throw a little earlier or later than the nominal one, which
moves its parts by a stroke at the same point of the walk, a difference of timing the bound
cannot use. So for a sequential design the bound covers the walks' rest states only (the
nominal gaps are still the closest over every point of the walks).

A pair may touch in a sample when g minus both bodies' moves is below zero. It is a bound,
not a proof: the largest moves need not happen in the state of the closest gap, nor towards
the other part, so it over-counts; it is reported beside the yield, not counted in it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mechc.ir.mechanism import Body, Mechanism
from mechc.parts.poses import Poses
from mechc.parts.pushrod import net_rods
from mechc.physics.interference import Interference

DRAWING = 1.0 + math.sqrt(2.0)  # a body's hole placing (sqrt 2 tol) and outline (tol)


@dataclass
class PairRisk:
    a: str
    b: str
    layer: int
    nominal_gap_mm: float
    samples: int  # samples where the bound says the pair may touch
    worst_mm: float  # the smallest bound on the gap over the samples (negative: may touch)


def radius(body: Body) -> float:
    """The largest distance of the body's outline from its reference point (its pivot)."""
    if body.pivot is None or not body.outline:
        return 0.0
    pts = np.array([p for poly in body.outline for p in poly], dtype=float)
    return float(np.hypot(pts[:, 0] - body.pivot[0], pts[:, 1] - body.pivot[1]).max())


def displacement(bodies: list[Body], poses: Poses, nominal: Poses, M: int, n: int,
                 radii: dict[str, float], last: bool = False) -> dict[str, np.ndarray]:
    """Per body, per sample: the most any of its points moves from its nominal pose over the
    ``n`` states (``poses``: M x n, ``nominal``: n; ``last``: the last state only);
    unsolvable: infinite."""
    out = {}

    def diff(now, was) -> np.ndarray:
        d = (np.broadcast_to(np.asarray(now, float), (M * n,)).reshape(M, n)
             - np.broadcast_to(np.asarray(was, float), (n,))[None, :])
        return np.where(np.isfinite(d), np.abs(d), np.inf)

    for b in bodies:
        if b.id in poses.u and b.id in nominal.u:
            d = diff(poses.u[b.id], nominal.u[b.id])
        elif b.id in poses.theta and b.id in nominal.theta:
            d = diff(poses.theta[b.id], nominal.theta[b.id]) * radii.get(b.id, 0.0)
            if b.id in poses.xy and b.id in nominal.xy:
                d = d + np.hypot(diff(poses.xy[b.id][0], nominal.xy[b.id][0]),
                                 diff(poses.xy[b.id][1], nominal.xy[b.id][1]))
        else:
            continue
        out[b.id] = d[:, -1] if last else d.max(axis=1)
    return out


class Risk:
    """Collects the bodies' moves per sample over a run's chunks; then the pairs at risk."""

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.moves: dict[str, list[np.ndarray]] = {}
        self.rod_ends = {r.body: (r.driver, r.load) for part in mech.nets.values()
                         for r in net_rods(part) if r.body is not None}

    def add(self, moves: dict[str, np.ndarray], M: int) -> None:
        for bid in set(self.moves) | set(moves):
            self.moves.setdefault(bid, []).append(moves.get(bid, np.zeros(M)))

    def bounds(self, inter: Interference, tol: float, clearance: float,
               N: int) -> dict[tuple[str, str], tuple[float, int, np.ndarray]]:
        """Per pair held to a gap at nominal: that gap, its plane, and per sample the bound
        on its gap (mm; below zero: may touch)."""
        moves = {b: np.concatenate(v) for b, v in self.moves.items()}
        zero = np.zeros(N)
        for rod, (drv, load) in self.rod_ends.items():
            moves[rod] = np.maximum(moves.get(drv, zero), moves.get(load, zero))
        extra = DRAWING * tol + clearance / 2
        return {(a, b): (r.gap, r.layer,
                         r.gap - moves.get(a, zero) - moves.get(b, zero) - 2 * extra)
                for (a, b), r in sorted(inter.results.items())
                if r.limit >= 0}  # abutting faces (limit below zero) touch by design

    def pairs(self, inter: Interference, tol: float, clearance: float,
              N: int) -> tuple[list[PairRisk], np.ndarray]:
        """Every pair held to a gap at nominal, with the samples the bound says may touch it,
        and per sample whether any pair may touch."""
        any_risk = np.zeros(N, dtype=bool)
        out = []
        for (a, b), (gap, layer, bound) in self.bounds(inter, tol, clearance, N).items():
            risk = bound < 0
            any_risk |= risk
            out.append(PairRisk(a, b, layer, gap, int(risk.sum()), float(bound.min())))
        out.sort(key=lambda p: (-p.samples, p.worst_mm))
        return out, any_risk
