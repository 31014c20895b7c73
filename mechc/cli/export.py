"""``mechc export``: a design as files to make it from: cut sheets (DXF), a parts list (CSV),
a 3D assembly (STL, glTF) or the drawing (SVG)."""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

from mechc.backends.bom import bom_rows, write_bom
from mechc.backends.design_json import design_from_json, design_to_json, write_atomic
from mechc.backends.fabrication import Fabrication, fabrication
from mechc.backends.svg import render
from mechc.cells.sources import library_for_design
from mechc.cli.common import check_output, compile_options, load_design_or_spec
from mechc.errors import EXIT_OK, UsageError
from mechc.ui import Progress, finite_float

#: format -> the file name suffix it is written with by default
SUFFIX = {"dxf": ".dxf", "svg": ".svg", "stl": ".stl", "gltf": ".glb", "bom": ".csv"}
#: suffix of -o -> format, when --format is not given
BY_SUFFIX = {".dxf": "dxf", ".svg": "svg", ".stl": "stl", ".glb": "gltf", ".gltf": "gltf",
             ".csv": "bom"}

FORMATS_HELP = """\
formats:
  dxf    cut sheets for a laser or water-jet cutter, in mm: every part's outline and pin holes,
         one layer per plane ("plane 0", "plane 1", ...; the links of rod joints on planes of
         their own above), the frame (base plate with a hole for every fixed pivot, a guide
         slot per slider and screw holes; stop blocks) on "frame", part names on "... labels"
         (engrave or hide), sheet borders on "sheets" (never cut); parts nested without
         overlap on --sheet sized sheets
  bom    bill of materials (CSV): plates by plane with material and size, springs (rate,
         preload, free length, wire, coils), pins (diameter, grip), rollers, actuators (force,
         stroke) and motors, each with its count and the names of the parts
  stl    the 3D assembly as one mesh in mm: every plate extruded at the plate thickness and
         stacked at its plane's height (plane k from k*t to (k+1)*t), the frame's base plate
         one plate under the lowest plane
  gltf   the same assembly as glTF 2.0, one named node per part, in metres (glTF's unit);
         -o NAME.glb (binary, default) or NAME.gltf (one text file)
  svg    the to-scale drawing of `mechc draw` at rest (every input off)

The parts are read at the rest pose, each in its own frame; see docs/export.md."""


def register(sub) -> None:
    e = sub.add_parser("export", help="cut sheets (DXF), parts list (CSV), 3D model (STL, "
                       "glTF) or drawing (SVG) of a design",
                       description="Write the files to make SPEC_OR_JSON from (a compiled "
                       "design, or a spec compiled in memory first). The file is written "
                       "atomically: on any error an existing file is left untouched.",
                       epilog=FORMATS_HELP, formatter_class=argparse.RawDescriptionHelpFormatter)
    e.add_argument("design", metavar="SPEC_OR_JSON")
    e.add_argument("-f", "--format", choices=list(SUFFIX),
                   help="what to write (default: from the -o file's suffix: .dxf .csv .stl "
                   ".glb .gltf .svg)")
    e.add_argument("-o", "--output", help="output file (default: the design's name with the "
                   "format's suffix, beside a design JSON, in the current directory for a spec)")
    e.add_argument("--sheet", default="1000x600", metavar="WxH",
                   help="dxf: stock sheet width x height in mm (default: %(default)s); a part "
                   "larger than the sheet gets a sheet of its own, and is named")
    e.add_argument("--gap", type=finite_float, default=3.0, metavar="MM",
                   help="dxf: least distance between parts and from the sheet's edge "
                   "(default: %(default)s mm)")
    e.add_argument("--preview", metavar="IMAGE",
                   help="dxf: also draw the sheets to IMAGE (.png, .svg or .pdf), as the DXF "
                   "reads (ezdxf's drawing add-on); stl, gltf: draw the assembly to IMAGE "
                   "(.png), seen from above at a slant")
    e.add_argument("--by-plane", action="store_true",
                   help="dxf: each plane's parts on sheets of their own (default: all planes "
                   "share sheets, as they are cut from one plate)")
    compile_options(e)
    e.set_defaults(func=run)


def parse_sheet(text: str) -> tuple[float, float]:
    m = re.fullmatch(r"\s*([0-9.]+)\s*[xX×]\s*([0-9.]+)\s*", text)
    try:
        w, h = (float(m.group(1)), float(m.group(2))) if m else (math.nan, math.nan)
    except ValueError:
        w = h = math.nan
    if not (math.isfinite(w) and math.isfinite(h) and 10 <= w <= 10000 and 10 <= h <= 10000):
        raise UsageError(f"--sheet {text!r}: expected WIDTHxHEIGHT in mm, each 10 to 10000 "
                         "(e.g. 1000x600)")
    return w, h


def choose_format(args: argparse.Namespace) -> str:
    if args.format:
        return args.format
    if args.output and Path(args.output).suffix.lower() in BY_SUFFIX:
        return BY_SUFFIX[Path(args.output).suffix.lower()]
    raise UsageError("say what to export with --format dxf|bom|stl|gltf|svg (or an -o file "
                     "ending in .dxf, .csv, .stl, .glb, .gltf or .svg)")


def default_output(design: str, fmt: str) -> str:
    """Beside a compiled design; in the current directory for a spec (never into the folder
    of sources)."""
    path = Path(design)
    out = path.with_suffix(SUFFIX[fmt])
    return str(out) if path.suffix.lower() == ".json" else out.name


