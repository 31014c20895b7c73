"""Parts of two-level against multi-level designs (docs/multilevel.md's table).

    python benchmarks/multilevel_parts.py [examples/multilevel/adder4.v ...]

Each spec is compiled with ``--levels auto``: both designs are mapped, placed and assembled
(amplifiers counted), and the stats give both part counts. Printed as a Markdown table with
the compile seconds of the whole run (both designs), measured here.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from mechc.frontends import load_spec
from mechc.pipeline import CompileOptions, compile_spec

ROOT = Path(__file__).resolve().parent.parent
DEFAULT = [f"examples/multilevel/{n}.{f}"
           for n in ("adder4", "alu181", "cmp8") for f in ("v", "blif")]


def row(path: str) -> str:
    t0 = time.perf_counter()
    design = compile_spec(load_spec(ROOT / path), CompileOptions(levels="auto"))
    seconds = time.perf_counter() - t0
    lv = design.stats["levels"]
    two, multi = lv["parts"]["2"], lv["parts"]["multi"]
    by = design.stats["cells_by_type"]
    return (f"| `{path}` | {len(design.spec.inputs)} | {two} | {multi} | {two / multi:.2f}x | "
            f"{by.get('AMPLIFIER', 0)} | {design.stats['depth']} | {lv['multi']['method']} | "
            f"{seconds:.0f} |")


def main(argv: list[str]) -> None:
    print("| spec | inputs | two-level parts | multi-level parts | ratio | amplifiers (multi) "
          "| depth (multi) | multi-level method | seconds (both) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in argv or DEFAULT:
        print(row(path), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
