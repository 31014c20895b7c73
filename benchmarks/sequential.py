"""Seconds per input change of the sequential proofs (issue 4), the speed controller first.

    python benchmarks/sequential.py [--specs examples/speedctl.fsm ...] [--walks 2]

Per spec: compile once, then run the logic, kinematic and dynamic sequential proofs over the
same walks (the covering tour plus ``--walks`` seeded random walks) and print seconds per input
change of each, the dynamic level's cost as a multiple of the kinematic one measured in the
same run, and the dynamic level's largest output error against the closed form. Printed as
``name: value`` lines. Flow-table synthesis time for 4 to 32 rows is benchmarks/flowtable.py.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm_file
from mechc.pipeline import compile_sequential
from mechc.proofs.seq_logic import prove_sequential
from mechc.proofs.seq_mechanism import prove_sequential_dynamic, prove_sequential_kinematic

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--specs", nargs="+", default=[str(ROOT / "examples" / "speedctl.fsm")])
    ap.add_argument("--walks", type=int, default=2, help="seeded random walks after the tour")
    args = ap.parse_args(argv)
    lib = load_library()
    for path in args.specs:
        spec = parse_fsm_file(path)
        name = Path(path).stem
        t0 = time.perf_counter()
        design = compile_sequential(spec, library=lib)
        print(f"{name}_compile_seconds: {time.perf_counter() - t0:.3f}")
        print(f"{name}_cells: {len(design.netlist.cells)}")
        t0 = time.perf_counter()
        logic = prove_sequential(design.netlist, spec)
        t_logic = time.perf_counter() - t0
        kin = prove_sequential_kinematic(design, spec, lib, random_walks=args.walks)
        dyn = prove_sequential_dynamic(design, spec, lib, random_walks=args.walks)
        n = max(1, dyn["cases"])
        per_kin = kin["seconds"] / max(1, kin["cases"])
        per_dyn = dyn["seconds"] / n
        print(f"{name}_logic_transitions: {logic['transitions']}")
        print(f"{name}_logic_seconds_per_transition: "
              f"{t_logic / max(1, logic['transitions']):.3g}")
        print(f"{name}_kinematic_seconds_per_change: {per_kin:.3g}")
        print(f"{name}_dynamic_changes: {dyn['cases']}")
        print(f"{name}_dynamic_seconds_per_change: {per_dyn:.3g}")
        print(f"{name}_dynamic_vs_kinematic_cost: {per_dyn / max(per_kin, 1e-12):.1f}x")
        print(f"{name}_dynamic_max_error_fraction: {dyn['max_position_error_fraction']}")
        print(f"{name}_all_levels_passed: "
              f"{logic['passed'] and kin['passed'] and dyn['passed']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
