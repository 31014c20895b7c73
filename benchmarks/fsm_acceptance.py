"""Random flow tables through compile and the three sequential proofs: the fraction compile
accepts, and that every accepted one passes (issue 15).

    python benchmarks/fsm_acceptance.py [--tables 20] [--rows 7 10] [--inputs 1 2]
                                        [--outputs 1 2] [--dc 0.0] [--seed 0]

Table ``i`` is ``random_flow_table`` of ``default_rng(seed + i)`` with rows, inputs and
outputs drawn uniformly from the given ranges (inclusive) and output bits unspecified with
probability ``--dc``. Each is compiled (``compile_sequential``, the CLI's defaults); an
accepted one (every design check passed, ordering requirements included) is proven at the
logic, kinematic and dynamic levels (the ``mechc simulate`` defaults); with ``--logic-only``
synthesis and the logic proof alone (accepted = synthesised). Prints one line per
table and then ``name: value`` lines: tables, accepted, accepted_fraction,
accepted_passing_all, refused reasons.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from mechc.bench.circuits import random_flow_table
from mechc.cells.library import load_library
from mechc.errors import MechcError
from mechc.ir.seqspec import SeqSpec
from mechc.pipeline import compile_sequential
from mechc.proofs.seq_logic import prove_sequential
from mechc.proofs.seq_mechanism import prove_sequential_dynamic, prove_sequential_kinematic


def table(seed: int, rows: tuple[int, int], inputs: tuple[int, int],
          outputs: tuple[int, int], dc: float) -> SeqSpec:
    rng = np.random.default_rng(seed)
    ft = random_flow_table(rng, int(rng.integers(rows[0], rows[1] + 1)),
                           int(rng.integers(inputs[0], inputs[1] + 1)),
                           int(rng.integers(outputs[0], outputs[1] + 1)), p_dc_output=dc)
    return SeqSpec(f"<random {seed}>", ft.inputs, ft.outputs, table=ft)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tables", type=int, default=20)
    ap.add_argument("--rows", type=int, nargs=2, default=(7, 10))
    ap.add_argument("--inputs", type=int, nargs=2, default=(1, 2))
    ap.add_argument("--outputs", type=int, nargs=2, default=(1, 2))
    ap.add_argument("--dc", type=float, default=0.0, help="P(an output bit is '-')")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--logic-only", action="store_true",
                    help="synthesis and the logic proof only (no mechanism, no design checks)")
    args = ap.parse_args(argv)
    lib = load_library()
    accepted = passing = 0
    refused: dict[str, int] = {}
    for i in range(args.tables):
        seed = args.seed + i
        spec = table(seed, args.rows, args.inputs, args.outputs, args.dc)
        rows = len(spec.table.rows)
        t0 = time.perf_counter()
        try:
            d = compile_sequential(spec, library=lib, mechanism=not args.logic_only)
        except MechcError as e:  # refused at synthesis (the table's own problem)
            reason = type(e).__name__
            refused[reason] = refused.get(reason, 0) + 1
            print(f"seed {seed}: {rows} rows, {spec.n} inputs: refused ({reason}: {e})")
            continue
        if args.logic_only:
            accepted += 1
            ok = prove_sequential(d.netlist, spec)["passed"]
            passing += ok
            print(f"seed {seed}: {rows} rows, {spec.n} inputs: compiled, logic {ok}")
            continue
        dc = d.stats["design_checks"]
        if not dc["passed"]:
            reason = "ordering" if any("ordering" in t for t in dc["failed"]) else "design check"
            refused[reason] = refused.get(reason, 0) + 1
            print(f"seed {seed}: {rows} rows, {spec.n} inputs: exit 1 ({dc['failed'][0]})")
            continue
        accepted += 1
        logic = prove_sequential(d.netlist, spec)
        kin = prove_sequential_kinematic(d, spec, lib)
        dyn = prove_sequential_dynamic(d, spec, lib)
        ok = logic["passed"] and kin["passed"] and dyn["passed"]
        passing += ok
        reqs = d.stats["sequential"].get("ordering", {})
        cure = reqs.get("cure") or {}
        print(f"seed {seed}: {rows} rows, {spec.n} inputs: accepted, "
              f"{len(reqs.get('requirements', []))} ordering requirement(s)"
              f"{', cured' if cure.get('kept') else ''}; logic {logic['passed']}, kinematic "
              f"{kin['passed']}, dynamic {dyn['passed']} {dyn['failure_kinds'] or ''} "
              f"({time.perf_counter() - t0:.0f} s)", flush=True)
    print(f"tables: {args.tables}")
    print(f"accepted: {accepted}")
    print(f"accepted_fraction: {accepted / max(1, args.tables):.3f}")
    print(f"accepted_passing_all: {passing}")
    print(f"refused: {refused}")
    return 0 if passing == accepted else 1


if __name__ == "__main__":
    raise SystemExit(main())
