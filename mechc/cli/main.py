"""Command line: ``mechc compile | simulate | cells`` (see ``mechc COMMAND --help``)."""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from pathlib import Path

from mechc import __version__
from mechc.cli import bench, cells, draw, synth
from mechc.cli import compile as compile_cmd
from mechc.cli.common import check_output, compile_options, load_design_or_spec, load_spec
from mechc.errors import (
    EXIT_FAILED,
    EXIT_INTERNAL,
    EXIT_OK,
    MechcError,
    SpecError,
    UsageError,
)
from mechc.ui import finite_float, table

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
    compile_cmd.register(sub)
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
    compile_options(s)
    s.set_defaults(func=cmd_simulate)
    cells.register(sub)
    draw.register(sub)
    synth.register(sub)
    bench.register(sub)
    return p


SOLVER_OPTIONS = ("dt", "iterations", "move_time")


def _solver_settings(args, design):
    """Default dynamic settings with the solver options the user gave."""
    from mechc.physics.scene import DynSettings

    st = DynSettings(violation_limit=0.005 * design.mechanism.ctx.stroke
                     if design.mechanism else 0.1)
    for opt in SOLVER_OPTIONS:
        v = getattr(args, opt)
        if v is not None:  # checked positive by _check_simulate_options
            setattr(st, opt, v)
    return st


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
        check_output(args.report, "report", [("design", args.design), ("spec", args.spec)])


def cmd_simulate(args) -> int:
    from mechc.backends.design_json import dumps, write_atomic
    from mechc.cells.library import load_library

    _check_simulate_options(args)
    design = load_design_or_spec(args.design, args)
    spec = load_spec(args.spec) if args.spec else design.spec
    lib = load_library(args.cell_dirs)
    try:
        report = _prove(args, design, spec, lib)
    except UsageError as e:  # the options were checked: this is about the design, name it
        raise UsageError(f"{args.design}: {e}") from None
    report["design"] = args.design
    report["spec"] = args.spec or design.spec.path
    print_report(report, spec)
    if args.report:
        write_atomic(args.report, dumps(report))
    return EXIT_OK if report["passed"] else EXIT_FAILED


def _prove(args, design, spec, lib) -> dict:
    """The proof at ``args.level`` of ``design`` against ``spec``: the report."""
    from mechc.proofs.logic import check_interface

    sequential = getattr(spec, "kind", "") == "fsm"
    if not sequential and any(c.type == "MEMORY" for c in design.netlist.cells.values()):
        raise UsageError("a sequential design (with MEMORY cells) is proved against a .fsm spec, "
                         "not a combinational one")
    check_interface(design.netlist, spec)  # every level assumes the same pins as the spec
    if args.level == "logic" and sequential:
        from mechc.proofs.seq_logic import prove_sequential

        report = prove_sequential(design.netlist, spec, seed=args.seed)
    elif args.level == "logic":
        from mechc.proofs.logic import prove_logic

        report = prove_logic(design.netlist, spec)
    elif args.level == "kinematic" and sequential:
        from mechc.proofs.seq_mechanism import prove_sequential_kinematic

        report = prove_sequential_kinematic(design, spec, lib, tolerance=args.tolerance,
                                            seed=args.seed)
    elif args.level == "dynamic" and sequential:
        from mechc.proofs.seq_mechanism import prove_sequential_dynamic
        from mechc.ui import Progress

        bar = Progress(1, f"sequential dynamic proof of {Path(args.design).name}")

        def step(done, total):
            bar.total = total
            bar.update(done, "input changes")

        st = None
        if any(getattr(args, o) is not None for o in SOLVER_OPTIONS):
            from mechc.proofs.seq_mechanism import settle_allowance

            st = _solver_settings(args, design)
            st.settle_time = max(st.settle_time, settle_allowance(design, lib))
        try:
            report = prove_sequential_dynamic(design, spec, lib, settings=st,
                                              tolerance=args.tolerance, seed=args.seed,
                                              progress=step)
        finally:
            bar.close()
    elif args.level == "kinematic":
        from mechc.proofs.kinematic import prove_kinematic

        report = prove_kinematic(design, spec, lib, tolerance=args.tolerance, seed=args.seed)
    else:
        from mechc.proofs.dynamic import PRUNE_DEFAULT, prove_dynamic
        from mechc.ui import Progress

        st = _solver_settings(args, design)
        bar = Progress(1, f"dynamic proof of {Path(args.design).name}")

        def tick(done, total):
            bar.total = total
            bar.update(done, "input changes")

        try:
            if args.accuracy is not None:
                from mechc.proofs.accuracy import prove_with_accuracy

                report = prove_with_accuracy(design, spec, lib, args.accuracy,
                                             tolerance=args.tolerance, extra=args.cases,
                                             seed=args.seed, progress=tick,
                                             prune=args.prune)
            else:
                report = prove_dynamic(design, spec, lib, st, tolerance=args.tolerance,
                                       extra=args.cases, seed=args.seed, progress=tick,
                                       prune=args.prune or PRUNE_DEFAULT)
        finally:
            bar.close()
    return report


