"""What several commands share: the compile options, reading a spec or a design, and
refusing an output path that would overwrite an input."""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from pathlib import Path

from mechc.backends.design_json import check_writable, design_from_json, load_design_json
from mechc.cells.materials import DEFAULT_MATERIAL, MATERIALS
from mechc.errors import UsageError
from mechc.frontends import load_spec
from mechc.ir.design import Design
from mechc.ir.mechanism import SynthContext
from mechc.passes.assemble import MechOptions
from mechc.passes.map import MapOptions
from mechc.passes.minimise import MinimiseOptions
from mechc.passes.strength import force_ceiling
from mechc.pipeline import CompileOptions, compile_sequential, compile_spec
from mechc.ui import finite_float, int_at_least

__all__ = ["StageProgress", "by_type", "check_output", "compile_options", "compile_path",
           "load_design_or_spec", "load_spec", "options_from_args"]


def compile_options(c: argparse.ArgumentParser) -> None:
    """The options every command that compiles a spec takes (compile, simulate, draw)."""
    g = c.add_argument_group("compilation")
    g.add_argument("--cells", dest="cell_dirs", action="append", default=[], metavar="DIR",
                   help="extra directory of cell files (repeatable; also MECHC_CELLS)")
    g.add_argument("--use-cell", dest="use_cell", action="append", default=[], metavar="NAME",
                   help="use library cell NAME wherever it fits, also one the mapper does not "
                   "choose by itself (e.g. three_bar_and; repeatable)")
    g.add_argument("--fan-in", type=int_at_least(2), default=None, metavar="N",
                   help="at most N inputs per AND/OR/NAND/NOR cell (default: the library's)")
    g.add_argument("--time-limit", type=finite_float, default=20.0, metavar="S",
                   help="seconds per exact-cover program before the best cover found is used "
                   "and reported as not proven minimal (default: %(default)s)")
    g.add_argument("--phase", choices=["auto", "sop"], default="auto",
                   help="auto: also try complement (NOR/NAND root) and XOR forms and keep the "
                   "cheapest; sop: sums of products only (default: %(default)s)")
    g.add_argument("--map", dest="map_target", choices=["conventional", "threshold", "auto"],
                   default="conventional",
                   help="threshold: outputs of up to 3 inputs as THRESHOLD generators (001 Ch. "
                   "III); auto: only where that costs fewer parts (default: %(default)s)")
    g.add_argument("--levels", choices=["2", "multi", "auto"], default=None,
                   help="2: sums of products; multi: multi-level logic (Yosys/ABC, mapped to "
                   "the cells by parts; a BLIF or Verilog network is kept as its author wrote "
                   "it); auto: build both and keep the one with fewer parts (default: multi "
                   "for Verilog, 2 for the rest: auto runs Yosys on every compile)")
    g.add_argument("--no-share", action="store_true",
                   help="do not share product terms between outputs")
    g.add_argument("--keep-hazards", action="store_true",
                   help="build the minimum covers as they are, without consensus terms (outputs "
                   "may then dip during single-input changes)")
    m = c.add_argument_group("mechanism")
    m.add_argument("--stroke", type=finite_float, default=20.0, metavar="MM",
                   help="stroke of every terminal, off to on (default: %(default)s mm)")
    m.add_argument("--actuator-force", type=finite_float, default=100.0, metavar="N",
                   help="rated force of each input actuator (default: %(default)s N)")
    m.add_argument("--output-load", type=finite_float, default=0.5, metavar="N",
                   help="force each circuit output must move either way (default: %(default)s N)")
    m.add_argument("--clearance", type=finite_float, default=1.0, metavar="MM",
                   help="least gap between two parts on one plane in any state the design "
                   "checks visit; closer fails the interference check (default: %(default)s mm)")
    m.add_argument("--material", default=DEFAULT_MATERIAL, metavar="NAME",
                   help="plate material of bars, sliders, levers and rods: "
                   + ", ".join(f"{k} ({v.title})" for k, v in MATERIALS.items())
                   + " (default: %(default)s; springs are music wire and pins steel whatever "
                   "the plate)")
    m.add_argument("--no-amplify", action="store_true",
                   help="never insert AMPLIFIER cells by itself (by default they go where an "
                   "actuator or a MEMORY loop is short of force, and before a sequential output "
                   "that would move partway while a memory switches); the design checks then "
                   "report what fails")