def run(args: argparse.Namespace) -> int:
    fmt = choose_format(args)
    sheet = parse_sheet(args.sheet)
    if not 0 <= args.gap <= 100:
        raise UsageError(f"--gap must be between 0 and 100 mm, got {args.gap:g}")
    out = args.output or default_output(args.design, fmt)
    check_output(out, f"{fmt} export", [("input", args.design)])
    if args.preview:
        kinds = {"dxf": (".png", ".svg", ".pdf"), "stl": (".png",), "gltf": (".png",)}
        if fmt not in kinds:
            raise UsageError("--preview draws cut sheets or the assembly: it goes with "
                             "--format dxf, stl or gltf")
        if Path(args.preview).suffix.lower() not in kinds[fmt]:
            raise UsageError(f"--preview {args.preview}: expected a "
                             f"{' or '.join(kinds[fmt])} file for --format {fmt}")
        check_output(args.preview, "preview", [("input", args.design), ("DXF output", out)])
    design = load_design_or_spec(args.design, args)
    if not args.design.lower().endswith(".json"):
        # the parts as a design file holds them (rounded), so a spec exports exactly what
        # its compiled design does
        design = design_from_json(design_to_json(design), args.design)
    if design.mechanism is None:
        raise UsageError(f"{args.design}: this design has no mechanism geometry; recompile the "
                         "spec with this mechc")
    if fmt == "svg":
        return _svg(design, args, out)
    fab = fabrication(design.mechanism)
    if fmt == "dxf":
        from mechc.backends.dxf import write_dxf  # ezdxf loads only for this format

        res = write_dxf(fab, sheet, args.gap, args.by_plane)
        write_atomic(out, res.text)
        sizes = sorted({f"{s.size[0]:.0f} x {s.size[1]:.0f} mm" for s in res.sheets})
        print(f"{args.design} -> {out}: {len(fab.pieces)} parts on {len(res.sheets)} "
              f"sheet{'s' * (len(res.sheets) != 1)} ({', '.join(sizes)}), "
              f"{len(fab.planes)} planes, {_holes(fab)} holes")
        if args.preview:
            from mechc.backends.dxf_preview import preview  # matplotlib loads only for this

            write_atomic(args.preview, preview(res.text, Path(args.preview).suffix[1:].lower()))
            print(f"  sheets drawn to {args.preview}")
        if res.oversize:
            print(f"mechc: note: {len(res.oversize)} part(s) larger than the {sheet[0]:g} x "
                  f"{sheet[1]:g} mm sheet, each on a sheet of its own: "
                  f"{', '.join(res.oversize)}", file=sys.stderr)
    elif fmt == "bom":
        write_atomic(out, write_bom(fab))
        print(f"{args.design} -> {out}: {len(bom_rows(fab))} lines: {len(fab.pieces)} plates, "
              f"{len(fab.springs)} springs, {len(fab.pins)} pins, {len(fab.actuators)} "
              f"actuators, {len(fab.motors)} motors")
    else:
        from mechc.backends.mesh import assembly, write_gltf, write_stl  # trimesh: these only

        n = sum(1 for p in fab.pieces if p.plane is not None)
        bar = Progress(n, "meshing parts")
        asm = assembly(fab, bar.update)
        bar.close()
        data = write_stl(asm) if fmt == "stl" else write_gltf(
            asm, binary=Path(out).suffix.lower() != ".gltf")
        write_atomic(out, data)
        if args.preview:
            from mechc.backends.mesh_preview import preview as draw_3d  # matplotlib: only here

            write_atomic(args.preview, draw_3d(asm))
        lo, hi = asm.bounds
        print(f"{args.design} -> {out}: {len(asm.parts)} parts on {len(fab.planes)} planes, "
              f"{hi[0] - lo[0]:.0f} x {hi[1] - lo[1]:.0f} x {hi[2] - lo[2]:.0f} mm, "
              f"{len(data) / 1024:.0f} KB"
              + (f"; drawn to {args.preview}" if args.preview else ""))
    _warn_unholed(fab)
    _note_frame(fab)
    return EXIT_OK


def _note_frame(fab: Fabrication) -> None:
    crowded = fab.frame.crowded if fab.frame else []
    if crowded:
        print(f"mechc: note: {len(crowded)} slider guide slot(s) in the base plate meet "
              f"another hole of it wherever the peg goes: {', '.join(crowded[:4])}"
              + (f" and {len(crowded) - 4} more" if len(crowded) > 4 else ""), file=sys.stderr)


def _holes(fab: Fabrication) -> int:
    return sum(len(p.holes) for p in fab.pieces)


def _warn_unholed(fab: Fabrication) -> None:
    if fab.unholed:
        names = ", ".join(f"{j} in {b}" for j, b in fab.unholed[:4])
        more = f" and {len(fab.unholed) - 4} more" if len(fab.unholed) > 4 else ""
        print(f"mechc: note: {len(fab.unholed)} pin(s) have no hole in a part they join (the "
              f"pin's centre is on or past that part's edge): {names}{more}; the BOM lists "
              "them", file=sys.stderr)


def _svg(design, args: argparse.Namespace, out: str) -> int:
    """The drawing at rest, as ``mechc draw`` makes it."""
    lib = library_for_design(design.cell_sources, args.cell_dirs, args.design)
    dr = render(design, {}, 2.0, True, lib)
    write_atomic(out, dr.svg)
    print(f"{args.design} -> {out}: the drawing at rest, {dr.size_mm[0]:.0f} x "
          f"{dr.size_mm[1]:.0f} mm")
    return EXIT_OK
