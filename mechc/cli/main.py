"""Command line: ``mechc compile | simulate | cells`` (see ``mechc COMMAND --help``)."""

from __future__ import annotations

import argparse
import os
import sys
import time
import traceback
from pathlib import Path

from mechc import __version__
from mechc.errors import (
    EXIT_FAILED,
    EXIT_INTERNAL,
    EXIT_OK,
    MechcError,
    SpecError,
    UsageError,
)
from mechc.ui import finite_float, int_at_least, table

DESCRIPTION = """\
mechc compiles logic into mechanisms: a Boolean or sequential specification becomes a netlist of
mechanical cells (sliders, levers, springs) with their geometry, and a simulation proves it.

  mechc compile sorter.bool -o sorter.json     spec -> mechanism JSON (netlist + geometry)
  mechc simulate sorter.json                   prove it (levels: logic, kinematic, dynamic)
  mechc draw sorter.json -o sorter.svg         look at it
  mechc cells                                  list the cell library

Exit status: 0 success, 1 a proof or design check failed, 2 bad input, 3 internal error.
"""


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return EXIT_OK
    try:
        return args.func(args)
    except SpecError as e:
        print(str(e), file=sys.stderr)
        return e.exit_code
    except MechcError as e:
        print(f"mechc: error: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        print("mechc: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return EXIT_OK
    except Exception as e:  # a bug in mechc: say so plainly
        if os.environ.get("MECHC_DEBUG"):
            traceback.print_exc()
        print(f"mechc: internal error: {type(e).__name__}: {e} (set MECHC_DEBUG=1 for a "
              "traceback, and please report it)", file=sys.stderr)
        return EXIT_INTERNAL


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="mechc", description=DESCRIPTION,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"mechc {__version__}")
    sub = p.add_subparsers(title="commands", metavar="COMMAND")

    c = sub.add_parser("compile", help="compile a spec to a netlist JSON",
                       description="Parse SPEC (.bool or .pla), minimise every output exactly, "
                       "map to library cells, place them, and write the design as JSON. The "
                       "output file is written atomically: on any error an existing file is "
                       "left untouched.")
    c.add_argument("spec", help="specification file (.bool, .pla, .fsm)")
    c.add_argument("-o", "--output", help="output JSON file (default: SPEC with .json suffix)")
    _compile_options(c)
    c.add_argument("--timings", action="store_true",
                   help="record seconds per stage in stats.seconds (the file then differs "
                   "from run to run)")
    c.add_argument("--print-netlist", action="store_true",
                   help="also print the netlist in canonical text form")
    c.set_defaults(func=cmd_compile)

    s = sub.add_parser("simulate", help="prove a design against its spec",
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       description="""\
Prove a design: SPEC_OR_JSON is a compiled design (.json) or a spec, compiled in memory first.

levels:
  logic      the netlist's cells evaluated as Boolean functions on every input vector
  kinematic  the mechanism's closed forms (from its geometry, not its logic types) on every
             input vector at rest and sampled along every single-input change: outputs within
             --tolerance of their positions, outputs that must not change dwell; design checks
  dynamic    (default) pymunk rigid bodies, springs and contacts; inputs moved by bounded-force
             actuators along a Gray-code tour of every vector plus --cases seeded random
             changes; outputs at rest, glitches, settling, joint violations (solver error)

Exit status 0 only if the proof holds; 1 if it fails (the failures are listed).""")
    s.add_argument("design", metavar="SPEC_OR_JSON")
    s.add_argument("--level", choices=["logic", "kinematic", "dynamic"], default="dynamic",
                   help="simulation level (default: %(default)s)")
    s.add_argument("--tolerance", type=finite_float, default=0.05, metavar="F",
                   help="outputs must sit within F of stroke of their position (default: "
                   "%(default)s)")
    s.add_argument("--cases", type=int, default=16, metavar="N",
                   help="dynamic: seeded random single-input changes after the Gray tour "
                   "(default: %(default)s)")
    s.add_argument("--seed", type=int, default=0, help="seed for the random cases")
    s.add_argument("--dt", type=finite_float, default=None, metavar="S",
                   help="dynamic: time step in seconds (default 2.5e-4)")
    s.add_argument("--iterations", type=int, default=None,
                   help="dynamic: solver iterations per step (default 60)")
    s.add_argument("--move-time", type=finite_float, default=None, metavar="S",
                   help="dynamic: seconds an input takes to move (default 0.08)")
    s.add_argument("--prune", action="store_true",
                   help="dynamic: run each input change on a scene of only the cells it can "
                   "move (see docs/performance.md)")
    s.add_argument("--accuracy", type=finite_float, default=None, metavar="F",
                   help="dynamic: the cheapest settings (from the measured error model) whose "
                   "output error is at most F of stroke, confirmed on the run by step halving")
    s.add_argument("--spec", metavar="OTHER",
                   help="prove against this spec instead of the one the design was compiled from")
    s.add_argument("--report", metavar="FILE.json", help="write the proof report as JSON")
    _compile_options(s)
    s.set_defaults(func=cmd_simulate)

    k = sub.add_parser("cells", help="list the cell library",
                       description="List library cells: name, logic type, pins, cost (parts). "
                       "Cells come from stdlib/ and from directories in --cells / MECHC_CELLS.")
    k.add_argument("--cells", dest="cell_dirs", action="append", default=[], metavar="DIR",
                   help="extra directory of cell files (repeatable)")
    k.add_argument("--json", action="store_true", help="print as JSON")
    k.set_defaults(func=cmd_cells)

    _register_optional(sub, "mechc.backends.svg")  # mechc draw ...
    _register_optional(sub, "mechc.cli.synth")  # mechc synth ...
    _register_optional(sub, "mechc.bench.speed_accuracy")  # mechc bench ...
    return p


