"""Held-out sweep of random flow tables through the command line: each table is written as a
``.fsm`` file, then ``mechc compile`` and ``mechc simulate`` (default: dynamic) run on it as
a user would run them.

    python benchmarks/fsm_heldout.py --seeds 7000 7019 [--rows 7 10] [--inputs 1 2]
                                     [--outputs 1 2] [--dc 0.0] [--dir DIR]

Table of seed ``s`` is ``random_flow_table`` of ``default_rng(s)`` with rows, inputs and
outputs drawn uniformly from the given ranges (as in ``benchmarks/fsm_acceptance.py``). A
table counts as *accepted* when compile exits 0, *refused* when it exits 1 or 2 with one
``error:`` line and no traceback, and *passing* when simulate exits 0 on the written design.
A failure is: compile exits 0 and simulate does not, any traceback, or any other exit
status. Prints one line per table and then ``name: value`` lines.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from mechc.bench.circuits import random_flow_table
from mechc.ir.seqspec import FlowTable


def fsm_text(ft: FlowTable) -> str:
    """The table in the ``.fsm`` flow-table form (why: the sweep goes through the parser too)."""
    lines = [f"inputs {' '.join(ft.inputs)}", f"outputs {' '.join(ft.outputs)}",
             "columns " + " ".join(ft.label(k) for k in range(len(ft.columns))), "flow"]
    for r, name in enumerate(ft.rows):
        ents = []
        for k in range(len(ft.columns)):
            d = ft.next[r][k]
            ents.append("-" if d is None else (f"({ft.rows[d]})" if d == r else ft.rows[d]))
        outs = " ".join("-" if v is None else str(v) for v in ft.out[r])
        lines.append(f"{name}: {' '.join(ents)} | {outs}")
    return "\n".join(lines) + "\n"


def table(seed: int, rows: tuple[int, int], inputs: tuple[int, int],
          outputs: tuple[int, int], dc: float) -> FlowTable:
    rng = np.random.default_rng(seed)
    return random_flow_table(rng, int(rng.integers(rows[0], rows[1] + 1)),
                             int(rng.integers(inputs[0], inputs[1] + 1)),
                             int(rng.integers(outputs[0], outputs[1] + 1)), p_dc_output=dc)


def mechc(*args: str) -> tuple[int, str]:
    """Run the command line in a fresh process, as a user would; (status, stdout+stderr)."""
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parent.parent))
    p = subprocess.run([sys.executable, "-m", "mechc", *args], capture_output=True, text=True,
                       env=env)
    return p.returncode, p.stdout + p.stderr


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, nargs=2, required=True, metavar=("FIRST", "LAST"))
    ap.add_argument("--rows", type=int, nargs=2, default=(7, 10))
    ap.add_argument("--inputs", type=int, nargs=2, default=(1, 2))
    ap.add_argument("--outputs", type=int, nargs=2, default=(1, 2))
    ap.add_argument("--dc", type=float, default=0.0, help="P(an output bit is '-')")
    ap.add_argument("--level", default="dynamic", choices=("logic", "kinematic", "dynamic"))
    ap.add_argument("--dir", help="keep the .fsm and .json files here")
    args = ap.parse_args(argv)
    work = Path(args.dir or tempfile.mkdtemp(prefix="fsm_heldout_"))
    work.mkdir(parents=True, exist_ok=True)
    n = accepted = passing = 0
    failures: list[str] = []
    refused: dict[str, int] = {}
    for seed in range(args.seeds[0], args.seeds[1] + 1):
        ft = table(seed, tuple(args.rows), tuple(args.inputs), tuple(args.outputs), args.dc)
        src = work / f"t{seed}.fsm"
        out = work / f"t{seed}.json"
        src.write_text(fsm_text(ft))
        out.unlink(missing_ok=True)
        n += 1
        t0 = time.perf_counter()
        rc, text = mechc("compile", "-q", str(src), "-o", str(out))
        head = f"seed {seed}: {len(ft.rows)} rows, {ft.n} inputs, {len(ft.outputs)} outputs:"
        if "Traceback" in text or rc not in (0, 1, 2):
            failures.append(f"seed {seed}: compile exit {rc}")
            print(f"{head} FAIL compile exit {rc}\n{text}", flush=True)
            continue
        if rc != 0:
            err = next((ln for ln in text.splitlines() if "error" in ln or "FAIL" in ln),
                       text.strip().splitlines()[-1] if text.strip() else "")
            key = f"exit {rc}"
            refused[key] = refused.get(key, 0) + 1
            print(f"{head} refused (exit {rc}): {err}", flush=True)
            continue
        accepted += 1
        rc, text = mechc("simulate", str(out), "--level", args.level)
        ok = rc == 0 and "Traceback" not in text
        passing += ok
        if not ok:
            failures.append(f"seed {seed}: simulate exit {rc}")
        last = text.strip().splitlines()[-1] if text.strip() else ""
        print(f"{head} accepted; simulate {args.level} exit {rc} ({last}) "
              f"[{time.perf_counter() - t0:.0f} s]", flush=True)
    print(f"tables: {n}")
    print(f"accepted: {accepted}")
    print(f"accepted_fraction: {accepted / max(1, n):.3f}")
    print(f"accepted_passing: {passing}")
    print(f"refused: {refused}")
    print(f"failures: {failures}")
    return 0 if not failures else 1


if __name__ == "__main__":
    raise SystemExit(main())