def options_from_args(args: argparse.Namespace) -> CompileOptions:
    """The pipeline's options from the command line, each range checked."""
    if args.time_limit <= 0:
        raise UsageError("--time-limit must be positive")
    if not 1.0 <= args.stroke <= 500.0:
        raise UsageError("--stroke must be between 1 and 500 mm")
    if args.actuator_force <= 0 or args.output_load < 0:
        raise UsageError("--actuator-force must be positive and --output-load not negative")
    if not 0.0 <= args.clearance <= 100.0:
        raise UsageError("--clearance must be between 0 and 100 mm")
    check_forces(args)
    return CompileOptions(
        minimise=MinimiseOptions(time_limit=args.time_limit, share=not args.no_share,
                                 complements=args.phase == "auto",
                                 hazard_free=not args.keep_hazards),
        map=MapOptions(fan_in=args.fan_in, phase=args.phase,
                       hazard_free=not args.keep_hazards,
                       prefer=tuple(getattr(args, "use_cell", ())),
                       target=getattr(args, "map_target", "conventional")),
        mech=MechOptions(stroke=args.stroke, actuator_force=args.actuator_force,
                         output_load=args.output_load, clearance=args.clearance,
                         material=getattr(args, "material", DEFAULT_MATERIAL)),
        cell_dirs=tuple(args.cell_dirs),
        amplify=not getattr(args, "no_amplify", False),
        timings=getattr(args, "timings", False),
        levels=getattr(args, "levels", None) or default_levels(getattr(args, "spec", "")),
    )


def default_levels(spec: object) -> str:
    """Multi-level for Verilog (a two-level flattening of a datapath is rarely wanted), two
    levels for the rest: ``auto`` builds both, which makes every compile run Yosys."""
    return "multi" if str(spec).endswith(".v") else "2"


def check_forces(args: argparse.Namespace) -> None:
    """The material is known, and no force option asks more than one bar of it carries at
    yield (or, brittle, at break) with no safety factor at all: such a design could not be
    made of that plate whatever its layout, so it is refused (exit 2) before any work. Loads
    below that but above what the safety factors allow compile, and the strength checks fail
    (exit 1) naming the parts."""
    name = getattr(args, "material", DEFAULT_MATERIAL)
    if name not in MATERIALS:
        raise UsageError(f"--material {name!r} is not a known material; known: "
                         + ", ".join(MATERIALS))
    ctx = SynthContext(stroke=args.stroke, material=name)
    ceiling = force_ceiling(ctx)
    for opt, v in (("--output-load", args.output_load), ("--actuator-force", args.actuator_force)):
        if v > ceiling:
            raise UsageError(
                f"refusing to compile: {opt} {v:g} N is more than a {ctx.bar:g} x "
                f"{ctx.thickness:g} mm bar of {MATERIALS[name].title} carries at "
                f"{'break' if MATERIALS[name].brittle else 'yield'} ({ceiling:.4g} N, with no "
                f"safety factor); no design of that plate can carry it (a larger --stroke "
                f"widens the bars, or choose another --material)")


def compile_path(spec_path: str, args: argparse.Namespace, mechanism: bool = True,
                 stages: StageProgress | None = None) -> Design:
    """Compile a spec file in memory (``mechanism=False``: a sequential spec stops after
    placement, all its logic proof needs); ``stages`` shows the stages of a long compile."""
    spec = load_spec(spec_path)
    if not mechanism and getattr(spec, "kind", "") == "fsm":
        return compile_sequential(spec, options_from_args(args), mechanism=False)
    opts = options_from_args(args)
    if not getattr(args, "levels", None):
        # the file compiled decides, whichever command (simulate's --spec names another
        # file); a network too wide for a table has one way to be built: multi-level
        opts.levels = ("multi" if getattr(spec, "network", None) is not None
                       else default_levels(spec_path))
    if stages is None:
        return compile_spec(spec, opts)
    return compile_spec(spec, opts, progress=stages.start, done=stages.end)