def _register_optional(sub, module: str) -> None:
    """Subcommands that live with their subsystem: the module defines ``register(sub)``."""
    import importlib

    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as e:
        if e.name and module.startswith(e.name):
            return  # subsystem not present in this build
        raise
    mod.register(sub)


def _compile_options(c: argparse.ArgumentParser) -> None:
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
    m.add_argument("--no-amplify", action="store_true",
                   help="never insert AMPLIFIER cells by itself (by default they go where an "
                   "actuator or a MEMORY loop is short of force, and before a sequential output "
                   "that would move partway while a memory switches); the design checks then "
                   "report what fails")


def _options(args):
    from mechc.passes.assemble import MechOptions
    from mechc.passes.map import MapOptions
    from mechc.passes.minimise import MinimiseOptions
    from mechc.pipeline import CompileOptions

    if args.time_limit <= 0:
        raise UsageError("--time-limit must be positive")
    if not 1.0 <= args.stroke <= 500.0:
        raise UsageError("--stroke must be between 1 and 500 mm")
    if args.actuator_force <= 0 or args.output_load < 0:
        raise UsageError("--actuator-force must be positive and --output-load not negative")
    return CompileOptions(
        minimise=MinimiseOptions(time_limit=args.time_limit, share=not args.no_share,
                                 complements=args.phase == "auto",
                                 hazard_free=not args.keep_hazards),
        map=MapOptions(fan_in=args.fan_in, phase=args.phase,
                       hazard_free=not args.keep_hazards,
                       prefer=tuple(getattr(args, "use_cell", ())),
                       target=getattr(args, "map_target", "conventional")),
        mech=MechOptions(stroke=args.stroke, actuator_force=args.actuator_force,
                         output_load=args.output_load),
        cell_dirs=tuple(args.cell_dirs),
        amplify=not getattr(args, "no_amplify", False),
        timings=getattr(args, "timings", False),
    )


def _load_spec(spec_path: str):
    """The one place a spec file is read: .fsm (sequential) here, the others in mechc.frontends."""
    if str(spec_path).lower().endswith(".fsm"):
        from mechc.frontends.fsm import parse_fsm_file

        return parse_fsm_file(spec_path)
    from mechc.frontends import load_spec

    return load_spec(spec_path)


