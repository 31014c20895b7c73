"""Kinematic and dynamic speed of whole mechanisms (issue 3's benchmark).

For the sorter and random compiled circuits of about 10, 30 and 100 cells: kinematic input
vectors per second (every vector, vectorised closed forms), dynamic input changes per second
(pymunk at the default settings), and the output error at those defaults against the closed
form. Figures are also given relative to the sorter measured in the same run (the machine is
shared and noisy).

    python benchmarks/mechanism.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from mechc.bench.circuits import random_compiled
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.passes.assemble import MechOptions
from mechc.physics.evaluate import evaluate
from mechc.pipeline import CompileOptions, compile_spec
from mechc.proofs.dynamic import prove_dynamic

LIB = load_library()
STRONG = CompileOptions(mech=MechOptions(actuator_force=1e4))  # measure, do not gate on force


def designs(quick: bool):
    yield "sorter", compile_spec(load_spec("examples/sorter.bool"))
    for cells in (10, 30) if quick else (10, 30, 100):
        # random specs compiled by mechc to about this many cells (hazard-free, as compiled
        # designs are; raw random netlists would fail on their static hazards)
        yield f"random {cells}", random_compiled(cells, seed=cells, options=STRONG)


def kinematic_rate(d, repeat: int) -> float:
    n = len(d.netlist.inputs)
    rows = np.tile(np.arange(1 << n), max(1, 4096 >> n))
    vals = {x: ((rows >> (n - 1 - k)) & 1).astype(float) for k, x in enumerate(d.netlist.inputs)}
    types = {c.id: c.cell for c in d.netlist.cells.values()}
    evaluate(d.mechanism, LIB, types, vals)  # warm
    t0 = time.perf_counter()
    for _ in range(repeat):
        evaluate(d.mechanism, LIB, types, vals)
    return repeat * len(rows) / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="skip the 100-cell circuit")
    ap.add_argument("--cases", type=int, default=12, help="dynamic input changes per circuit")
    args = ap.parse_args()
    rows = []
    for name, d in designs(args.quick):
        kin = kinematic_rate(d, 3)
        n = len(d.netlist.inputs)
        t0 = time.perf_counter()
        r = prove_dynamic(d, d.spec, LIB, extra=0 if (1 << n) - 1 >= args.cases else args.cases)
        secs = time.perf_counter() - t0
        cases = r["cases"]
        rows.append((name, len(d.netlist.cells), r["scene"]["bodies"], kin, cases / secs,
                     r["max_position_error_fraction"], r["max_joint_violation_mm"],
                     r["passed"]))
        print(f"{name:12s} cells {rows[-1][1]:4d} bodies {rows[-1][2]:4d}  kinematic "
              f"{kin:12.0f} vectors/s  dynamic {cases / secs:7.2f} changes/s  "
              f"error {r['max_position_error_fraction']:.4f} of stroke  joint "
              f"{r['max_joint_violation_mm']:.4f} mm  {'pass' if r['passed'] else 'FAIL'}",
              flush=True)
    base = rows[0]
    for name, _cells, _b, kin, dyn, err, _vio, _ok in rows:
        key = name.replace(" ", "_")
        print(f"{key}_kinematic_vectors_per_s: {kin:.0f}")
        print(f"{key}_dynamic_changes_per_s: {dyn:.3f}")
        print(f"{key}_dynamic_error_fraction: {err:.5f}")
        print(f"{key}_kinematic_vs_sorter: {kin / base[3]:.3f}")
        print(f"{key}_dynamic_vs_sorter: {dyn / base[4]:.3f}")
    print(f"default_error_max: {max(r[5] for r in rows):.5f}")


if __name__ == "__main__":
    main()
