"""``mechc view``: a design animated in one self-contained HTML page, or as a GIF."""

from __future__ import annotations

import argparse
import gc
import sys
from contextlib import contextmanager
from pathlib import Path

from mechc.backends import animation, viewer
from mechc.backends.design_json import write_atomic
from mechc.cells.sources import library_for_design
from mechc.cli.common import check_output, compile_options, load_design_or_spec
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.ir.design import Design
from mechc.physics.scene import DynSettings
from mechc.proofs import ProofSettings, prove, spec_kind
from mechc.proofs import trace as pose_trace
from mechc.ui import Progress


def register(sub) -> None:
    v = sub.add_parser("view", help="animate a design in a browser page (or a GIF)",
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       description="""\
Animate SPEC_OR_JSON (a compiled design, or a spec compiled in memory first) from the poses its
proof visits, as one self-contained HTML page: open it from disk in any browser (no server,
nothing fetched). Click an input to change it: the mechanism moves there and the outputs show
the values; play runs the proof's tour of every state; a time slider, the planes shown or
hidden, zoom (mouse wheel) and pan (drag). See docs/viewer.md.

poses:
  default    the closed form (kinematic proof): every input state and every single-input change
  --dynamic  the dynamic proof's pymunk run as the tour and for the changes it made (slower);
             the closed form for changes it did not make

Exit status 0 when written and the proof(s) passed; 1 if a proof failed (the page is still
written, for inspection); 2 bad input.""")
    v.add_argument("design", metavar="SPEC_OR_JSON")
    v.add_argument("-o", "--output", metavar="PAGE.html",
                   help="the page (default: a design JSON's name with .html beside it; a "
                   "spec's name with .html in the current directory; none when only --gif is "
                   "asked for)")
    v.add_argument("--dynamic", action="store_true",
                   help="animate the dynamic proof's run (pymunk) instead of the closed form")
    v.add_argument("--cases", type=int, default=16, metavar="N",
                   help="--dynamic: seeded random input changes after the Gray tour "
                   "(default: %(default)s)")
    v.add_argument("--gif", metavar="OUT.gif",
                   help="also render the tour as an animated GIF (matplotlib, no browser)")
    v.add_argument("--gif-width", type=int, default=900, metavar="PX",
                   help="width of the GIF in pixels (default: %(default)s)")
    v.add_argument("--fps", type=int, default=12,
                   help="GIF frames per second (default: %(default)s)")
    v.add_argument("--slow", type=float, default=10.0, metavar="X",
                   help="GIF: slow motion, seconds shown per second simulated divided by X "
                   "(default: %(default)s)")
    compile_options(v)
    v.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.cases < 0:
        raise UsageError("--cases must not be negative")
    if not 100 <= args.gif_width <= 4000:
        raise UsageError("--gif-width must be between 100 and 4000 px")
    if not 1 <= args.fps <= 50:
        raise UsageError("--fps must be between 1 and 50")
    if not 0 < args.slow <= 1000:
        raise UsageError("--slow must be between 0 and 1000")
    out = args.output or (None if args.gif else default_output(args.design))
    if out:
        check_output(out, "page", [("input", args.design)])
    if args.gif:
        if Path(args.gif).suffix.lower() != ".gif":
            raise UsageError(f"--gif {args.gif}: the file name must end in .gif")
        check_output(args.gif, "GIF", [("input", args.design), ("page", out)])
    design = load_design_or_spec(args.design, args)
    if design.mechanism is None:
        raise UsageError(f"{args.design}: this design has no mechanism geometry; recompile the "
                         "spec with this mechc")
    with _no_gc():
        anim, passed = build_animation(args, design)
        text = viewer.page(anim) if out else ""
    if out:
        write_atomic(out, text)
        print(f"{args.design} -> {out}: {len(anim.nodes)} states, {len(anim.cases)} cases, "
              f"{len(anim.bodies)} bodies, tour {anim.tour_duration():.2f} s simulated, "
              f"{len(text.encode()) / 1024:.0f} KB")
    if args.gif:
        from mechc.backends import gif  # matplotlib: loaded only when a GIF is asked for

        bar = Progress(1, f"GIF of {Path(args.design).name}")

        drawn = bar.counter("frames")

        try:
            frames, size = gif.write(anim, args.gif, width=args.gif_width, fps=args.fps,
                                     slow=args.slow, progress=drawn)
        finally:
            bar.close()
        print(f"{args.design} -> {args.gif}: {frames} frames, {size / 1024:.0f} KB")
    if not passed:
        print("mechc: error: the proof the animation comes from failed (see mechc simulate)",
              file=sys.stderr)
        return EXIT_FAILED
    return EXIT_OK


def build_animation(args: argparse.Namespace, design: Design) -> tuple[animation.Animation,
                                                                       bool]:
    """The kinematic trace (and with --dynamic the dynamic one) of ``design``'s proof, as an
    animation; and whether the proofs passed."""
    spec = design.spec
    lib = library_for_design(design.cell_sources, args.cell_dirs, args.design)
    source = {"design": args.design, "spec": spec.path}
    traces = []
    levels = ["kinematic"] + (["dynamic"] if args.dynamic else [])
    for level in levels:
        rec = pose_trace.TraceRecorder(design.mechanism, move_time=DynSettings().move_time)
        settings = ProofSettings(cases=args.cases, trace=rec)
        bar = None
        try:
            if level == "dynamic":
                what = ("sequential dynamic" if spec_kind(spec) == "sequential"
                        else "dynamic")
                bar = Progress(1, f"{what} proof of {Path(args.design).name}")

                report = prove(design, spec, lib, level, settings,
                               bar.counter("input changes"))
            else:
                report = prove(design, spec, lib, level, settings)
        except UsageError as e:
            raise UsageError(f"{args.design}: {e}") from None
        finally:
            if bar is not None:
                bar.close()
        traces.append(rec.to_json(report, list(spec.inputs), list(spec.outputs), source))
    types = {c.id: c.type for c in design.netlist.cells.values()}
    name = Path(spec.path).name if getattr(spec, "path", None) else Path(args.design).name
    anim = animation.build(traces[0], traces[1] if args.dynamic else None, types, title=name)
    return anim, all(t["proof"]["passed"] for t in traces)


@contextmanager
def _no_gc():
    """No cyclic garbage collection while the trace's millions of numbers are alive: they
    hold no cycles, and each full collection walked them all (a random 86-cell design's page:
    20.7 s with collections, 11.0 s without)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def default_output(design: str) -> str:
    """Beside a compiled design; in the current directory for a spec (as ``mechc draw``)."""
    path = Path(design)
    if path.suffix.lower() == ".json":
        return str(path.with_suffix(".html"))
    return path.with_suffix(".html").name
