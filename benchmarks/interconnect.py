"""Interconnect figures of every example: rods, planes used, total rod length, bends.

    python benchmarks/interconnect.py [--markdown] [--random SEED:CELLS ...]

Compiles each spec in ``examples/`` with the default options and reads the figures back from
its design JSON (not from the compiler's own ``stats``, so the table also recomputes them):
planes are the distinct values of every body's ``layer`` and ``poly_layers`` (cells, input
sliders, the nets' fan-out bars and rods); rod length is pin to pin, summed over every rod of
every net (a ``pushrod`` body between its two pins, or a massless ``rod`` joint as designs
before rods were bodies held them); bends count the rods' corners (every rod is straight).

Then, for compiled random specs (``mechc.bench.circuits.random_compiled``; default the
benchmarks' 81-cell circuit, seed 100), how wide the channels made the mechanism: fan-out slots
per channel, the cells' width, the mass of all rods, and the heaviest load a gate drives
(``mechc.parts.pushrod.net_loads``: its rods and its loads' input sliders) against
``HEAVY_KG``, above which the screened proof runs a change in pymunk.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from mechc.backends.design_json import design_to_json
from mechc.bench.circuits import random_compiled
from mechc.frontends import load_spec
from mechc.ir.design import Design
from mechc.parts.pushrod import net_loads
from mechc.pipeline import compile_spec
from mechc.proofs.screen import HEAVY_KG

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


def channel_figures(d: Design) -> dict:
    """Fan-out slots per channel (distinct bar positions after each column), the cells' width
    (mm), every rod's mass (kg) and the loads gates drive (kg)."""
    mech, nl = d.mechanism, d.netlist
    depth = nl.depth()
    slots: dict[int, set[float]] = {}
    for net, part in mech.nets.items():
        col = 0 if net in nl.inputs else depth[nl.driver[net][0]]
        slots.setdefault(col, set()).add(part.data["fanout_bar_x"])
    xs = [x for p in mech.cells.values() for b in p.bodies for poly in b.outline
          for x, _ in poly]
    loads = net_loads(mech)
    gates = [loads[n] for n in mech.nets if n not in nl.inputs]
    return {"cells": len(nl.cells), "slots": [len(slots[k]) for k in sorted(slots)],
            "width_mm": max(xs) - min(xs),
            "rod_kg": sum(b.mass for p in mech.nets.values() for b in p.bodies),
            "heaviest_kg": max(gates, default=0.0),
            "heavy_gates": sum(m > HEAVY_KG for m in gates)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table")
    ap.add_argument("--random", action="append", metavar="SEED:CELLS",
                    help="a compiled random spec of about CELLS cells (repeatable; default "
                    "100:100, the benchmarks' 81-cell circuit)")
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
    else:
        widths = [max(len(r[i]) for r in [*lines, list(head)]) for i in range(len(head))]
        for row in [list(head), *lines]:
            print("  ".join(c.ljust(w) for c, w in zip(row, widths)))
        print(f"total rod length {total:.0f} mm")
    for arg in args.random or ["100:100"]:
        seed, cells = (int(v) for v in arg.split(":"))
        f = channel_figures(random_compiled(cells, seed=seed))
        print(f"\nrandom spec seed {seed} ({f['cells']} cells): fan-out slots per channel "
              f"{', '.join(map(str, f['slots']))}; cells {f['width_mm']:.0f} mm wide; rods "
              f"{f['rod_kg']:.2f} kg; heaviest gate load {f['heaviest_kg']:.4f} kg, "
              f"{f['heavy_gates']} gate(s) over {HEAVY_KG:g} kg")


if __name__ == "__main__":
    main()
