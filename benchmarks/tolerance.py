"""Tolerance runs: how long 10,000 Monte Carlo samples of the sorter take against one nominal
kinematic proof of it (same run, same machine), and with ``--markdown`` the yield and the
dimension that matters most for every combinational example (docs/tolerance.md's table).

    python benchmarks/tolerance.py [--samples 10000] [--chart tolerance_sorter.png]
    python benchmarks/tolerance.py --markdown [--samples 2000]
    python benchmarks/tolerance.py --scale [--samples 500] [--chart tolerance_scale.png]

``--scale`` (how small can it be): for each process preset (mechc/tolerance/process.py), the
yield of each example compiled at strokes from 5 to 40 mm, with the springs and over-travel
stops robust design chose for the sorter (margin 1.46, 4 %), the smallest stroke that keeps
99 %, and a chart of yield against stroke.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from mechc.backends.design_json import design_from_json, load_design_json
from mechc.cells.sources import library_for_design
from mechc.proofs.kinematic import prove_kinematic
from mechc.tolerance.chart import sensitivity_chart
from mechc.tolerance.montecarlo import ToleranceSettings, run

ROOT = Path(__file__).resolve().parent.parent
#: every example (and the full adder with threshold generators)
EXAMPLES = [("sorter.bool", ()), ("full_adder.bool", ()),
            ("full_adder.bool", ("--map", "threshold")), ("comparator2.bool", ()),
            ("majority.pla", ()), ("sevenseg.bool", ()), ("full_adder_net.blif", ()),
            ("fv157.bool", ()), ("speedctl.fsm", ()), ("speedctl_sr.fsm", ()),
            ("toggle.fsm", ()), ("toggle.kiss2", ()), ("gated_latch.fsm", ()),
            ("sequence_detector.fsm", ())]


def compiled(spec: str, extra: tuple[str, ...], out: Path):
    subprocess.run([sys.executable, "-m", "mechc", "compile", str(ROOT / "examples" / spec),
                    "-o", str(out), *extra], check=True, capture_output=True)
    d = design_from_json(load_design_json(out), str(out))
    return d, library_for_design(d.cell_sources, [], str(out))


def speed(samples: int, chart: str | None) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        d, lib = compiled("sorter.bool", (), Path(tmp) / "sorter.json")
    reps = 20
    t = time.perf_counter()
    c = time.process_time()
    for _ in range(reps):
        prove_kinematic(d, d.spec, lib)
    nominal = (time.perf_counter() - t) / reps
    nominal_cpu = (time.process_time() - c) / reps
    s = ToleranceSettings(samples=samples)
    t, c = time.perf_counter(), time.process_time()
    r = run(d, lib, s)
    total, cpu = time.perf_counter() - t, time.process_time() - c
    lo, hi = r.ci
    print(f"sorter: {len(r.dims)} dimensions, {samples} samples at +-{s.tol} mm, clearance "
          f"{s.clearance} mm, springs +-{s.spring_tol:.0%}")
    print(f"  nominal kinematic proof          {nominal * 1e3:8.2f} ms  "
          f"(CPU {nominal_cpu * 1e3:.2f} "
          "ms; mean of 20)")
    print(f"  tolerance run                    {total:8.2f} s  (derivatives "
          f"{r.seconds['derivatives']:.2f} s, samples {r.seconds['samples']:.2f} s, analysis "
          f"{r.seconds['analysis']:.2f} s)")
    print(f"  tolerance run, CPU time          {cpu:8.2f} s  (the machine is shared: wall "
          "time includes waiting for the other jobs)")
    print(f"  per sample                       {total / samples * 1e3:8.3f} ms = "
          f"{total / samples / nominal:.3f} x one nominal proof")
    print(f"  {samples} one-by-one proofs would take {samples * nominal:.1f} s: "
          f"{samples * nominal / total:.1f} x the run (CPU: {samples * nominal_cpu:.1f} s, "
          f"{samples * nominal_cpu / cpu:.1f} x)")
    print(f"  yield {r.yield_:.2%} [{lo:.2%}, {hi:.2%}]")
    if chart:
        sensitivity_chart(r, chart, "sorter")
        print(f"  chart: {chart}")


def markdown(samples: int, tol: float, clearance: float, spring_tol: float,
             only: list[str] | None = None) -> None:
    s = ToleranceSettings(tol=tol, clearance=clearance, spring_tol=spring_tol, samples=samples)
    print(f"| design | dimensions | yield ({samples} samples) | 95 % interval | most frequent "
          "failing check | dimension that matters most | output scatter at rest (99 %) | "
          "interference bound: may touch (of them passing) |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec, extra in EXAMPLES:
            if only and spec not in only:
                continue
            d, lib = compiled(spec, extra, Path(tmp) / "d.json")
            r = run(d, lib, s)
            lo, hi = r.ci
            f = r.failing[0] if r.failing else None
            fail = (f"{f.key.name} at {f.key.where} ({f.count / r.samples:.1%})" if f
                    else "none")
            top = r.ranked[0]
            if top.position_mm > 0:
                what = f"`{top.dim.name}` ({top.dim.what}, {top.position_mm:.3f} mm)"
            elif top.margin_coef != 0:
                what = (f"`{top.dim.name}` ({top.dim.what}; by regression, "
                        f"{top.margin_coef:+.3f} mm of margin)")
            else:
                what = "— (no dimension moves an output)"
            spread = max((max(abs(e.spread_mm[0]), abs(e.spread_mm[1])) for e in r.structural),
                         default=0.0)
            name = spec + (" " + " ".join(extra) if extra else "")
            print(f"| `{name}` | {len(r.dims)} | {r.yield_:.2%} | [{lo:.2%}, {hi:.2%}] | {fail} "
                  f"| {what} | " + (f"±{spread:.3f} mm |" if r.structural else "— |")
                  + f" {r.interference_samples} ({r.interference_passing}) |", flush=True)


SCALE_EXAMPLES = ["sorter.bool", "full_adder.bool", "comparator2.bool", "majority.pla"]
STROKES = [5.0, 7.5, 10.0, 15.0, 20.0, 30.0, 40.0]


def scale(samples: int, chart: str | None, target: float = 0.99) -> None:
    # imported here: only this study compiles in memory with chosen rules
    from mechc.cells.library import load_library
    from mechc.frontends import load_spec
    from mechc.passes.assemble import MechOptions
    from mechc.pipeline import CompileOptions, compile_spec
    from mechc.tolerance.process import PROCESSES

    lib = load_library(())
    yields: dict[tuple[str, str], list[float]] = {}
    for spec_name in SCALE_EXAMPLES:
        spec = load_spec(ROOT / "examples" / spec_name)
        for stroke in STROKES:
            opts = CompileOptions(mech=MechOptions(stroke=stroke, spring_margin=1.46,
                                                   overtravel=0.04))
            d = compile_spec(spec, opts, lib)
            for p in PROCESSES.values():
                r = run(d, lib, ToleranceSettings(tol=p.tol, clearance=p.clearance,
                                                  spring_tol=p.spring_tol, samples=samples))
                yields.setdefault((p.name, spec_name), []).append(r.yield_)
    print("| process | tolerance / pin clearance | "
          + " | ".join(f"`{e}`" for e in SCALE_EXAMPLES) + " |")
    print("|---|---|" + "---|" * len(SCALE_EXAMPLES))
    for p in PROCESSES.values():
        cells = []
        for e in SCALE_EXAMPLES:
            ys = yields[(p.name, e)]
            ok = [s for s, y in zip(STROKES, ys) if y >= target]
            smallest = next((s for i, s in enumerate(STROKES)
                             if all(y >= target for y in ys[i:])), None)
            cells.append(f"{smallest:g} mm" if smallest is not None
                         else f"none up to {STROKES[-1]:g} mm (best {max(ys):.1%})"
                         if not ok else f"{min(ok):g} mm (not all above)")
        print(f"| {p.name} | ±{p.tol} mm / {p.clearance} mm | " + " | ".join(cells) + " |")
    print()
    print("yield by stroke (mm): " + ", ".join(f"{s:g}" for s in STROKES))
    for (proc, e), ys in yields.items():
        print(f"  {proc:5s} {e:18s} " + " ".join(f"{y:7.2%}" for y in ys))
    if chart:
        import matplotlib
        import matplotlib.ticker
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(PROCESSES), figsize=(5 * len(PROCESSES), 4),
                                 sharey=True)
        for ax, p in zip(axes, PROCESSES.values()):
            for e in SCALE_EXAMPLES:
                ax.plot(STROKES, [100 * y for y in yields[(p.name, e)]], marker="o", label=e)
            ax.axhline(100 * target, color="grey", lw=0.8, ls="--")
            ax.set_xscale("log")
            ax.set_xticks(STROKES, [f"{s:g}" for s in STROKES])
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.set_xlabel("stroke (mm); every part scales with it")
            ax.set_title(f"{p.name}: ±{p.tol} mm, pins {p.clearance} mm, springs "
                         f"±{p.spring_tol:.0%}", fontsize=9)
        axes[0].set_ylabel(f"yield (%), {samples} samples")
        axes[0].legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(chart, dpi=110)
        print(f"chart: {chart}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--samples", type=int, default=None)
    p.add_argument("--chart", default="tolerance_sorter.png")
    p.add_argument("--markdown", action="store_true")
    p.add_argument("--only", nargs="+", metavar="SPEC",
                   help="with --markdown: only these examples (file names)")
    p.add_argument("--scale", action="store_true")
    p.add_argument("--tol", type=float, default=0.1)
    p.add_argument("--clearance", type=float, default=0.05)
    p.add_argument("--spring-tol", type=float, default=0.1)
    a = p.parse_args()
    if a.scale:
        scale(a.samples or 500, a.chart if a.chart != "tolerance_sorter.png"
              else "tolerance_scale.png")
    elif a.markdown:
        markdown(a.samples or 2000, a.tol, a.clearance, a.spring_tol, a.only)
    else:
        speed(a.samples or 10_000, a.chart)


if __name__ == "__main__":
    main()