class StageProgress:
    """The stages of a long job on stderr, silent for a short one: a stage still running after
    ``delay`` seconds is named (``compile: assemble ...``) and its seconds printed when it ends;
    :meth:`summary` gives every stage's seconds once the whole job took ``delay`` or more."""

    def __init__(self, label: str = "compile", delay: float = 2.0, stream=None,
                 enabled: bool = True):
        self.label, self.delay, self.enabled = label, delay, enabled
        self.stream = stream or sys.stderr
        self.t0 = time.perf_counter()
        self.seconds: list[tuple[str, float]] = []
        self._timer: threading.Timer | None = None
        self._named = False
        self._lock = threading.Lock()

    def start(self, name: str) -> None:
        self._cancel()
        self._named = False
        if self.enabled:
            self._timer = threading.Timer(self.delay, self._name, (name,))
            self._timer.daemon = True
            self._timer.start()

    def _name(self, name: str) -> None:
        with self._lock:
            self._named = True
            self._print(f"{self.label}: {name} ...")

    def end(self, name: str, seconds: float) -> None:
        self._cancel()
        self.seconds.append((name, seconds))
        if self._named or seconds >= self.delay:
            self._print(f"{self.label}: {name} {seconds:.1f} s")

    def _cancel(self) -> None:
        with self._lock:
            if self._timer is not None:
                self._timer.cancel()
                self._timer = None

    def _print(self, line: str) -> None:
        if self.enabled:
            try:
                print(line, file=self.stream, flush=True)
            except (OSError, ValueError):  # the stream went away (a closed pipe)
                self.enabled = False

    def close(self) -> None:
        """Stop any pending stage line (a job that ended by an error must not print later)."""
        self._cancel()

    def total(self) -> float:
        return time.perf_counter() - self.t0

    def summary(self) -> str | None:
        """'compile stages (s): minimise 1.2, map 0.2, ...' when the job was long, else None."""
        if not self.seconds or self.total() < self.delay:
            return None
        return (f"{self.label} stages (s): "
                + ", ".join(f"{n} {s:.2f}" for n, s in self.seconds)
                + f"; total {self.total():.1f}")


def check_output(out: str, what: str, inputs: list[tuple[str, str | None]]) -> None:
    """Refuse an output path that would overwrite an input or cannot be written, before any
    work is done (the write itself is atomic: see
    :func:`mechc.backends.design_json.write_atomic`)."""
    for kind, path in inputs:
        if path and (Path(out).resolve() == Path(path).resolve() or same_file(out, path)):
            raise UsageError(f"refusing to overwrite the {kind} '{path}' with the {what}")
    check_writable(out)


def same_file(a: str, b: str) -> bool:
    """Also a hard link, which resolve() does not see through."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet)
        return False


def by_type(d: dict) -> str:
    """'2 AND, 1 OR': cells by logic type, for summaries."""
    return ", ".join(f"{v} {k}" for k, v in d.items()) or "none"


def load_design_or_spec(path: str, args: argparse.Namespace) -> Design:
    """A compiled design (.json), or a spec compiled in memory."""
    if path.lower().endswith((".json", ".json.gz")):  # the logic level reads no geometry
        return design_from_json(load_design_json(path), path,
                                mechanism=getattr(args, "level", None) != "logic")
    # a logic proof of a sequential spec needs the netlist only, not the mechanism
    return compile_path(path, args, mechanism=getattr(args, "level", None) != "logic")


#: simulate's options that set the pymunk solver (DynSettings fields of the same names).
