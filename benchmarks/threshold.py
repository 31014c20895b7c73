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
from mechc.threshold.planar import planar_generator

MARGIN = 0.05  # of the stroke, as in the tests


def proof(d, x_changes, meta, samples) -> bool:
    """The kinematic proof of tests/threshold: the 8 rest states, both ends of every change,
    and every output that must hold staying within the margin along its change."""
    tt = np.array(d.truth_table)
    rest = d.kinematics(input_matrix(3).T.astype(float)).output
    if np.abs(rest - tt).max() > MARGIN:
        return False
    out = d.kinematics(x_changes).output.reshape(len(meta), samples)
    for (a, b), o in zip(meta, out):
        if abs(o[0] - tt[a]) > MARGIN or abs(o[-1] - tt[b]) > MARGIN:
            return False
        if tt[a] == tt[b] and np.abs(o - tt[a]).max() > MARGIN:
            return False
    return True


def main() -> None:
    basic_loop.cache_clear()
    planar_generator.cache_clear()
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
    cols, meta = [], []
    for a in range(8):
        for j in range(3):
            xx = np.repeat(X[a][:, None].astype(float), samples, 1)
            xx[j] = X[a][j] + (X[a ^ (4 >> j)][j] - X[a][j]) * u
            cols.append(xx)
            meta.append((a, a ^ (4 >> j)))
    xc = np.concatenate(cols, 1)
    gens = [dd for dd in designs if dd.kind == "generator"]
    t0 = time.perf_counter()
    passed = sum(proof(dd, xc, meta, samples) for dd in gens)
    dt = time.perf_counter() - t0
    planar = sum(dd.planar is not None for dd in gens)
    print(f"kinematic proofs (8 rest states + 24 changes x {samples} samples): "
          f"{len(gens) / dt:,.0f} proofs/s over {len(gens)} generators "
          f"({len(gens) * (8 + 24 * samples) / dt:,.0f} evaluations/s); "
          f"passed {passed}/{len(gens)} ({planar} planar generators)")
    cells(xc, samples)


def cells(xc: np.ndarray, samples: int) -> None:
    """The THRESHOLD cell (stdlib/threshold.py): every generator built as a mechanism (bodies,
    joints, cam profile) and proven through the generic closed forms plus the cam follower;
    the reference is the generator's own closed form on the same states, timed above."""
    from mechc.stdlib.threshold import ThresholdCell

    from mechc.ir.mechanism import Demand, SynthContext
    from mechc.passes.threshold_map import params_of
    from mechc.physics.evaluate import signal_of
    from mechc.threshold.weights import realise

    ctx = SynthContext()
    fvs = [fv for fv in range(256) if design_generator(fv, strict=False).kind == "generator"]
    t0 = time.perf_counter()
    parts = [ThresholdCell.synthesise("c1", ctx, 3, params_of(realise(fv)), Demand(0.5, 0.5))
             for fv in fvs]
    synth = time.perf_counter() - t0
    x = np.concatenate([input_matrix(3).T.astype(float), xc], 1)
    t0 = time.perf_counter()
    for p in parts:
        fixed = {p.terminals[k].body: (x[i] - 0.5) * ctx.stroke for i, k in enumerate("ABC")}
        poses = ThresholdCell.kinematics(p, fixed, x.shape[1])
        t = p.terminals["Z"]
        signal_of(t, p.body(t.body), poses)
    dt = time.perf_counter() - t0
    print(f"threshold cells synthesised (all {len(fvs)} generator functions): {synth:.2f} s")
    print(f"threshold cell kinematic proofs per second: {len(parts) / dt:.1f} "
          f"({len(parts) * x.shape[1] / dt:,.0f} cell states/s, 24 changes x {samples} samples)")


if __name__ == "__main__":
    main()
