"""Interconnect figures of every example: rods, planes used, total rod length, bends.

    python benchmarks/interconnect.py [--markdown]

Compiles each spec in ``examples/`` with the default options and reads the figures back from
its design JSON (not from the compiler's own ``stats``, so the table also recomputes them):
planes are the distinct values of every body's ``layer`` and ``poly_layers`` (cells, input
sliders, the nets' fan-out bars and rods); rod length is pin to pin, summed over every rod of
every net (a ``pushrod`` body between its two pins, or a massless ``rod`` joint as designs
before rods were bodies held them); bends count the rods' corners (every rod is straight).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from mechc.backends.design_json import design_to_json
from mechc.frontends import load_spec
from mechc.pipeline import compile_spec

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SUFFIXES = (".bool", ".pla", ".blif", ".fsm", ".kiss2")


def figures(obj: dict) -> dict:
    """Rods, planes, total rod length (mm) and bends of a design JSON."""
    mech = obj["mechanism"]
    parts = [c["geometry"] for c in obj["cells"] if "geometry" in c]
    parts += list(mech["inputs"].values()) + list(mech["nets"].values())
    planes = {pl for p in parts for b in p["bodies"] for pl in b.get("poly_layers")
              or [b.get("layer", 0)]}
    lengths = []
    for part in mech["nets"].values():
        for j in part["joints"]:
            if j["kind"] == "rod":
                lengths.append(j["length_mm"])
        for b in part["bodies"]:
            ends = [j["pa"] for j in part["joints"] if j["kind"] == "pin"
                    and b["id"] in (j["a"], j["b"])]
            lengths.append(math.dist(*ends))
    return {"rods": len(lengths), "planes": sorted(planes), "rod_length_mm": sum(lengths),
            "bends": 0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = ap.parse_args()
    rows = []
    for path in sorted(p for p in EXAMPLES.iterdir() if p.suffix in SUFFIXES):
        obj = design_to_json(compile_spec(load_spec(path)))
        rows.append((path.name, figures(obj)))
    head = ("example", "rods", "planes", "which", "rod length (mm)", "bends")
    lines = [[name, str(f["rods"]), str(len(f["planes"])), " ".join(map(str, f["planes"])),
              f"{f['rod_length_mm']:.0f}", str(f["bends"])] for name, f in rows]
    total = sum(f["rod_length_mm"] for _, f in rows)
    if args.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for row in lines:
            print("| " + " | ".join(row) + " |")
        print(f"| total | {sum(f['rods'] for _, f in rows)} | | | {total:.0f} | 0 |")
        return
    widths = [max(len(r[i]) for r in [*lines, list(head)]) for i in range(len(head))]
    for row in [list(head), *lines]:
        print("  ".join(c.ljust(w) for c, w in zip(row, widths)))
    print(f"total rod length {total:.0f} mm")


if __name__ == "__main__":
    main()
