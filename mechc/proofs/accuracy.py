"""Accuracy on request: the cheapest dynamic settings that meet an output error, and a check
on the run that they did.

The error model (``accuracy_model.json`` beside this file) is written by
``benchmarks/speed_accuracy.py``: for a grid of time step, solver iterations and input move
time, the largest output position error against the closed form (fraction of stroke) over the
benchmark circuits, whether the solver held (no joint stretch, contact overrun or failure to
settle), and the steps one input change takes. Cost is machine-independent: steps per change ×
(iterations + the per-step overhead expressed in iterations, measured by the benchmark).

A choice is only a prediction from other circuits, so :func:`confirm` measures it on the design
itself: the proof's own error against the closed form, and a step-halving check (the first
changes run again at half the time step; for a first-order method the error of the coarse run
is about twice the difference between the two). Both must stay within the requested error.
:func:`mechc.proofs.dynamic.prove_with_accuracy` runs the proof that way.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from mechc.errors import UsageError

MODEL_PATH = Path(__file__).with_name("accuracy_model.json")
SAFETY = 0.5  # choose settings whose modelled error is at most this share of the request
HALVING_CASES = 4  # changes re-run at half the step
HALVING_FACTOR = 2.0  # error of the coarse run ~ 2 x |coarse - fine| (first order)


@dataclass(frozen=True)
class ModelPoint:
    dt: float
    iterations: int
    move_time: float
    error: float  # fraction of stroke, worst benchmark circuit (inf if the solver failed)
    solver_ok: bool
    steps_per_change: float

    def cost(self, overhead: float) -> float:
        return self.steps_per_change * (self.iterations + overhead)


@dataclass
class ErrorModel:
    points: list[ModelPoint]
    overhead_iterations: float  # per-step work outside the solver, in solver iterations
    source: str = ""

    def to_json(self) -> dict:
        return {"format": "mechc-accuracy-model", "version": 1, "source": self.source,
                "overhead_iterations": round(self.overhead_iterations, 4),
                "points": [{"dt_s": p.dt, "iterations": p.iterations,
                            "move_time_s": p.move_time,
                            "error_fraction": (round(p.error, 6) if p.error != float("inf")
                                               else None),
                            "solver_ok": p.solver_ok,
                            "steps_per_change": round(p.steps_per_change, 2)}
                           for p in self.points]}

    @staticmethod
    def from_json(d: dict) -> ErrorModel:
        if d.get("format") != "mechc-accuracy-model":
            raise UsageError("not a mechc accuracy model")
        pts = [ModelPoint(float(p["dt_s"]), int(p["iterations"]), float(p["move_time_s"]),
                          float("inf") if p["error_fraction"] is None
                          else float(p["error_fraction"]),
                          bool(p["solver_ok"]), float(p["steps_per_change"]))
               for p in d["points"]]
        return ErrorModel(pts, float(d["overhead_iterations"]), d.get("source", ""))


def load_model(path: Path | str | None = None) -> ErrorModel:
    p = Path(path) if path else MODEL_PATH
    if not p.exists():
        raise UsageError(f"no accuracy model at {p}: run benchmarks/speed_accuracy.py to "
                         "measure one")
    return ErrorModel.from_json(json.loads(p.read_text()))


def choose(target: float, model: ErrorModel, safety: float = SAFETY) -> ModelPoint:
    """The cheapest measured settings whose modelled error is within ``safety × target`` and
    whose solver held on every benchmark circuit."""
    if not 0 < target < 0.5:
        raise UsageError("--accuracy must be between 0 and 0.5 (fraction of stroke)")
    ok = [p for p in model.points if p.solver_ok and p.error <= safety * target]
    if not ok:
        best = min((p.error for p in model.points if p.solver_ok), default=float("inf"))
        raise UsageError(f"no measured setting reaches an output error of {target:g} of stroke "
                         f"(the best measured is {best:.3g}; the model asks for "
                         f"{safety:g} x the target as margin)")
    return min(ok, key=lambda p: (p.cost(model.overhead_iterations), p.error))


def halving_error(coarse: list[dict], fine: list[dict]) -> float:
    """Estimated error of the coarse run from the same changes run at half the step."""
    worst = 0.0
    for a, b in zip(coarse, fine):
        for o, v in a["final"].items():
            if o in b["final"]:
                d = abs(v - b["final"][o])
                worst = max(worst, HALVING_FACTOR * d if d == d else float("inf"))
    return worst


def confirm(target: float, report: Mapping, coarse: list[dict], fine: list[dict]) -> dict:
    """Whether the run met the requested error: its error against the closed form, the
    step-halving estimate, and no solver breakdown."""
    err = float(report["max_position_error_fraction"])
    halving = halving_error(coarse, fine)
    kinds = report.get("failure_kinds", {})
    broke = {k: v for k, v in kinds.items() if k in ("solver", "contact", "settle")}
    obtained = max(err, halving)
    return {"target_fraction": target, "error_vs_closed_form_fraction": round(err, 6),
            "halving_estimate_fraction": round(halving, 6),
            "halving_cases": min(len(coarse), len(fine)),
            "obtained_fraction": round(obtained, 6),
            "solver_breakdown": broke,
            "confirmed": obtained <= target and not broke}
