"""Speed against accuracy: every simulation level on the benchmark circuits, a grid of dynamic
settings, pruned against whole scenes, where the methods break, and peers in the same run.

``python benchmarks/speed_accuracy.py [--quick] [--out DIR]`` or ``mechc bench``. Writes
``speed_accuracy.csv``, ``speed_accuracy.png`` (output error against seconds per input change,
log-log, one series per circuit, Pareto fronts and default settings marked) and
``stability.png`` (the stability map and the breakdown sweeps) into ``--out``, and the error
model ``accuracy_model.json`` (into the package with ``--write-model``, which a full run does by
default). The summary ends in ``name: value`` lines. Every ratio is of two figures measured in
this run, on this machine.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from mechc.bench.charts import chart, stability_chart
from mechc.bench.circuits import ROOT, bench_circuits
from mechc.bench.error_grid import error_model, grid, step_overhead
from mechc.bench.harness import Bench, cell_count, write_csv
from mechc.bench.levels import levels
from mechc.bench.peers import peers
from mechc.bench.pruning import pruning
from mechc.bench.stability_study import stability_study
from mechc.cells.library import load_library
from mechc.proofs.accuracy import MODEL_PATH


def run(quick: bool, out: Path, write_model: Path | None) -> dict:
    """Every study in order, then the CSV, the charts and the summary lines."""
    t_start = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    b = Bench(load_library(), quick)
    steps = ["compile the circuits", "proof levels", "pruning", "error grid", "step overhead",
             "stability study", "peers"]

    def step(k: int) -> None:  # the studies run minutes: say which one is running
        b.say(f"[{k + 1}/{len(steps)}] {steps[k]} ({time.perf_counter() - t_start:.0f} s so far)")

    step(0)
    cs = bench_circuits(quick, b.say)
    for c in cs:
        b.say(f"{c.name}: {cell_count(c.design)} cells, {len(c.design.spec.inputs)} inputs"
              + (f" [{c.note}]" if c.note else ""))
    step(1)
    levels(b, cs)
    step(2)
    pruning(b, cs)
    step(3)
    grid_rows = grid(b, cs)
    fa = next(c for c in cs if c.name == "full_adder")
    step(4)
    overhead = step_overhead(b, fa)
    model = error_model(grid_rows, overhead, "benchmarks/speed_accuracy.py"
                        + (" --quick" if quick else ""))
    (out / "accuracy_model.json").write_text(json.dumps(model.to_json(), indent=1) + "\n")
    if write_model:
        write_model.write_text(json.dumps(model.to_json(), indent=1) + "\n")
        b.say(f"error model written to {write_model}")
    b.summary["step_overhead_iterations"] = round(overhead, 2)
    step(5)
    study = stability_study(b, fa)
    step(6)
    peers(b, next(c for c in cs if c.name == "random30"))
    write_csv(b.rows, out / "speed_accuracy.csv")
    chart(b, out / "speed_accuracy.png")
    stability_chart(b, study, out / "stability.png")
    b.summary["wall_seconds"] = round(time.perf_counter() - t_start, 1)
    b.say(f"\nwrote {out / 'speed_accuracy.csv'}, {out / 'speed_accuracy.png'}, "
          f"{out / 'stability.png'}, {out / 'accuracy_model.json'}")
    order = ["pruned_speedup", "pruned_all_frozen_speedup", "pruned_solver_speedup",
             "pruned_error_delta", "default_error",
             "default_case_seconds", "kinematic_vs_pylinkage", "kinematic_vs_pylinkage_step",
             "dynamic_vs_bare_pymunk"]
    for k, v in b.summary.items():
        if k not in order:
            print(f"{k}: {v}")
    for k in order:
        if k in b.summary:
            print(f"{k}: {b.summary[k]}")
    return b.summary


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quick", action="store_true",
                   help="smaller grids and fewer changes on the 100-cell circuit (< 5 min)")
    p.add_argument("--out", default=str(ROOT / "benchmarks" / "out"), metavar="DIR",
                   help="directory for the CSV and PNG files (default: benchmarks/out)")
    p.add_argument("--write-model", nargs="?", const=str(MODEL_PATH), default=None,
                   metavar="PATH", help="also write the error model there (default path: the "
                   "package's, which --accuracy reads; a full run writes it unless --no-model)")
    p.add_argument("--no-model", action="store_true", help="never write the package's model")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(p)
    return run_args(p.parse_args(argv))


def run_args(args: argparse.Namespace) -> int:
    """The benchmark as the command line asks for it (``mechc bench`` and the script)."""
    model = args.write_model
    if model is None and not args.quick and not args.no_model:
        model = str(MODEL_PATH)
    if args.no_model:
        model = None
    run(args.quick, Path(args.out), Path(model) if model else None)
    return 0
