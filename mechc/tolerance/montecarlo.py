"""The Monte Carlo run: draw every dimension within its tolerance, prove every sample at the
kinematic level (in chunks of samples solved together, ``mechc.tolerance.batch``), and count.

Each dimension in mm is drawn uniformly within +-``tol`` (every value in the band as likely:
harsher than a normal distribution with the band at 3 sigma); each spring's rate and preload
within +-``spring_tol`` of nominal. Pin clearance is the lost motion of every pin taken up the
worst way (``mechc.tolerance.sensitivity.lost_motion``). Yield is the fraction of samples that
pass every check, with a Wilson score interval.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.spec import Spec
from mechc.physics.interference import Interference
from mechc.tolerance.batch import Batch, CheckKey
from mechc.tolerance.clearance import DRAWING, PairRisk, Risk
from mechc.tolerance.dimensions import Dim, dimensions
from mechc.tolerance.sensitivity import (
    Ranked,
    by_owner,
    jacobian,
    lost_motion,
    rank,
)
from mechc.tolerance.sequential import SequentialBatch
from mechc.tolerance.states import proof_states
from mechc.tolerance.structural import OutputError, structural_error

Z95 = 1.959963984540054
SEQUENTIAL_CHUNK = 256  # samples a sequential walk carries at once (x 21 points a step)


@dataclass(frozen=True)
class ToleranceSettings:
    tol: float = 0.1  # mm, every dimension +-
    clearance: float = 0.05  # mm, diametral play of every pin in its hole
    spring_tol: float = 0.1  # fraction of a spring's rate and preload +-
    samples: int = 10_000
    seed: int = 0
    proof_tolerance: float = 0.05  # fraction of stroke an output may sit from its position
    yield_level: float = 0.99  # the structural error's margin is quoted at this yield
    chunk_states: int = 1 << 16  # samples x states solved in one evaluation

    def check(self) -> None:
        for name, v in (("--tol", self.tol), ("--clearance", self.clearance),
                        ("--spring-tol", self.spring_tol)):
            if not np.isfinite(v) or v < 0:
                raise UsageError(f"{name} must be a number >= 0 (got {v})")
        if self.spring_tol >= 1:
            raise UsageError("--spring-tol is a fraction of the rate: below 1")
        if self.samples < 1:
            raise UsageError("--samples must be at least 1")
        if not 0 < self.proof_tolerance < 0.5:
            raise UsageError("--proof-tolerance must be between 0 and 0.5 (fraction of stroke)")
        if not 0 < self.yield_level < 1:
            raise UsageError("--yield must be between 0 and 1")


@dataclass
class Failing:
    key: CheckKey
    count: int
    worst: float


@dataclass
class ToleranceResult:
    settings: ToleranceSettings
    dims: list[Dim]
    samples: int
    passed: int
    ci: tuple[float, float]
    failing: list[Failing]  # most frequent first
    nominal_margin_mm: dict[str, float]  # output -> proof tolerance minus worst deviation
    structural: list[OutputError]
    ranked: list[Ranked]
    per_owner: dict[str, float]
    sample_pass: np.ndarray  # (N,) bool
    fails: dict[str, np.ndarray] = field(default_factory=dict)  # check name -> (N,) failed
    # the interference bound (mechc.tolerance.clearance): pairs held to a gap at nominal and
    # the samples where they may touch; samples where any may (not counted in the yield)
    interference: list[PairRisk] = field(default_factory=list)
    interference_samples: int = 0
    interference_passing: int = 0  # of them, samples that pass every check
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def yield_(self) -> float:
        return self.passed / self.samples


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a proportion k/n (95 % by default)."""
    if n == 0:
        return (0.0, 1.0)
    p = k / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z / den * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
    return (max(0.0, float(centre - half)), min(1.0, float(centre + half)))


def tolerances(dims: list[Dim], s: ToleranceSettings) -> np.ndarray:
    return np.array([s.spring_tol if d.unit == "fraction" else s.tol for d in dims])


def draw(dims: list[Dim], s: ToleranceSettings, n: int | None = None) -> np.ndarray:
    """(n, D) deltas, uniform within each dimension's tolerance; seeded."""
    rng = np.random.default_rng(s.seed)
    tol = tolerances(dims, s)
    return rng.uniform(-1.0, 1.0, size=(n or s.samples, len(dims))) * tol[None, :]


def prepare(design: Design, lib: Library, s: ToleranceSettings):
    """The batch solver of ``design`` with its pins' lost motion, and the derivatives (a
    sequential design: its walks' batch, the derivatives taken at every point of its walks)."""
    if design.mechanism is None:
        raise UsageError("the design has no geometry (compile it with this mechc version)")
    dims = dimensions(design.mechanism)
    batch: Batch | SequentialBatch
    if design.sequential is not None or not isinstance(design.spec, Spec):
        batch = SequentialBatch(design, lib, dims, s.proof_tolerance)
        jac = jacobian(batch, per=SEQUENTIAL_CHUNK)
    else:
        batch = Batch(design, lib, proof_states(design.spec), dims, s.proof_tolerance)
        jac = jacobian(batch, s.chunk_states)
    batch.lost = lost_motion(jac, s.clearance) if s.clearance > 0 else {}
    return batch, jac


