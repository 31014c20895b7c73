"""Kinematic level: the mechanism's closed forms on every input state and along every
single-input change.

At rest each output terminal must sit within ``tolerance`` (fraction of stroke) of the position
the spec asks for (don't-cares excepted). Along a single-input change, an output whose value is
the same at both ends (both cared for) must dwell: stay within ``tolerance`` at every sample of
the moving input. The design checks are measured on the same samples. Nothing here reads the
cells' logic types: positions come from the geometry.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.spec import Spec
from mechc.logic.cubes import DC
from mechc.parts.poses import PoseSink
from mechc.physics.closed_form import KinematicsError, Poses
from mechc.physics.evaluate import evaluate, output_signals
from mechc.physics.measures import CheckStats
from mechc.proofs.cases import bits, single_changes, try_directed
from mechc.proofs.registry import OnProgress, check_interface, engine
from mechc.proofs.report import ProofReport
from mechc.proofs.settings import ProofSettings
from mechc.proofs.trace import TraceRecorder

EXHAUSTIVE_MAX_INPUTS = 10
MAX_LISTED = 50
#: states solved per vectorised call (a sweep's chunk, at most): each closed form passes over
#: its arrays a few dozen times, so a chunk whose arrays stay in the CPU cache between passes
#: is solved faster per state than a larger one, while the solver's per-call Python is spread
#: over enough states. 8192 states are 64 KB per array: under glibc's 128 KB mmap threshold,
#: where arrays of a larger chunk can be mapped and unmapped (page faults) on every call.
SOLVE_CHUNK = 8192


def sweep(design: Design, lib: Library, samples: int = 21, seed: int = 0,
          inputs_order: list[str] | None = None, stats: PoseSink | None = None,
          budget: int = 20_000_000, sample: int = 512, max_states: int | None = None,
          on_poses: Callable[[Poses, int], None] | None = None,
          progress: OnProgress | None = None, directed: bool = False):
    """Evaluate rest states and single-input changes (``samples`` points along the moving
    input), in chunks so memory stays bounded; returns output signals only, and feeds the
    design-check statistics ``stats`` as it goes.

    Up to 10 inputs every vector and every single-input change; beyond, a seeded sample of
    ``sample`` vectors and as many changes (as boolean matrices, so any number of inputs
    works). ``on_poses`` receives the poses of every chunk of states in the order evaluated
    (the rest states, then each change's samples): a trace. ``progress`` is told the states
    evaluated so far and their total after every chunk. Beyond 10 inputs (``directed``, a
    combinational netlist) the sample is led by changes chosen to switch every cell
    (:func:`mechc.proofs.cases.directed_changes`) and by their start states."""
    mech = design.mechanism
    chosen: dict | None = None
    names = inputs_order or list(design.netlist.inputs)
    n = len(names)
    full = (1 << n) + n * (1 << max(n - 1, 0)) * samples if n <= EXHAUSTIVE_MAX_INPUTS else 0
    if n <= EXHAUSTIVE_MAX_INPUTS and (max_states is None or full <= max_states):
        rest_bits = bits(np.arange(1 << n, dtype=np.int64), n).astype(bool)
        e_rows, e_k = single_changes(n)
        edge_bits = bits(e_rows, n).astype(bool)
        exhaustive = True
    elif n <= EXHAUSTIVE_MAX_INPUTS:  # a budget: every vector, a seeded sample of changes
        rng = np.random.default_rng(seed)
        rest_bits = bits(np.arange(1 << n, dtype=np.int64), n).astype(bool)
        e_rows, e_k = single_changes(n)
        keep = rng.permutation(len(e_k))[:max(1, (max_states - (1 << n)) // samples)]
        e_k = e_k[np.sort(keep)]
        edge_bits = bits(e_rows[np.sort(keep)], n).astype(bool)
        exhaustive = False
    else:
        rng = np.random.default_rng(seed)
        rest_bits = rng.random((n, sample)) < 0.5
        e_k = rng.integers(0, n, size=sample)
        edge_bits = rng.random((n, sample)) < 0.5
        edge_bits[e_k, np.arange(len(e_k))] = False
        exhaustive = False
        dr = try_directed(design.netlist, names, seed) if directed else None
        if dr is not None:  # first the changes that switch every cell, then the random ones
            edge_bits = np.concatenate([dr.lo, edge_bits], axis=1)
            e_k = np.concatenate([dr.k, e_k])
            rest_bits = np.concatenate([dr.lo, rest_bits], axis=1)
            chosen = {**dr.coverage(), "random_changes": sample, "random_states": sample}
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    n_bodies = max(1, len(mech.body_index()))
    chunk = max(64, min(SOLVE_CHUNK, budget // (3 * n_bodies)))
    total_states = rest_bits.shape[1] + len(e_k) * samples
    done = [0]

    def run(vals: np.ndarray) -> dict[str, np.ndarray]:
        outs: dict[str, list[np.ndarray]] = {}
        for s in range(0, vals.shape[1], chunk):
            part = vals[:, s:s + chunk]
            poses = evaluate(mech, lib, types, {nm: part[k] for k, nm in enumerate(names)})
            if stats is not None:
                stats.add(poses)
            if on_poses is not None:
                on_poses(poses, part.shape[1])
            for o, v in output_signals(mech, poses).items():
                outs.setdefault(o, []).append(np.broadcast_to(v, (part.shape[1],)))
            done[0] += part.shape[1]
            if progress is not None:
                progress(done[0], total_states)
        return {o: np.concatenate(v) for o, v in outs.items()}

    rest = run(rest_bits.astype(float))
    t = np.linspace(0.0, 1.0, samples)
    per = max(1, chunk // samples)
    path: dict[str, list[np.ndarray]] = {}
    for s in range(0, len(e_k), per):
        eb, ek = edge_bits[:, s:s + per], e_k[s:s + per]
        vals = np.repeat(eb.astype(float), samples, axis=1)
        moving = np.repeat(ek, samples)
        vals[moving, np.arange(vals.shape[1])] = np.tile(t, len(ek))
        for o, v in run(vals).items():
            path.setdefault(o, []).append(v)
    return dict(names=names, rest_bits=rest_bits, rest=rest, edge_bits=edge_bits, e_k=e_k,
                path={o: np.concatenate(v) for o, v in path.items()}, samples=samples,
                exhaustive=exhaustive, directed=chosen)


@engine("kinematic", "combinational")
def kinematic_engine(design: Design, spec: Spec, lib: Library, settings: ProofSettings,
                     progress: OnProgress | None) -> ProofReport:
    return prove_kinematic(design, spec, lib, tolerance=settings.tolerance, seed=settings.seed,
                           trace=settings.trace, progress=progress)


def prove_kinematic(design: Design, spec: Spec, lib: Library, tolerance: float = 0.05,
                    samples: int = 21, seed: int = 0,
                    trace: TraceRecorder | None = None,
                    progress: OnProgress | None = None) -> ProofReport:
    t0 = time.perf_counter()
    if design.mechanism is None:
        raise UsageError("the design has no geometry (compile it with this mechc version)")
    check_interface(design.netlist, spec)
    names = list(spec.inputs)
    mech = design.mechanism
    stats = CheckStats(mech)
    try:
        sw = sweep(design, lib, samples, seed, names, stats, directed=True,
                   on_poses=trace.take if trace is not None else None, progress=progress)
    except KinematicsError as e:
        raise UsageError(f"the geometry is not a determinate mechanism: {e}") from None
    if trace is not None:
        trace.add_sweep(sw, spec)
    rest_bits, edge_bits, e_k = sw["rest_bits"], sw["edge_bits"], sw["e_k"]
    rest_want = spec.values_at(rest_bits)
    lo_want = spec.values_at(edge_bits)
    hi_bits = edge_bits.copy()
    hi_bits[e_k, np.arange(len(e_k))] = True
    hi_want = spec.values_at(hi_bits)
    failures: list[dict] = []
    fail_count = 0
    max_dev = 0.0
    min_margin = 0.5
    for o in spec.outputs:
        want = rest_want[o]
        care = want != DC
        got = sw["rest"][o]
        dev = np.abs(got - want)
        dev = np.where(np.isnan(dev), np.inf, dev)
        if care.any():
            max_dev = max(max_dev, float(dev[care].max()))
            min_margin = min(min_margin, float((0.5 - dev[care]).min()))
        bad = np.flatnonzero(care & (dev > tolerance))
        fail_count += len(bad)
        for i in bad[:max(0, MAX_LISTED - len(failures))]:
            failures.append({"kind": "rest", "output": o, "inputs": _vec(rest_bits[:, i], names),
                             "expected": int(want[i]), "position": _num(got[i]),
                             "deviation_fraction": _num(dev[i])})
        # dwell along single-input changes
        lo, hi = lo_want[o], hi_want[o]
        hold = (lo == hi) & (lo != DC)
        pos = sw["path"][o].reshape(len(e_k), sw["samples"])
        d = np.abs(pos - lo[:, None])
        d = np.where(np.isnan(d), np.inf, d).max(axis=1)
        if hold.any():
            max_dev = max(max_dev, float(d[hold].max()))
            min_margin = min(min_margin, float((0.5 - d[hold]).min()))
        bad = np.flatnonzero(hold & (d > tolerance))
        fail_count += len(bad)
        for i in bad[:max(0, MAX_LISTED - len(failures))]:
            failures.append({"kind": "dwell", "output": o,
                             "inputs": _vec(edge_bits[:, i], names), "moving": names[e_k[i]],
                             "expected": int(lo[i]), "max_deviation_fraction": _num(d[i])})
    checks = stats.checks() + mech.synthesis_checks()
    for c in checks:
        if not c.passed:
            fail_count += 1
            if len(failures) < MAX_LISTED:
                failures.append({"kind": "design check", "check": c.name, "where": c.where,
                                 "value": _num(c.value), "limit": c.limit, "message": c.text()})
    mus = [c.value for c in checks if c.name == "transmission angle"]
    sing = [c.value for c in checks if c.name == "distance from toggle"]
    return ProofReport(
        level="kinematic", kind="combinational", passed=fail_count == 0,
        cases=int(rest_bits.shape[1]),
        coverage={"transitions": int(len(e_k)), "samples_per_transition": sw["samples"],
                  "exhaustive": sw["exhaustive"], "tolerance_fraction": tolerance,
                  # what an exhaustive proof would visit: a sampled one is "N of M"
                  "cases_total": 1 << len(names),
                  "transitions_total": len(names) << max(len(names) - 1, 0),
                  **(sw["directed"] or {})},
        failure_count=fail_count, failures=failures,
        figures={
            "max_deviation_fraction": round(max_dev, 9),
            # the closed forms are the reference the dynamic level is measured against, and
            # their joints close exactly (states where one cannot are counted as unsolvable
            # checks)
            "max_position_error_fraction": 0.0,
            "max_joint_violation_mm": 0.0,
            "min_margin_fraction": round(min_margin, 9),
            "min_transmission_angle_deg": round(min(mus), 4) if mus else None,
            "min_toggle_distance_deg": round(min(sing), 4) if sing else None,
            "checks": [c.to_json() for c in checks],
        },
        seconds=round(time.perf_counter() - t0, 4))


def _vec(column: np.ndarray, names: list[str]) -> dict[str, int]:
    return {nm: int(column[k]) for k, nm in enumerate(names)}


def _num(x) -> float | None:
    x = float(x)
    return None if not np.isfinite(x) else round(x, 6)
