"""Flow-table synthesis time for random primitive tables of 4 to 32 rows (issue 4).

    python benchmarks/flowtable.py [--sizes 4 8 12 16 24 32] [--tables 2] [--inputs 2] [--seed 0]

Tables come from ``mechc.bench.circuits.random_flow_table`` (seeded): each row stable in one
column, each single-input change from it specified with probability 0.8 towards a random row
stable in the new column, two outputs. Per table the stages are timed in this process:
implication table + minimum closed cover, state assignment, and the equations (excitation,
exact minimisation of SET/RESET/outputs, consensus terms, the reachability check). Printed as
``name: value`` lines: per size the median seconds of each stage, merged rows, state variables,
whether the cover and the variable count are proven minimum, and the ratio of the median total
to the median total of the smallest size (how synthesis time grows with the table). For sizes
up to 6 rows the cover is also found by trying every collection of compatibles (the
brute-force reference) and its time ratio to the exact program is printed.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from mechc.bench.circuits import random_flow_table
from mechc.ir.seqspec import SeqSpec
from mechc.passes.flowtable import (
    assign_states,
    brute_force_min_cover,
    closed_cover,
    compatibility,
    derive_equations,
    reduce_table,
)

BRUTE_FORCE_MAX_ROWS = 6


def run_table(rows: int, inputs: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    ft = random_flow_table(rng, rows, inputs, 2)
    spec = SeqSpec(f"<random {rows}x{1 << inputs} seed {seed}>", ft.inputs, ft.outputs, table=ft)
    t0 = time.perf_counter()
    comp = compatibility(ft)
    cover = closed_cover(ft, comp)
    t1 = time.perf_counter()
    rt = reduce_table(ft, cover.classes)
    asg = assign_states(rt)
    t2 = time.perf_counter()
    se = derive_equations(spec)  # the whole synthesis again, as the compiler runs it
    t3 = time.perf_counter()
    out = {"cover_s": t1 - t0, "assign_s": t2 - t1, "total_s": t3 - t2,
           "merged": len(cover.classes), "variables": asg.width,
           "cover_proven": cover.proven, "assign_proven": asg.proven,
           "transitions": se.checked["transitions"]}
    if rows <= BRUTE_FORCE_MAX_ROWS:
        t4 = time.perf_counter()
        size = brute_force_min_cover(ft, comp)
        out["brute_s"] = time.perf_counter() - t4
        out["brute_agrees"] = size == len(cover.classes)
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[4, 8, 12, 16, 24, 32])
    ap.add_argument("--tables", type=int, default=2, help="random tables per size")
    ap.add_argument("--inputs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    base = None
    for rows in args.sizes:
        res = [run_table(rows, args.inputs, args.seed + 1000 * rows + i)
               for i in range(args.tables)]
        med = {k: statistics.median(r[k] for r in res)
               for k in ("cover_s", "assign_s", "total_s")}
        name = f"flowtable.rows{rows}"
        print(f"{name}.tables: {len(res)}")
        print(f"{name}.columns: {1 << args.inputs}")
        print(f"{name}.merged_rows: {' '.join(str(r['merged']) for r in res)}")
        print(f"{name}.state_variables: {' '.join(str(r['variables']) for r in res)}")
        print(f"{name}.cover_proven: {sum(r['cover_proven'] for r in res)}/{len(res)}")
        print(f"{name}.assignment_proven: {sum(r['assign_proven'] for r in res)}/{len(res)}")
        print(f"{name}.transitions_checked: {' '.join(str(r['transitions']) for r in res)}")
        print(f"{name}.cover_seconds_median: {med['cover_s']:.4f}")
        print(f"{name}.assign_seconds_median: {med['assign_s']:.4f}")
        print(f"{name}.synthesis_seconds_median: {med['total_s']:.4f}")
        if base is None:
            base = (rows, med["total_s"])
        print(f"{name}.synthesis_time_ratio_vs_rows{base[0]}: {med['total_s'] / base[1]:.2f}")
        if all("brute_s" in r for r in res):
            ratio = statistics.median(r["brute_s"] / max(r["cover_s"], 1e-9) for r in res)
            print(f"{name}.bruteforce_cover_agrees: "
                  f"{sum(r['brute_agrees'] for r in res)}/{len(res)}")
            print(f"{name}.bruteforce_cover_time_ratio: {ratio:.2f}")


if __name__ == "__main__":
    main()
