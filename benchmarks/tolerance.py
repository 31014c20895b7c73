"""Tolerance runs: how long 10,000 Monte Carlo samples of the sorter take against one nominal
kinematic proof of it (same run, same machine), and with ``--markdown`` the yield and the
dimension that matters most for every combinational example (docs/tolerance.md's table).

    python benchmarks/tolerance.py [--samples 10000] [--chart tolerance_sorter.png]
    python benchmarks/tolerance.py --markdown [--samples 2000]
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
#: every combinational example (a sequential design is not yet run: mechc tolerance says so)
EXAMPLES = [("sorter.bool", ()), ("full_adder.bool", ()),
            ("full_adder.bool", ("--map", "threshold")), ("comparator2.bool", ()),
            ("majority.pla", ()), ("sevenseg.bool", ()), ("full_adder_net.blif", ())]


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


def markdown(samples: int, tol: float, clearance: float, spring_tol: float) -> None:
    s = ToleranceSettings(tol=tol, clearance=clearance, spring_tol=spring_tol, samples=samples)
    print(f"| design | dimensions | yield ({samples} samples) | 95 % interval | most frequent "
          "failing check | dimension that matters most | output scatter at rest (99 %) |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for spec, extra in EXAMPLES:
            d, lib = compiled(spec, extra, Path(tmp) / "d.json")
            r = run(d, lib, s)
            lo, hi = r.ci
            f = r.failing[0] if r.failing else None
            fail = (f"{f.key.name} at {f.key.where} ({f.count / r.samples:.1%})" if f
                    else "none")
            top = r.ranked[0]
            spread = max((max(abs(e.spread_mm[0]), abs(e.spread_mm[1])) for e in r.structural),
                         default=0.0)
            name = spec + (" " + " ".join(extra) if extra else "")
            print(f"| `{name}` | {len(r.dims)} | {r.yield_:.2%} | [{lo:.2%}, {hi:.2%}] | {fail} "
                  f"| `{top.dim.name}` ({top.dim.what}, {top.position_mm:.3f} mm) | "
                  f"±{spread:.3f} mm |")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--samples", type=int, default=None)
    p.add_argument("--chart", default="tolerance_sorter.png")
    p.add_argument("--markdown", action="store_true")
    p.add_argument("--tol", type=float, default=0.1)
    p.add_argument("--clearance", type=float, default=0.05)
    p.add_argument("--spring-tol", type=float, default=0.1)
    a = p.parse_args()
    if a.markdown:
        markdown(a.samples or 2000, a.tol, a.clearance, a.spring_tol)
    else:
        speed(a.samples or 10_000, a.chart)


if __name__ == "__main__":
    main()
