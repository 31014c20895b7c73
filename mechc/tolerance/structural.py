"""Structural error (the linkage-computer measure, after Svoboda's *Computing Mechanisms and
Linkages*): for every output, how far its positions at rest scatter from the nominal design's
against the stroke, and the margin to mid-stroke it keeps at a given yield."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechc.tolerance.batch import Batch
from mechc.tolerance.sequential import SequentialBatch


@dataclass
class OutputError:
    output: str
    stroke_mm: float
    spread_mm: tuple[float, float]  # central `yield_level` of rest deviations from nominal
    extreme_mm: tuple[float, float]  # smallest and largest over every sample
    lost_mm: float  # the most the pins' play adds at rest (either way)
    mid_margin_mm: float  # distance from mid-stroke kept by `yield_level` of the samples
    nominal_mid_margin_mm: float
    yield_level: float

    def to_json(self) -> dict:
        r = lambda v: round(float(v), 5)  # noqa: E731
        return {"output": self.output, "stroke_mm": r(self.stroke_mm),
                "spread_mm": [r(v) for v in self.spread_mm],
                "extreme_mm": [r(v) for v in self.extreme_mm], "lost_motion_mm": r(self.lost_mm),
                "mid_stroke_margin_mm": r(self.mid_margin_mm),
                "nominal_mid_stroke_margin_mm": r(self.nominal_mid_margin_mm),
                "at_yield": self.yield_level}


def structural_error(batch: Batch | SequentialBatch, rest_pos: dict[str, np.ndarray],
                     nominal_pos: dict[str, np.ndarray], yield_level: float) -> list[OutputError]:
    """``rest_pos``: per output the (N, rest points) signals of every sample at the points
    ``batch.rest_reference`` names (a combinational design's rest states, a sequential one's
    step ends); ``nominal_pos``: (1, rest points) of the nominal design."""
    S = batch.mech.ctx.stroke
    out = []
    for o, pos in rest_pos.items():
        at, want, lost = batch.rest_reference(o)
        if not len(at):
            continue
        if pos.shape[1] != len(at):  # a combinational batch keeps every rest state
            pos = pos[:, at]
        nom = nominal_pos[o][0]
        nom = nom[at] if len(nom) != len(at) else nom
        dev = (pos - nom[None, :]) * S
        dev = np.where(np.isfinite(dev), dev, np.nan)
        lo_q, hi_q = (1 - yield_level) / 2, (1 + yield_level) / 2
        with np.errstate(invalid="ignore"):
            mid = (0.5 - np.abs(pos - want[None, :]) - lost[None, :]) * S
        mid = np.where(np.isfinite(mid), mid, -np.inf).min(axis=1)
        nom_mid = float(((0.5 - np.abs(nom - want) - lost) * S).min())
        flat = dev[np.isfinite(dev)]
        spread = (float(np.quantile(flat, lo_q)), float(np.quantile(flat, hi_q))) if flat.size \
            else (np.nan, np.nan)
        extreme = (float(flat.min()), float(flat.max())) if flat.size else (np.nan, np.nan)
        at_yield = float(np.quantile(mid, 1 - yield_level, method="lower"))
        out.append(OutputError(o, S, spread, extreme, float(lost.max() * S) if lost.size
                               else 0.0, at_yield, nom_mid, yield_level))
    return out
