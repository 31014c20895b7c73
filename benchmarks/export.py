"""Export figures of every example: the parts `mechc export` makes of it.

    python benchmarks/export.py [--markdown]

Compiles each spec in ``examples/`` with the default options, reads the design back from its
JSON (as ``mechc export`` does) and prints, per example: the bosses the compiler added
(counted by wrapping ``add_bosses`` where assembly calls it), plate parts of the bodies, rod-joint
links and the planes they take, planes in all (the frame's base plate included), sheets of
1000 x 600 mm the DXF needs, pins, pins a part has no hole for, springs, and the frame: the
base plate's size, its holes for fixed points, its guide slots, the stop blocks, and the
guide slots that meet another hole of the plate wherever their peg goes.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import mechc.passes.assemble as assemble
from mechc.backends.design_json import design_from_json, design_to_json
from mechc.backends.dxf import write_dxf
from mechc.backends.fabrication import ROD_LINK, fabrication
from mechc.frontends import load_spec
from mechc.pipeline import compile_spec

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SUFFIXES = (".bool", ".pla", ".blif", ".fsm", ".kiss2")


def figures(path: Path) -> dict:
    added: list = []
    add_bosses = assemble.add_bosses

    def counting(mech):
        out = add_bosses(mech)
        added[:] = out  # the last assembly's (assembly runs again after amplifying)
        return out

    assemble.add_bosses = counting
    try:
        design = design_from_json(design_to_json(compile_spec(load_spec(path))))
    finally:
        assemble.add_bosses = add_bosses
    fab = fabrication(design.mechanism)
    dxf = write_dxf(fab)
    fr = fab.frame
    links = [p for p in fab.pieces if p.role == ROD_LINK]
    x0, y0, x1, y1 = fr.base.bounds
    feats = fr.features
    return {
        "bosses": len(added),
        "plates": sum(p.kind != "frame" and p.role != ROD_LINK for p in fab.pieces),
        "links": len(links), "link planes": len({p.plane for p in links}),
        "planes": len(fab.planes), "sheets": len(dxf.sheets), "pins": len(fab.pins),
        "unholed": len(fab.unholed), "springs": len(fab.springs),
        "base": f"{x1 - x0:.0f} x {y1 - y0:.0f}",
        "fixed holes": sum(f.kind in ("pivot", "pin", "anchor", "slot") for f in feats),
        "slots": sum(f.kind == "guide" for f in feats), "stops": len(fr.stops),
        "crowded": len(fr.crowded),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = ap.parse_args()
    rows = []
    for path in sorted(p for p in EXAMPLES.iterdir() if p.suffix in SUFFIXES):
        rows.append((path.stem + path.suffix, figures(path)))
        if not args.markdown:
            print(f"  {path.name} done", flush=True)
    head = ["example", "bosses", "plate parts", "rod links (planes)", "planes", "sheets", "pins",
            "pins without a hole", "springs", "base plate (mm)", "fixed-point holes",
            "guide slots", "stop blocks", "slots meeting a hole"]
    lines = [[name, str(f["bosses"]), str(f["plates"]), f"{f['links']} ({f['link planes']})",
              str(f["planes"]),
              str(f["sheets"]), str(f["pins"]), str(f["unholed"]), str(f["springs"]),
              f["base"], str(f["fixed holes"]), str(f["slots"]), str(f["stops"]),
              str(f["crowded"])] for name, f in rows]
    if args.markdown:
        print("| " + " | ".join(head) + " |")
        print("|" + "---|" * len(head))
        for ln in lines:
            print("| " + " | ".join(ln) + " |")
    else:
        for ln in [head] + lines:
            print("  ".join(ln))


if __name__ == "__main__":
    main()
