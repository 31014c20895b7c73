"""The dynamic settings grid (time step x solver iterations x move time on the two example
circuits) and the error model fitted from it, with the per-step overhead the model's cost uses.
"""

from __future__ import annotations

import math

from mechc.bench.circuits import Circuit
from mechc.bench.harness import Bench, clock, failure_kinds, scene_types, solver_ok, time_dynamic
from mechc.physics.scene import DynSettings, Scene
from mechc.proofs.accuracy import ErrorModel, ModelPoint
from mechc.proofs.settings import dyn_settings


def grid(b: Bench, cs: list[Circuit]) -> list[dict]:
    if b.quick:
        dts, its, mts = (1e-4, 2.5e-4, 5e-4, 1e-3), (5, 20, 60), (0.04, 0.08)
    else:
        dts = (1e-4, 1.5e-4, 2.5e-4, 3.5e-4, 5e-4, 1e-3, 2e-3)
        its, mts = (3, 5, 10, 20, 40, 60), (0.04, 0.08, 0.16)
    names = ("sorter", "full_adder")
    b.say(f"\n== dynamic settings grid ({len(dts)} steps x {len(its)} iteration counts x "
          f"{len(mts)} move times on {', '.join(names)}) ==")
    out = []
    for c in [c for c in cs if c.name in names]:
        for dt in dts:
            for it in its:
                for mt in mts:
                    st = dyn_settings(c.design, dt=dt, iterations=it, move_time=mt)
                    r, secs = time_dynamic(b, c, st, prune=False)
                    out.append(b.row(section="grid", circuit=c.name, level="dynamic",
                                     variant="whole", dt_s=dt, iterations=it, move_time_s=mt,
                                     cases=r["cases"], seconds=secs,
                                     seconds_per_case=secs / max(1, r["cases"]),
                                     error_fraction=r["max_position_error_fraction"],
                                     max_violation_mm=r["max_joint_violation_mm"],
                                     passed=r["passed"], solver_ok=solver_ok(r),
                                     failure_kinds=failure_kinds(r), steps=r["steps"],
                                     default=(dt, it, mt) == (2.5e-4, 60, 0.08)))
        b.say(f"{c.name}: {sum(1 for r in out if r['circuit'] == c.name)} settings run")
    return out


def error_model(rows: list[dict], overhead: float, source: str) -> ErrorModel:
    """Per setting: the worst circuit's error (inf where the solver broke), the most steps."""
    keys = sorted({(r["dt_s"], r["iterations"], r["move_time_s"]) for r in rows})
    pts = []
    for k in keys:
        rs = [r for r in rows if (r["dt_s"], r["iterations"], r["move_time_s"]) == k]
        ok = all(r["solver_ok"] for r in rs)
        err = max(float(r["error_fraction"]) for r in rs) if ok else math.inf
        steps = max(r["steps"] / max(1, r["cases"]) for r in rs)
        pts.append(ModelPoint(k[0], k[1], k[2], err, ok, steps))
    return ErrorModel(pts, overhead, source)


def step_overhead(b: Bench, c: Circuit) -> float:
    """Per-step work outside pymunk's solver, in solver iterations: from one change run at two
    iteration counts (time per step is a + b * iterations)."""
    times = {}
    for it in (10, 60):
        st = DynSettings(iterations=it, violation_limit=0.1)
        sc = Scene.build(c.design.mechanism, b.lib, scene_types(c.design), st,
                         {k: 0.0 for k in c.design.spec.inputs})
        name = c.design.spec.inputs[0]
        t0 = clock()
        r = sc.move(name, 1.0)
        times[it] = (clock() - t0) / r.steps
    per_it = (times[60] - times[10]) / 50
    return max(0.0, (times[10] - 10 * per_it) / per_it) if per_it > 0 else 0.0

