"""Can a cheaper scene stand in for the whole one on joint stretch? Change by change.

    python benchmarks/stretch_probe.py [--circuit random81] [--out DIR]

The screened proof (``mechc.proofs.screen``) must run every *heavy* change in the whole scene,
because nothing predicts its joint stretch (docs/performance.md). A pruned scene
(``mechc.proofs.prune``) is cheaper; if its stretch were never below the whole scene's, it could
serve as a conservative probe. This runs every change of the dynamic proof's plan three ways —
the whole scene, and pruned scenes with the default freeze (``"inner"``) and with every still
body frozen (``"all"``) — and prints, per variant, the seconds, the verdict, the smallest and
largest ratio of its stretch to the whole scene's, and the changes it puts over the limit that
the whole scene keeps under it. Writes ``stretch_probe.csv`` (one row per change) to ``--out``
(default docs/perf).
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import LIB, circuits  # noqa: E402  (the circuits as benchmarks/timing.py builds them)

from mechc.proofs.dynamic import prove_dynamic  # noqa: E402
from mechc.proofs.settings import dyn_settings  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
VARIANTS = (("whole", False, None), ("pruned_inner", True, "inner"), ("pruned_all", True, "all"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--circuit", default="random81",
                    help="a circuit of benchmarks/timing.py (default %(default)s)")
    ap.add_argument("--out", default=str(ROOT / "docs" / "perf"))
    args = ap.parse_args()
    found = [d for name, d, _ in circuits(True) if name == args.circuit]
    if not found:
        ap.error(f"no circuit {args.circuit!r} in benchmarks/timing.py")
    design = found[0]
    st = dyn_settings(design)
    stretch: dict[str, list[float]] = {}
    for key, prune, freeze in VARIANTS:
        rec: list[dict] = []
        t0 = time.perf_counter()
        rep = prove_dynamic(design, design.spec, LIB, st, record=rec, prune=prune,
                            freeze=freeze)
        secs = time.perf_counter() - t0
        stretch[key] = [r["max_violation_mm"] for r in rec]
        line = f"{key:13s} {secs:7.1f} s  {'passed' if rep.passed else 'FAILED'}"
        if key != "whole":
            w = stretch["whole"]
            ratios = [v / b for v, b in zip(stretch[key], w) if b > 0]
            over = [i for i, (v, b) in enumerate(zip(stretch[key], w))
                    if v > st.violation_limit >= b]
            line += (f"  stretch / whole: {min(ratios):.2f} to {max(ratios):.2f}; over the "
                     f"{st.violation_limit} mm limit where the whole scene is not: {len(over)} "
                     f"{over[:8]}")
        print(line, flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "stretch_probe.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["change", *[f"{k}_stretch_mm" for k, _, _ in VARIANTS]])
        for i in range(len(stretch["whole"])):
            w.writerow([i, *[round(stretch[k][i], 5) for k, _, _ in VARIANTS]])


if __name__ == "__main__":
    main()