SUMMARY_KEYS = [
    ("cases", "input states / changes"), ("transitions", "single-input changes"),
    ("max_position_error_fraction", "max output error vs closed form (fraction of stroke)"),
    ("max_deviation_fraction", "max output deviation from spec (fraction of stroke)"),
    ("min_margin_fraction", "min margin to mid-stroke (fraction of stroke)"),
    ("max_joint_violation_mm", "max joint violation (mm)"),
    ("max_contact_penetration_mm", "max contact overrun (mm)"),
    ("max_settle_time_s", "max settle time (s)"),
    ("min_transmission_angle_deg", "min transmission angle (deg)"),
    ("min_toggle_distance_deg", "min distance from toggle (deg)"),
    ("seconds", "seconds"),
]


def print_report(report: dict, spec) -> None:
    rows = [[label, report[k]] for k, label in SUMMARY_KEYS if report.get(k) is not None]
    print(table(rows, ["level " + report["level"], "value"]))
    if report.get("accuracy"):
        from mechc.proofs.accuracy import describe

        print(describe(report["accuracy"]))
    verdict = "PASSED" if report["passed"] else "FAILED"
    kinds = report.get("failure_kinds")
    extra = f" ({', '.join(f'{v} {k}' for k, v in kinds.items())})" if kinds else ""
    print(f"{verdict}: level {report['level']}, {report['cases']} cases, "
          f"{report['failure_count']} failures{extra}, {report['seconds']:.3f} s")
    for f in report["failures"][:10]:
        print("  " + _failure_text(f))
    if report["failure_count"] > 10:
        print(f"  ... and {report['failure_count'] - 10} more (see --report)")
    hazards = (report.get("sequential") or {}).get("hazards") or []
    if hazards:  # timing the logic cannot remove: what the mechanism must respect
        print(f"ordering requirements ({len(hazards)}; the kinematic and dynamic levels check "
              "them):")
        for h in hazards[:10]:
            print(f"  {h['kind']}: {h['requires']}")


def _failure_text(f: dict) -> str:
    if "message" in f and "inputs" not in f:
        return f["message"]
    ins = " ".join(f"{k}={v}" for k, v in f.get("inputs", {}).items())
    kind = f.get("kind", "")
    if kind in ("", "rest") and "got" in f:
        return f"{f['output']}: expected {f['expected']}, got {f['got']} at {ins}"
    head = f"{kind}: "
    if "moving" in f:
        head += f"{f['moving']} -> {f.get('to', '')} " if "to" in f else f"{f['moving']} moving "
    if "output" in f:
        head += f"output {f['output']} (expected {f['expected']}) "
        for key in ("position", "max_deviation", "max_deviation_fraction", "deviation_fraction"):
            if key in f:
                head += f"{key.replace('_', ' ')} {f[key]} "
    if "message" in f:
        head += f["message"] + " "
    return head + f"at {ins}"


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
