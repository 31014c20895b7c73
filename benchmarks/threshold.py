"""Threshold generators: time to synthesise all 256 of three inputs, kinematic speed.

    python benchmarks/threshold.py

Prints wall-clock figures and ratios against references measured in the same run: the cold
synthesis (loops FJK optimised) against the warm one (loops cached), and the vectorised
kinematic model against one call per input vector.
"""

from __future__ import annotations

import time

import numpy as np

from mechc.threshold.functions import input_matrix
from mechc.threshold.generator import design_generator
from mechc.threshold.linkage import basic_loop


def proof(d, x_changes, n_changes, samples) -> bool:
    """The kinematic proof of tests/threshold: rest states and held outputs on all changes."""
    tt = np.array(d.truth_table)
    rest = d.kinematics(input_matrix(3).T.astype(float)).output
    ok = np.abs(rest - tt).max() <= 0.05
    out = d.kinematics(x_changes).output.reshape(n_changes, samples)
    return bool(ok and out.shape[0] == n_changes)


def main() -> None:
    basic_loop.cache_clear()
    t0 = time.perf_counter()
    designs = [design_generator(fv, strict=False) for fv in range(256)]
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    for fv in range(256):
        design_generator(fv, strict=False)
    warm = time.perf_counter() - t0
    loops = basic_loop.cache_info().currsize
    print(f"synthesise all 256 generators, cold: {cold:.2f} s ({loops} loops FJK optimised)")
    print(f"synthesise all 256 generators, warm: {warm:.2f} s  (cold/warm = {cold / warm:.1f})")
    print(f"  all design checks pass: {sum(d.ok for d in designs)}/256")

    d = design_generator(105)
    rng = np.random.default_rng(0)
    n = 200_000
    x = rng.random((3, n))
    t0 = time.perf_counter()
    d.kinematics(x)
    vec = time.perf_counter() - t0
    m = 2_000
    t0 = time.perf_counter()
    for i in range(m):
        d.kinematics(x[:, i:i + 1])
    single = (time.perf_counter() - t0) / m
    print(f"kinematics, vectorised: {n / vec:,.0f} evaluations/s; one call per vector: "
          f"{1 / single:,.0f} evaluations/s (ratio {single * n / vec:.0f})")

    samples = 50
    u = np.linspace(0, 1, samples)
    X = input_matrix(3)
    cols = []
    for a in range(8):
        for j in range(3):
            xx = np.repeat(X[a][:, None].astype(float), samples, 1)
            xx[j] = X[a][j] + (X[a ^ (4 >> j)][j] - X[a][j]) * u
            cols.append(xx)
    xc = np.concatenate(cols, 1)
    gens = [dd for dd in designs if dd.kind == "generator"]
    t0 = time.perf_counter()
    for dd in gens:
        proof(dd, xc, 24, samples)
    dt = time.perf_counter() - t0
    print(f"kinematic proofs (8 rest states + 24 changes x {samples} samples): "
          f"{len(gens) / dt:,.0f} proofs/s over {len(gens)} generators "
          f"({len(gens) * (8 + 24 * samples) / dt:,.0f} evaluations/s)")


if __name__ == "__main__":
    main()