def _compile(spec_path: str, args, mechanism: bool = True):
    from mechc.pipeline import compile_sequential, compile_spec

    spec = _load_spec(spec_path)
    if not mechanism and getattr(spec, "kind", "") == "fsm":
        return compile_sequential(spec, _options(args), mechanism=False)
    return compile_spec(spec, _options(args))


def cmd_compile(args) -> int:
    from mechc.backends.design_json import design_to_json, dumps, validate, write_atomic

    out = args.output or str(Path(args.spec).with_suffix(".json"))
    _check_output(out, "output", [("spec", args.spec)])
    t0 = time.perf_counter()
    design = _compile(args.spec, args)
    obj = design_to_json(design, timings=args.timings)
    validate(obj, out)
    write_atomic(out, dumps(obj))
    st = design.stats
    methods = {v["method"] for v in st["minimisation"]["outputs"].values()}
    if st["minimisation"]["proven"]:
        how = "minimum proven"
    elif "espresso" in methods:
        how = "heuristic cover (espresso-style, wide PLA): not proven minimal"
    else:
        how = "minimum NOT proven (time limit or too many primes)"
    print(f"{args.spec} -> {out}: {st['cells']} cells ({_by_type(st['cells_by_type'])}), "
          f"{st['parts']} parts, {st['literals']} literals, {how}, "
          f"{time.perf_counter() - t0:.2f} s")
    for o in design.spec.outputs:
        print(f"  {o} = {design.equations[o]}")
        if design.implemented.get(o) and design.implemented[o] != design.equations[o]:
            print(f"  {' ' * len(o)}   built as {design.implemented[o]}")
    se = getattr(design, "sequential", None)
    if se is not None:
        for m in se.memories:
            print(f"  MEMORY {m}: set = {se.text(se.set_names[m])}, reset = "
                  f"{se.text(se.reset_names[m])}, initial {se.initial[m]}")
        if se.checked.get("sr_overlap_total_states"):
            print(f"  note: SET and RESET of a memory are both on in "
                  f"{se.checked['sr_overlap_total_states']} total state(s) that the spec never "
                  "reaches (every reachable one was checked)")
        for h in se.essential_hazards:
            print(f"  essential hazard: state {h['state']}, {h['input']} {h['from']} -> "
                  f"{h['to']}: {h['requires']}")
    for net, why in st.get("amplified", {}).items():
        print(f"  AMPLIFIER on {net}: {why}")
    if args.print_netlist:
        print(design.netlist.to_text(), end="")
    dc = st.get("design_checks", {})
    if dc and not dc["passed"]:
        print(f"DESIGN CHECKS FAILED ({len(dc['failed'])} of {dc['count']}); the design was "
              f"written to {out} for inspection:", file=sys.stderr)
        for text in dc["failed"][:20]:
            print(f"  {text}", file=sys.stderr)
        return EXIT_FAILED
    if dc:
        print(f"  design checks: {dc['count']} passed (min transmission angle "
              f"{dc['min_transmission_angle_deg']}°)")
    return EXIT_OK


def _check_output(out: str, what: str, inputs: list[tuple[str, str | None]]) -> None:
    """Refuse an output path that would overwrite an input or cannot be written, before any
    work is done (the write itself is atomic: see
    :func:`mechc.backends.design_json.write_atomic`)."""
    from mechc.backends.design_json import check_writable

    for kind, path in inputs:
        if path and (Path(out).resolve() == Path(path).resolve() or _same_file(out, path)):
            raise UsageError(f"refusing to overwrite the {kind} '{path}' with the {what}")
    check_writable(out)


