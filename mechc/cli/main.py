"""The ``mechc`` command: the parser and one call per command (each command is a module of
``mechc.cli`` with ``register(sub)`` and ``run(args)``; see ``mechc COMMAND --help``)."""

from __future__ import annotations

import argparse
import os
import sys
import traceback

from mechc import __version__
from mechc.cli import bench, cells, draw, export, new_cell, simulate, synth, view
from mechc.cli import compile as compile_cmd
from mechc.errors import (
    EXIT_INTERNAL,
    EXIT_OK,
    MechcError,
    SpecError,
)

DESCRIPTION = """\
mechc compiles logic into mechanisms: a Boolean or sequential specification becomes a netlist of
mechanical cells (sliders, levers, springs) with their geometry, and a simulation proves it.

  mechc compile sorter.bool -o sorter.json     spec -> mechanism JSON (netlist + geometry)
  mechc simulate sorter.json                   prove it (levels: logic, kinematic, dynamic)
  mechc draw sorter.json -o sorter.svg         look at it
  mechc export sorter.json -o sorter.dxf       make it: cut sheets, parts list, 3D model
  mechc view sorter.json -o sorter.html        watch it move (a page for any browser)
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
    compile_cmd.register(sub)
    simulate.register(sub)
    cells.register(sub)
    new_cell.register(sub)
    draw.register(sub)
    export.register(sub)
    view.register(sub)
    synth.register(sub)
    bench.register(sub)
    return p


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
