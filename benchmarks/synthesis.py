"""Speed of the synthesis toolkit against a brute-force scipy solve of the same equations.

For each problem class, mechc's method (M/K circles reduced to the t-plane; the closed form of
the 3-bar gate) and a reference -- scipy.optimize.least_squares on the full standard-form
equations from random starts -- run on the same random problems in the same process.  Printed:
solutions per second for both, their ratio, and how many of mechc's solutions the reference
found (the brute force has no way to know when it has them all).

    python benchmarks/synthesis.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.optimize import least_squares

from mechc.linkage_synthesis import mk_circles as mk
from mechc.linkage_synthesis import three_bar_gate as tb


def random_problem(rng, k, n, free_link, known):
    links = rng.normal(size=k) + 1j * rng.normal(size=k)
    ang = np.zeros((k, n))
    ang[:, 1:] = rng.uniform(-np.pi, np.pi, size=(k, n - 1))
    pts = complex(rng.normal(), rng.normal()) + np.einsum("l,lj->j", links, np.exp(1j * ang))
    unknown = [j for j in range(1, n) if j not in known]
    ang[free_link, unknown] = np.nan
    return mk.ChainProblem(pts, ang, free_link)


def brute_force(pr: mk.ChainProblem, starts: int, rng) -> list[np.ndarray]:
    """All distinct solutions least_squares reaches from random starts (links only)."""
    k, n, u = pr.k, pr.n, pr.free_link
    var = [j for j in range(1, n) if np.isnan(pr.angles[u, j])]
    d = pr.deltas[1:]

    def f(v):
        L = v[0:2 * k:2] + 1j * v[1:2 * k:2]
        ang = pr.angles.copy()
        ang[u, var] = v[2 * k:]
        r = np.einsum("l,lj->j", L, np.exp(1j * ang[:, 1:]) - 1.0) - d
        return np.concatenate([r.real, r.imag])

    found: list[np.ndarray] = []
    for _ in range(starts):
        x0 = np.concatenate([rng.normal(size=2 * k), rng.uniform(-np.pi, np.pi, len(var))])
        r = least_squares(f, x0, xtol=1e-14, ftol=1e-14, gtol=1e-14)
        if np.max(np.abs(r.fun)) < 1e-9 * pr.scale:
            L = r.x[0:2 * k:2] + 1j * r.x[1:2 * k:2]
            if not any(np.max(np.abs(L - g)) < 1e-6 for g in found):
                found.append(L)
    return found


def bench_chain(label, k, n, free_link, known, problems, starts, seed=0):
    rng = np.random.default_rng(seed)
    probs = [random_problem(rng, k, n, free_link, known) for _ in range(problems)]
    t0 = time.perf_counter()
    ours = [mk.solve_chain(p) for p in probs]
    t_ours = time.perf_counter() - t0
    n_ours = sum(len(r.solutions) for r in ours)
    t0 = time.perf_counter()
    ref = [brute_force(p, starts, rng) for p in probs]
    t_ref = time.perf_counter() - t0
    n_ref = sum(len(r) for r in ref)
    common = sum(sum(any(np.max(np.abs(s.links - g)) < 1e-6 for g in rr) for s in r.solutions)
                 for r, rr in zip(ours, ref))
    extra = n_ref - common  # solutions the reference found that we did not
    rate_o, rate_r = n_ours / t_ours, max(n_ref, 1) / t_ref
    print(f"{label:<34} mechc {rate_o:9.1f} sol/s ({problems / t_ours:8.1f} problems/s)   "
          f"scipy x{starts} starts {rate_r:8.1f} sol/s ({problems / t_ref:6.2f} problems/s)   "
          f"ratio {rate_o / rate_r:7.1f}   scipy found {common}/{n_ours} of ours, "
          f"{extra} others")


def bench_three_bar(problems, seed=0):
    rng = np.random.default_rng(seed)
    reqs = [(rng.uniform(10, 80), rng.uniform(10, 60)) for _ in range(problems)]
    reqs = [(sep, s, rng.uniform(1.5, 5.0) * (sep + s)) for sep, s in reqs]
    t0 = time.perf_counter()
    closed = [tb.solve_closed_form(*r) for r in reqs]
    t_closed = time.perf_counter() - t0
    t0 = time.perf_counter()
    for d in closed:
        if d:
            tb.evaluate(d[0])
    t_eval = time.perf_counter() - t0

    def gate(v, sep, s, xo):
        m = v[0]
        if not m > s / 2:
            return [1e3]
        r = tb._gate_residual(sep, s, m, xo)
        return [r if np.isfinite(r) else 1e3]

    t0 = time.perf_counter()
    agree = converged = 0
    for (sep, s, xo), d in zip(reqs, closed):
        best = None
        for _ in range(5):
            m0 = s / 2 + rng.uniform(0.05, 5.0) * (sep + s)
            r = least_squares(gate, [m0], args=(sep, s, xo), xtol=1e-14, ftol=1e-14)
            if abs(r.fun[0]) < 1e-9 * s:
                best = r.x[0]
                break
        converged += best is not None
        if best is not None and d and abs(np.hypot(best, sep) - d[0].input_link) < 1e-6 * s:
            agree += 1
    t_ref = time.perf_counter() - t0
    print(f"{'3-bar gate, closed form':<34} mechc {problems / t_closed:9.1f} designs/s   "
          f"scipy (<=5 starts) {problems / t_ref:8.1f} designs/s   ratio "
          f"{t_ref / t_closed:7.1f}   scipy converged {converged}/{problems}, to the closed-form "
          f"design {agree}")
    print(f"{'3-bar gate, closed form + check':<34} mechc {problems / (t_closed + t_eval):9.1f}"
          f" designs/s   ratio {t_ref / (t_closed + t_eval):7.1f}")
    # the whole answer a user gets (closed form, numerical confirmation, toggle root, checks),
    # without the search for alternatives; on a subset, against the same scipy time per problem
    sub = reqs[: max(problems // 10, 1)]
    t0 = time.perf_counter()
    healthy = sum(tb.synthesise(*r, alternatives=False).healthy for r in sub)
    t_full = time.perf_counter() - t0
    rate_ref = problems / t_ref
    print(f"{'3-bar gate, full synthesise()':<34} mechc {len(sub) / t_full:9.1f} designs/s   "
          f"scipy (<=5 starts) {rate_ref:8.1f} designs/s   ratio "
          f"{len(sub) / t_full / rate_ref:7.1f}   healthy {healthy}/{len(sub)}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer problems")
    args = ap.parse_args()
    q = args.quick
    print("synthesis benchmark: mechc vs brute-force scipy least_squares on the same equations")
    bench_chain("dyad, 3 positions (linear)", 2, 3, 0, [1, 2], 40 if q else 200, 4)
    bench_chain("dyad, 4 positions (beta2 given)", 2, 4, 0, [1], 30 if q else 100, 20)
    bench_chain("dyad, 5 positions (search)", 2, 5, 0, [], 10 if q else 30, 40)
    bench_chain("triad, 5 positions (a2, a3 given)", 3, 5, 1, [1, 2], 20 if q else 60, 20)
    bench_chain("triad, 6 positions (search)", 3, 6, 1, [1], 6 if q else 20, 40)
    bench_three_bar(100 if q else 400)


if __name__ == "__main__":
    main()
