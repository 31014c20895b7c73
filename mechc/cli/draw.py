"""``mechc draw``: a design (or a spec compiled in memory) as a to-scale SVG."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from mechc.backends.design_json import write_atomic
from mechc.backends.svg import DEFAULT_WIDTH, parse_state, render
from mechc.cells.sources import library_for_design
from mechc.cli.common import check_output, compile_options, load_design_or_spec
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError


def register(sub) -> None:
    d = sub.add_parser("draw", help="draw a design as a to-scale SVG",
                       description="Draw SPEC_OR_JSON (a compiled design, or a spec compiled in "
                       "memory first) to scale as SVG, every body at its pose for the input "
                       "state given by --state (default: every input off). The file is written "
                       "atomically: on any error an existing file is left untouched. Exit 1 if "
                       "some body cannot be posed in that state (it is drawn dashed red).")
    d.add_argument("design", metavar="SPEC_OR_JSON")
    d.add_argument("-o", "--output", help="output SVG file (default: a design JSON's name with "
                   ".svg beside it; for a spec, its name with .svg in the current directory, so "
                   "drawing a spec never writes into the folder of sources)")
    d.add_argument("--state", default="", metavar="A=1,B=0",
                   help="input values (0/1 or off/on); inputs not named are off")
    d.add_argument("--scale", type=float, default=2.0, metavar="PX_PER_MM",
                   help="pixels per millimetre (default: %(default)s)")
    d.add_argument("--width", type=float, default=DEFAULT_WIDTH, metavar="PX",
                   help="show the drawing at most this wide, its text sized to read at that "
                   "size (default: %(default)g px, one screen); 0: its natural size, --scale "
                   "px per mm")
    d.add_argument("--no-labels", action="store_true",
                   help="leave out cell, net, input and output labels")
    compile_options(d)
    d.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if not math.isfinite(args.scale) or args.scale <= 0:
        raise UsageError(f"--scale must be a positive number of px per mm, got {args.scale:g}")
    if args.width and not (math.isfinite(args.width) and args.width >= 200):
        raise UsageError(f"--width must be at least 200 px (or 0), got {args.width:g}")
    out = args.output or default_output(args.design)
    check_output(out, "drawing", [("input", args.design)])
    design = load_design_or_spec(args.design, args)
    if design.mechanism is None:
        raise UsageError(f"{args.design}: this design has no mechanism geometry; recompile the "
                         "spec with this mechc")
    state = parse_state(args.state, list(design.netlist.inputs))
    lib = library_for_design(design.cell_sources, args.cell_dirs, args.design)
    dr = render(design, state, args.scale, not args.no_labels, lib, args.width or None)
    write_atomic(out, dr.svg)
    ins = " ".join(f"{k}={v}" for k, v in state.items())
    res = " ".join(f"{k}={int(v > 0.5) if v == v else '?'}" for k, v in dr.outputs.items())
    print(f"{args.design} -> {out}: {ins} -> {res}, {dr.size_mm[0]:.0f} x {dr.size_mm[1]:.0f} mm, "
          f"{len(dr.svg) / 1024:.0f} KB")
    if dr.unsolved:
        print(f"mechc: error: {len(dr.unsolved)} bodies cannot be posed in this state (drawn "
              f"dashed red at their design pose): {', '.join(dr.unsolved)}", file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def default_output(design: str) -> str:
    """Beside a compiled design (a build product); in the current directory for a spec, whose
    folder holds sources (``draw examples/sorter.bool`` must not write into ``examples/``)."""
    path = Path(design)
    if path.suffix.lower() == ".json":
        return str(path.with_suffix(".svg"))
    return path.with_suffix(".svg").name
