"""What the interference design check costs: seconds of the whole design-check pass, and of the
interference measure alone on the same states, for every example and for random compiled
designs of about 100 and 200 cells.

    python benchmarks/interference.py [--quick]

The measure alone is fed the chunks of poses of the sweep the design-check pass makes (same
samples and state budget as ``mechc.passes.checks.run_design_checks``), so its seconds exclude
solving the closed forms; a sequential design's pass also walks its transitions (in the pass
only). Wall seconds on a shared machine: the median of three runs.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from mechc.bench.circuits import random_compiled
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.parts.poses import Poses
from mechc.passes.checks import run_design_checks
from mechc.physics.interference import Interference
from mechc.pipeline import compile_spec
from mechc.proofs.kinematic import sweep

LIB = load_library()
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


class Keep:
    def __init__(self):
        self.chunks: list[Poses] = []

    def add(self, poses: Poses) -> None:
        self.chunks.append(poses)


def chunks_of(design) -> list[Poses]:
    """The sweep of the design-check pass (its samples and state budget)."""
    keep = Keep()
    wide = len(design.netlist.inputs) > 10
    budget = max(2000, 2_000_000 // max(1, len(design.netlist.cells)))
    sweep(design, LIB, samples=5 if wide else 11, stats=keep, sample=128, max_states=budget)
    return keep.chunks


def median_seconds(fn, runs: int = 3) -> float:
    out = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return statistics.median(out)


def measure(name: str, design) -> None:
    mech = design.mechanism
    chunks = chunks_of(design)
    states = sum(max(v.size for v in c.u.values()) for c in chunks)

    def alone():
        m = Interference(mech, mech.ctx.clearance)
        for c in chunks:
            m.add(c)
        m.flush()  # it holds small chunks to measure them together
        return m

    t_alone = median_seconds(alone)
    t_pass = median_seconds(lambda: run_design_checks(design, LIB))
    s = alone().summary()
    print(f"{name:24s} {len(design.netlist.cells):5d} {len(mech.body_index()):6d} "
          f"{s['pairs_on_one_plane']:8d} {states:7d} {t_alone:9.3f} {t_pass:9.3f} "
          f"{s['failed_pairs']:6d}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="examples only")
    args = ap.parse_args()
    print(f"{'design':24s} {'cells':>5s} {'bodies':>6s} {'pairs':>8s} {'states':>7s} "
          f"{'interf s':>9s} {'pass s':>9s} {'failed':>6s}")
    for path in sorted(EXAMPLES.iterdir()):
        if path.suffix in {".bool", ".pla", ".blif", ".fsm", ".kiss2"}:
            measure(path.name, compile_spec(load_spec(path), library=LIB))
    if not args.quick:
        for cells, seed in ((100, 100), (200, 1)):
            measure(f"random_compiled({cells})", random_compiled(cells, seed=seed))


if __name__ == "__main__":
    main()
