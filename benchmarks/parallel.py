"""What ``mechc simulate --jobs 2`` gains over ``--jobs 1``: the dynamic proof of a few designs
run both ways in the same run, wall seconds, the speed-up, and a check that both reports are
the same case by case.

    python benchmarks/parallel.py [--quick] [--jobs 2] [--repeat 2] [--out DIR]

Designs: the full adder and the sorter (examples), a compiled random spec of about 80 cells
(``mechc.bench.circuits.random_compiled(100, seed=100)``, as the speed benchmark's
``random100``), and the speed controller ``examples/speedctl.fsm`` (sequential: its walks cut
into pieces from power-up, ``mechc.proofs.seq_logic.split_walks``, are what the processes
share; "units" in the CSV); without ``--quick`` also ``examples/sequence_detector.fsm``.
Wall seconds (a parallel run is about wall time), the best of ``--repeat`` runs of each, the
two settings interleaved so a change in the machine's load hits both; the load average is
printed with the figures because the machine may be shared. "CPU
ratio" is the CPU seconds of every process of the parallel run (workers included) over the
serial run's: the work the pool adds (near 1: the speed-up is bounded by the free cores, not
by overhead). "CPU path" is the speed-up the two runs' critical paths give in CPU seconds (this
process's own, plus the busiest worker's: ``mechc.proofs.parallel.pool_cpu``): what a machine
with a free core per process would show, a figure other jobs' load moves far less than wall
time. Writes ``parallel.csv`` and ``parallel.png`` to ``--out`` (default: docs/perf).
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import time
from pathlib import Path

from mechc.bench.circuits import EXAMPLES, random_compiled
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.passes.assemble import MechOptions
from mechc.pipeline import CompileOptions, compile_spec
from mechc.proofs.dynamic import prove_dynamic
from mechc.proofs.parallel import available_cores, pool_cpu, run_cases
from mechc.proofs.seq_mechanism import prove_sequential_dynamic

LIB = load_library()
ROOT = Path(__file__).resolve().parents[1]


def designs(quick: bool) -> list[tuple[str, object, dict]]:
    """(name, design, keyword arguments of its proof)."""
    out = [("full_adder", compile_spec(load_spec(EXAMPLES / "full_adder.bool")), {}),
           ("sorter", compile_spec(load_spec(EXAMPLES / "sorter.bool")), {})]
    big = random_compiled(100, seed=100)
    if not big.stats["design_checks"]["passed"]:  # as the speed benchmark: the physics only
        big = random_compiled(100, seed=100,
                              options=CompileOptions(mech=MechOptions(actuator_force=1e4)))
    out.append((f"random{len(big.netlist.cells)}", big, {"max_cases": 8 if quick else 24}))
    out.append(("speedctl (sequential)", compile_spec(parse_fsm_file(EXAMPLES / "speedctl.fsm")),
                {"sequential": True}))
    if not quick:  # a second flow table, whose walks the cut was not tuned on
        out.append(("sequence_detector (seq.)",
                    compile_spec(parse_fsm_file(EXAMPLES / "sequence_detector.fsm")),
                    {"sequential": True}))
    return out


def cpu_seconds() -> float:
    """CPU seconds of this process and of its finished child processes (the pool's workers)."""
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + kids.ru_utime + kids.ru_stime


def prove(design, jobs: int, kw: dict):
    """(wall seconds, CPU seconds of every process, CPU seconds of the critical path, report,
    per-case records). The critical path is this process's own CPU seconds plus those of the
    busiest worker (``pool_cpu``): the wall time the run would take with a free core per
    process, which a loaded machine does not move as it moves wall time."""
    rec: list = []
    t, c, own = time.perf_counter(), cpu_seconds(), time.process_time()
    pool_cpu.clear()
    if kw.get("sequential"):
        r = prove_sequential_dynamic(design, design.spec, LIB, jobs=jobs, record=rec)
    else:
        r = prove_dynamic(design, design.spec, LIB, jobs=jobs, record=rec,
                          max_cases=kw.get("max_cases"))
    path = time.process_time() - own + max(pool_cpu.values(), default=0.0)
    return time.perf_counter() - t, cpu_seconds() - c, path, r, rec


def spin(n: int, lib, case: int) -> int:
    """The control: pure CPU work with nothing to share, through the same pool."""
    s = 0
    for i in range(n):
        s += i * i
    return s


def control(jobs: int, repeat: int) -> tuple[float, float]:
    """Best wall seconds of 8 equal CPU-bound cases at --jobs 1 and at ``jobs``: the speed-up
    the machine gives a perfectly parallel load in this run (on a shared machine it can be
    far below the core count)."""
    best = {1: float("inf"), jobs: float("inf")}
    for _ in range(repeat):
        for j in (1, jobs):
            t = time.perf_counter()
            run_cases(spin, 3_000_000, list(range(8)), LIB, j)
            best[j] = min(best[j], time.perf_counter() - t)
    return best[1], best[jobs]


def timeless(report) -> dict:
    return {k: v for k, v in report.to_json().items() if k != "seconds"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="8 changes of the random circuit")
    ap.add_argument("--jobs", type=int, default=2, help="the parallel run's processes")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each setting (best kept)")
    ap.add_argument("--out", default=str(ROOT / "docs" / "perf"))
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"cores this process may use: {available_cores()}; load average before: "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}", flush=True)
    rows = []
    print(f"{'design':24s} {'cells':>5s} {'cases':>5s} {'jobs 1 (s)':>10s} "
          f"{'jobs ' + str(a.jobs) + ' (s)':>10s} {'speed-up':>8s} {'CPU ratio':>9s} "
          f"{'CPU path':>9s}  same report",
          flush=True)
    for name, design, kw in designs(a.quick):
        best = {1: float("inf"), a.jobs: float("inf")}
        cpu = {1: float("inf"), a.jobs: float("inf")}
        path = {1: float("inf"), a.jobs: float("inf")}
        results = {}
        for _ in range(a.repeat):
            for jobs in (1, a.jobs):
                t, c, p, r, rec = prove(design, jobs, kw)
                if t < best[jobs]:
                    best[jobs], cpu[jobs] = t, c
                path[jobs] = min(path[jobs], p)
                results[jobs] = (r, rec)
        (r1, rec1), (rn, recn) = results[1], results[a.jobs]
        same = rec1 == recn and timeless(r1) == timeless(rn)
        ratio = best[1] / best[a.jobs]
        balance = path[1] / path[a.jobs]
        rows.append({"design": name, "cells": len(design.netlist.cells), "cases": r1.cases,
                     "units": r1.coverage.get("pieces", r1.cases), "passed": r1.passed,
                     "seconds_jobs_1": round(best[1], 3),
                     f"seconds_jobs_{a.jobs}": round(best[a.jobs], 3),
                     "speedup": round(ratio, 3), "cpu_seconds_jobs_1": round(cpu[1], 3),
                     f"cpu_seconds_jobs_{a.jobs}": round(cpu[a.jobs], 3),
                     "cpu_ratio": round(cpu[a.jobs] / cpu[1], 3),
                     "critical_path_seconds_jobs_1": round(path[1], 3),
                     f"critical_path_seconds_jobs_{a.jobs}": round(path[a.jobs], 3),
                     "critical_path_speedup": round(balance, 3), "same_report": same})
        print(f"{name:24s} {len(design.netlist.cells):5d} {r1.cases:5d} {best[1]:10.2f} "
              f"{best[a.jobs]:10.2f} {ratio:7.2f}x {cpu[a.jobs] / cpu[1]:9.2f} "
              f"{balance:8.2f}x  {'yes' if same else 'NO'}", flush=True)
    c1, cn = control(a.jobs, a.repeat)
    rows.append({"design": "control (CPU loop)", "cells": 0, "cases": 8, "units": 8,
                 "passed": True,
                 "seconds_jobs_1": round(c1, 3), f"seconds_jobs_{a.jobs}": round(cn, 3),
                 "speedup": round(c1 / cn, 3), "cpu_seconds_jobs_1": "",
                 f"cpu_seconds_jobs_{a.jobs}": "", "cpu_ratio": "",
                 "critical_path_seconds_jobs_1": "", f"critical_path_seconds_jobs_{a.jobs}": "",
                 "critical_path_speedup": "", "same_report": True})
    print(f"{'control (CPU loop)':24s} {'':5s} {8:5d} {c1:10.2f} {cn:10.2f} {c1 / cn:7.2f}x"
          "  (what this machine gives a perfectly parallel load now)", flush=True)
    rows, ctrl = rows[:-1], rows[-1]
    total1 = sum(r["seconds_jobs_1"] for r in rows)
    totaln = sum(r[f"seconds_jobs_{a.jobs}"] for r in rows)
    path1 = sum(r["critical_path_seconds_jobs_1"] for r in rows)
    pathn = sum(r[f"critical_path_seconds_jobs_{a.jobs}"] for r in rows)
    print(f"all designs: {total1:.2f} s -> {totaln:.2f} s, speed-up {total1 / totaln:.2f}x "
          f"(CPU path {path1:.2f} s -> {pathn:.2f} s, {path1 / pathn:.2f}x); "
          f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    rows.append(ctrl)
    with open(out / "parallel.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    chart(rows, a.jobs, out / "parallel.png")
    print(f"wrote {out / 'parallel.csv'} and {out / 'parallel.png'}")
    if not all(r["same_report"] for r in rows):
        raise SystemExit("a parallel report differs from the serial one")


def chart(rows: list[dict], jobs: int, path: Path) -> None:
    import matplotlib  # a benchmark-only import

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, ax = plt.subplots(figsize=(8, 4.5))
    x = np.arange(len(rows))
    one = [r["seconds_jobs_1"] for r in rows]
    many = [r[f"seconds_jobs_{jobs}"] for r in rows]
    ax.bar(x - 0.2, one, 0.4, label="--jobs 1")
    ax.bar(x + 0.2, many, 0.4, label=f"--jobs {jobs}")
    for i, r in enumerate(rows):
        cp = r.get("critical_path_speedup")
        ax.annotate(f"{r['speedup']:.2f}x" + (f"\nCPU path {cp:.2f}x" if cp else ""),
                    (x[i] + 0.2, many[i]), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(x, [f"{r['design']}\n{r['cases']} cases"
                      + (f", {r['units']} pieces" if r["units"] != r["cases"] else "")
                      for r in rows], fontsize=8)
    ax.set_ylabel("wall seconds (dynamic proof; control: a CPU loop)")
    ax.set_title(f"mechc simulate --jobs {jobs} against --jobs 1 (same reports)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