def nominal_gaps(batch: Batch | SequentialBatch, risk: Risk, s: ToleranceSettings
                 ) -> Interference:
    """The interference check of the nominal design over the run's states, measured out to
    the largest gap the samples' moves could close."""
    finite = [float(v[np.isfinite(v)].max()) for vs in risk.moves.values() for v in vs
              if np.isfinite(v).any()]
    reach = 2 * (max(finite, default=0.0) + DRAWING * s.tol + s.clearance / 2)
    inter = Interference(batch.mech, clearance=reach)
    for poses in batch.nominal_poses():
        inter.add(poses)
    return inter


def interference_risk(batch: Batch | SequentialBatch, risk: Risk, s: ToleranceSettings,
                      N: int) -> tuple[list[PairRisk], np.ndarray]:
    """Pairs on one plane and the samples the bound says may touch them."""
    return risk.pairs(nominal_gaps(batch, risk, s), s.tol, s.clearance, N)


def run(design: Design, lib: Library, s: ToleranceSettings,
        progress: Callable[[int, int], None] | None = None,
        deltas: np.ndarray | None = None) -> ToleranceResult:
    """Yield, failing checks, structural error and sensitivity of ``design``."""
    s.check()
    t0 = time.perf_counter()
    batch, jac = prepare(design, lib, s)
    t1 = time.perf_counter()
    dims = batch.dims
    X = draw(dims, s) if deltas is None else deltas
    N = X.shape[0]
    per = max(1, s.chunk_states // batch.states.size) if isinstance(batch, Batch) \
        else SEQUENTIAL_CHUNK
    passes, margins = [], []
    fails: dict[str, list[tuple[int, np.ndarray]]] = {}
    fail_count: dict[CheckKey, int] = {}
    fail_worst: dict[CheckKey, float] = {}
    rest_pos: dict[str, list[np.ndarray]] = {}
    risk = Risk(design.mechanism)
    stroke = design.mechanism.ctx.stroke
    for start in range(0, N, per):
        chunk = X[start:start + per]
        res = batch.run(chunk)
        ok = np.ones(len(chunk), dtype=bool)
        for key, v in res.checks.items():
            p = key.passed(v)
            ok &= p
            bad = ~p
            if bad.any():
                fails.setdefault(key.name, []).append((start, bad))
                fail_count[key] = fail_count.get(key, 0) + int(bad.sum())
                vv = v[bad]
                vv = np.where(np.isnan(vv), -np.inf if key.sense == ">=" else np.inf, vv)
                w = float(vv.min() if key.sense == ">=" else vv.max())
                old = fail_worst.get(key)
                fail_worst[key] = w if old is None else (
                    min(old, w) if key.sense == ">=" else max(old, w))
        passes.append(ok)
        worst = np.max(np.stack(list(res.worst_dev.values())), axis=0) if res.worst_dev \
            else np.zeros(len(chunk))
        margins.append((s.proof_tolerance - worst) * stroke)
        for o, v in res.rest_pos.items():
            rest_pos.setdefault(o, []).append(v)
        risk.add(res.moves, len(chunk))
        if progress is not None:
            progress(min(N, start + per), N)
    t2 = time.perf_counter()
    sample_pass = np.concatenate(passes)
    margin = np.concatenate(margins)
    k = int(sample_pass.sum())
    by_name = {}
    for name, parts in fails.items():
        m = np.zeros(N, dtype=bool)
        for at, bad in parts:
            m[at:at + len(bad)] |= bad
        by_name[name] = m
    failing = sorted((Failing(key, c, fail_worst[key]) for key, c in fail_count.items()),
                     key=lambda f: (-f.count, f.key.name, f.key.where))
    nominal = batch.run(np.zeros((1, len(dims))))
    nominal_margin = {o: float((s.proof_tolerance - v[0]) * stroke)
                      for o, v in nominal.worst_dev.items()}
    structural = structural_error(batch, {o: np.concatenate(v) for o, v in rest_pos.items()},
                                  nominal.rest_pos, s.yield_level) if rest_pos else []
    # a sample whose output lands on the wrong side says only "fails": clipped at minus the
    # allowance, so a few of them do not outweigh the trend of all the others
    ranked = rank(jac, tolerances(dims, s), stroke, X,
                  np.maximum(margin, -s.proof_tolerance * stroke))
    pairs, at_risk = interference_risk(batch, risk, s, N)
    t3 = time.perf_counter()
    return ToleranceResult(
        s, dims, N, k, wilson(k, N), failing, nominal_margin, structural, ranked,
        by_owner(ranked), sample_pass, by_name, pairs, int(at_risk.sum()),
        int((at_risk & sample_pass).sum()),
        {"derivatives": round(t1 - t0, 4), "samples": round(t2 - t1, 4),
         "analysis": round(t3 - t2, 4), "total": round(t3 - t0, 4)})
