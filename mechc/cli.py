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
from mechc.ui import table

DESCRIPTION = """\
mechc compiles logic into mechanisms: a Boolean or sequential specification becomes a netlist of
mechanical cells (sliders, levers, springs) with their geometry, and a simulation proves it.

  mechc compile sorter.bool -o sorter.json     spec -> netlist JSON
  mechc simulate sorter.json --level logic     prove a compiled design against its spec
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
    c.add_argument("spec", help="specification file (.bool, .pla)")
    c.add_argument("-o", "--output", help="output JSON file (default: SPEC with .json suffix)")
    _compile_options(c)
    c.add_argument("--timings", action="store_true",
                   help="record seconds per stage in stats.seconds (the file then differs "
                   "from run to run)")
    c.add_argument("--print-netlist", action="store_true",
                   help="also print the netlist in canonical text form")
    c.set_defaults(func=cmd_compile)

    s = sub.add_parser("simulate", help="prove a design against its spec",
                       description="Prove a design: SPEC_OR_JSON is a compiled design (.json) "
                       "or a spec, compiled in memory first. At level 'logic' the netlist is "
                       "evaluated on every input vector and compared with the spec (don't-cares "
                       "excepted). Exit 0 only if the proof holds.")
    s.add_argument("design", metavar="SPEC_OR_JSON")
    s.add_argument("--level", choices=["logic"], default="logic",
                   help="simulation level (default: %(default)s)")
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

    _register_optional(sub, "mechc.synthesis.cli")  # mechc synth ...
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
    g.add_argument("--fan-in", type=_positive_int(2), default=None, metavar="N",
                   help="at most N inputs per AND/OR/NAND/NOR cell (default: the library's)")
    g.add_argument("--time-limit", type=float, default=20.0, metavar="S",
                   help="seconds per exact-cover program before the best cover found is used "
                   "and reported as not proven minimal (default: %(default)s)")
    g.add_argument("--phase", choices=["auto", "sop"], default="auto",
                   help="auto: also try complement (NOR/NAND root) and XOR forms and keep the "
                   "cheapest; sop: sums of products only (default: %(default)s)")
    g.add_argument("--no-share", action="store_true",
                   help="do not share product terms between outputs")


def _positive_int(lo: int):
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'") from None
        if v < lo:
            raise argparse.ArgumentTypeError(f"must be at least {lo}")
        return v

    return parse


def _options(args):
    from mechc.logic.minimise import MinimiseOptions
    from mechc.netlist.mapping import MapOptions
    from mechc.pipeline import CompileOptions

    if args.time_limit <= 0:
        raise UsageError("--time-limit must be positive")
    return CompileOptions(
        minimise=MinimiseOptions(time_limit=args.time_limit, share=not args.no_share,
                                 complements=args.phase == "auto"),
        map=MapOptions(fan_in=args.fan_in, phase=args.phase),
        cell_dirs=tuple(args.cell_dirs),
        timings=getattr(args, "timings", False),
    )


def _compile(spec_path: str, args):
    from mechc.pipeline import compile_spec
    from mechc.spec import load_spec

    spec = load_spec(spec_path)
    return compile_spec(spec, _options(args))


def cmd_compile(args) -> int:
    from mechc.writer import design_to_json, dumps, validate, write_atomic

    out = args.output or str(Path(args.spec).with_suffix(".json"))
    if Path(out).resolve() == Path(args.spec).resolve():
        raise UsageError(f"refusing to overwrite the spec '{args.spec}' with the output")
    t0 = time.perf_counter()
    design = _compile(args.spec, args)
    obj = design_to_json(design, timings=args.timings)
    validate(obj, out)
    write_atomic(out, dumps(obj))
    st = design.stats
    print(f"{args.spec} -> {out}: {st['cells']} cells ({_by_type(st['cells_by_type'])}), "
          f"{st['parts']} parts, {st['literals']} literals, minimum "
          f"{'proven' if st['minimisation']['proven'] else 'NOT proven (time limit)'}, "
          f"{time.perf_counter() - t0:.2f} s")
    for o in design.spec.outputs:
        print(f"  {o} = {design.equations[o]}")
        if design.implemented.get(o) and design.implemented[o] != design.equations[o]:
            print(f"  {' ' * len(o)}   built as {design.implemented[o]}")
    if args.print_netlist:
        print(design.netlist.to_text(), end="")
    return EXIT_OK


def _by_type(d: dict) -> str:
    return ", ".join(f"{v} {k}" for k, v in d.items()) or "none"


def load_design_or_spec(path: str, args):
    from mechc.writer import design_from_json, load_design_json

    if path.lower().endswith(".json"):
        return design_from_json(load_design_json(path), path)
    return _compile(path, args)


def cmd_simulate(args) -> int:
    from mechc.sim.logic import prove_logic
    from mechc.spec import load_spec
    from mechc.writer import dumps, write_atomic

    design = load_design_or_spec(args.design, args)
    spec = load_spec(args.spec) if args.spec else design.spec
    report = prove_logic(design.netlist, spec)
    report["design"] = args.design
    report["spec"] = args.spec or design.spec.path
    rows = [[o, "pass" if not any(f["output"] == o for f in report["failures"]) else "FAIL"]
            for o in spec.outputs]
    print(table(rows, ["output", "logic"]))
    verdict = "PASSED" if report["passed"] else "FAILED"
    print(f"{verdict}: level {report['level']}, {report['cases']} input vectors, "
          f"{report['failure_count']} wrong output values, {report['seconds']:.3f} s")
    for f in report["failures"][:10]:
        ins = " ".join(f"{k}={v}" for k, v in f["inputs"].items())
        print(f"  {f['output']}: expected {f['expected']}, got {f['got']} at {ins}")
    if report["failure_count"] > 10:
        print(f"  ... and {report['failure_count'] - 10} more")
    if args.report:
        write_atomic(args.report, dumps(report))
    return EXIT_OK if report["passed"] else EXIT_FAILED


def cmd_cells(args) -> int:
    import json

    from mechc.library import load_library

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