def _same_file(a: str, b: str) -> bool:
    """Also a hard link, which resolve() does not see through."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet)
        return False


def _by_type(d: dict) -> str:
    return ", ".join(f"{v} {k}" for k, v in d.items()) or "none"


def load_design_or_spec(path: str, args):
    from mechc.backends.design_json import design_from_json, load_design_json

    if path.lower().endswith(".json"):
        return design_from_json(load_design_json(path), path)
    # a logic proof of a sequential spec needs the netlist only, not the mechanism
    return _compile(path, args, mechanism=getattr(args, "level", None) != "logic")


#: simulate's options that set the pymunk solver (DynSettings fields of the same names).
SOLVER_OPTIONS = ("dt", "iterations", "move_time")


def _check_simulate_options(args) -> None:
    """Every option range, before any file is read or any proof started."""
    if not 0 < args.tolerance < 0.5:
        raise UsageError("--tolerance must be between 0 and 0.5")
    if args.cases < 0:
        raise UsageError("--cases must not be negative")
    for opt in SOLVER_OPTIONS:
        v = getattr(args, opt)
        if v is not None and v <= 0:
            raise UsageError(f"--{opt.replace('_', '-')} must be positive")
    if args.accuracy is not None:
        if not 0 < args.accuracy < 0.5:
            raise UsageError("--accuracy must be between 0 and 0.5 (fraction of stroke)")
        if any(getattr(args, o) is not None for o in SOLVER_OPTIONS):
            raise UsageError("--accuracy chooses --dt, --iterations and --move-time")
    if args.report:  # before a proof that may take minutes, not after it
        _check_output(args.report, "report", [("design", args.design), ("spec", args.spec)])


def cmd_simulate(args) -> int:
    from mechc.backends.design_json import dumps, write_atomic
    from mechc.cells.library import load_library

    _check_simulate_options(args)
    design = load_design_or_spec(args.design, args)
    spec = _load_spec(args.spec) if args.spec else design.spec
    lib = load_library(args.cell_dirs)
    try:
        report = _prove(args, design, spec, lib)
    except UsageError as e:  # the options were checked: this is about the design, name it
        raise UsageError(f"{args.design}: {e}") from None
    report.source = {"design": args.design, "spec": args.spec or design.spec.path}
    print(report.summary_text())
    if args.report:
        write_atomic(args.report, dumps(report.to_json()))
    return EXIT_OK if report.passed else EXIT_FAILED


def _prove(args, design, spec, lib):
    """The proof at ``args.level`` of ``design`` against ``spec`` (a ProofReport), with a
    progress bar while a dynamic proof runs."""
    # imported when used, as every command's modules here: start-up time of the CLI
    from mechc.proofs import ProofSettings, prove, spec_kind
    from mechc.ui import Progress

    settings = ProofSettings(tolerance=args.tolerance, seed=args.seed, cases=args.cases,
                             prune=args.prune, accuracy=args.accuracy, dt=args.dt,
                             iterations=args.iterations, move_time=args.move_time)
    if args.level != "dynamic":
        return prove(design, spec, lib, args.level, settings)
    what = "sequential dynamic" if spec_kind(spec) == "sequential" else "dynamic"
    bar = Progress(1, f"{what} proof of {Path(args.design).name}")

    def tick(done: int, total: int) -> None:
        bar.total = total
        bar.update(done, "input changes")

    try:
        return prove(design, spec, lib, args.level, settings, tick)
    finally:
        bar.close()


def cmd_cells(args) -> int:
    import json

    from mechc.cells.library import load_library

    lib = load_library(args.cell_dirs)
    rows, items = [], []
    for name, cell in lib.cells.items():
        n = cell.min_inputs
        fan = (f"{cell.min_inputs}" if cell.min_inputs == cell.max_inputs
               else f"{cell.min_inputs}-{cell.max_inputs}")
        pins = ",".join(cell.input_names(n)) + (f"..{cell.input_names(cell.max_inputs)[-1]}"
                                                 if cell.max_inputs > n else "")
        rows.append([name, cell.type, fan, f"{pins or '-'} -> {','.join(cell.outputs)}",
                     cell.pin_kind, cell.cost(n), cell.description])
        items.append({"name": name, "type": cell.type, "inputs": [cell.min_inputs,
                      cell.max_inputs], "outputs": list(cell.outputs), "pin_kind": cell.pin_kind,
                      "cost": {str(k): cell.cost(k) for k in range(cell.min_inputs,
                                                                   cell.max_inputs + 1)},
                      "description": cell.description, "source": cell.source})
    if args.json:
        print(json.dumps(items, indent=2))
    else:
        print(table(rows, ["cell", "type", "inputs", "pins", "kind", "cost", "description"]))
    return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
