"""``mechc simulate``: prove a design (or a spec compiled in memory) at one level."""

from __future__ import annotations

import argparse
from pathlib import Path

from mechc.backends.design_json import dumps, write_atomic
from mechc.cells.library import Library
from mechc.cells.sources import library_for_design
from mechc.cli.common import check_output, compile_options, load_design_or_spec, load_spec
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.ir.design import Design
from mechc.ir.seqspec import SeqSpec
from mechc.ir.spec import Spec
from mechc.physics.scene import DynSettings
from mechc.proofs import LEVELS, ProofReport, ProofSettings, prove, spec_kind
from mechc.proofs import trace as pose_trace
from mechc.proofs.dynamic import RECHECK_MAX
from mechc.proofs.parallel import available_cores
from mechc.proofs.settings import LOGIC_METHODS
from mechc.ui import Progress, finite_float


def register(sub) -> None:
    s = sub.add_parser("simulate", help="prove a design against its spec",
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       description="""\
Prove a design: SPEC_OR_JSON is a compiled design (.json) or a spec, compiled in memory first.

levels:
  logic      the netlist's cells evaluated as Boolean functions on every input vector; a
             design too wide to enumerate is proved by a SAT miter instead (--logic-method)
  kinematic  the mechanism's closed forms (from its geometry, not its logic types) on every
             input vector at rest and sampled along every single-input change: outputs within
             --tolerance of their positions, outputs that must not change dwell; design checks
  screened   (default) the dynamic level's verdict, with pymunk run only on the changes the
             timing level cannot vouch for (small slack, an untimed or heavily loaded
             cell, a held output with a possible hazard or near its tolerance) and on
             witnesses of every cell kind the others switch; it falls back to every change
             when the changes that ran disagree with the timing model or leave less than
             a stated headroom of a solver limit; a sequential design runs every transition
  dynamic    the reference: pymunk rigid bodies, springs and contacts; inputs moved by
             bounded-force actuators along a Gray-code tour of every vector plus --cases
             seeded random changes; outputs at rest, glitches, settling, joint violations
             (solver error), every change in pymunk
  timing     the dynamic level's changes timed from the closed form and the cells'
             characterised tables (no scene): each output's switching and settle time, the
             critical path, slack; a sequential design's ordering requirements with slack

Exit status 0 only if the proof holds; 1 if it fails (the failures are listed).""")
    s.add_argument("design", metavar="SPEC_OR_JSON")
    s.add_argument("--level", choices=list(LEVELS), default="screened",
                   help="simulation level (default: %(default)s)")
    s.add_argument("--tolerance", type=finite_float, default=0.05, metavar="F",
                   help="outputs must sit within F of stroke of their position (default: "
                   "%(default)s)")
    s.add_argument("--cases", type=int, default=16, metavar="N",
                   help="dynamic: seeded random single-input changes after the Gray tour "
                   "(default: %(default)s)")
    s.add_argument("--seed", type=int, default=0, help="seed for the random cases")
    s.add_argument("--logic-method", choices=list(LOGIC_METHODS), default="auto",
                   help="logic: every vector evaluated (exhaustive), proved by a SAT miter "
                   "(sat), or a seeded sample (sampled, not a proof); auto: exhaustive while "
                   "cheap, else sat (default: %(default)s)")
    s.add_argument("--dt", type=finite_float, default=None, metavar="S",
                   help="dynamic: time step in seconds (default 2.5e-4)")
    s.add_argument("--iterations", type=int, default=None,
                   help="dynamic: solver iterations per step (default 60)")
    s.add_argument("--move-time", type=finite_float, default=None, metavar="S",
                   help="dynamic: seconds an input takes to move (default 0.08)")
    s.add_argument("--hold", type=finite_float, default=None, metavar="S",
                   help="dynamic, screened and timing: seconds each input change is held "
                   "after its move before the next, the time it has to settle (default: "
                   "0.15, or longer where the design needs it: 2 x a combinational "
                   "design's static critical path, the longest chain of its cells' "
                   "characterised delays; a sequential design's memories in turn). Give "
                   "the time your machine will allow to prove the design at that pace")
    s.add_argument("--no-recheck", dest="recheck", action="store_false",
                   help="dynamic and screened: do not run the changes failing on a joint "
                   "stretch, contact overrun or late settle again at twice the iterations "
                   f"(by default the first {RECHECK_MAX} are: one that passes every check "
                   "there failed by the solver and is proved there, counted as passed; one "
                   "that still fails is listed as failing; the screened level also re-runs "
                   "a witness that failed its calibration on stretch or overrun alone, and "
                   "clears on it there. Each costs about twice a change at the proof's "
                   "settings)")
    s.add_argument("--prune", action="store_true",
                   help="dynamic: run each input change on a scene of only the cells it can "
                   "move (see docs/performance.md)")
    s.add_argument("--accuracy", type=finite_float, default=None, metavar="F",
                   help="dynamic: the cheapest settings (from the measured error model) whose "
                   "output error is at most F of stroke, confirmed on the run by step halving")
    s.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="dynamic: run the input changes (a sequential design: its walks) on N "
                   "processes; the report is the same as with --jobs 1, case by case (default: "
                   f"every core this process may use, here {available_cores()}; a --trace "
                   "run stays in this process)")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="dynamic: run the same cases on the Dask distributed cluster whose "
                   "scheduler is at ADDRESS (e.g. tcp://127.0.0.1:8786; needs "
                   "pip install 'mechc[cluster]'); the report is the serial run's")
    s.add_argument("--spec", metavar="OTHER",
                   help="prove against this spec instead of the one the design was compiled from")
    s.add_argument("--report", metavar="FILE.json", help="write the proof report as JSON")
    s.add_argument("--trace", metavar="FILE.json",
                   help="kinematic and dynamic: write every body's pose in every case the "
                   "proof visits as JSON (docs/trace.md)")
    s.add_argument("--trace-every", type=finite_float, default=None, metavar="S",
                   help="dynamic: seconds of simulated time between trace samples (default "
                   f"{pose_trace.EVERY_S}; each change's start and end are always sampled)")
    compile_options(s)
    s.set_defaults(func=run)


#: What --accuracy chooses; with --hold, the options that must be positive.
SOLVER_OPTIONS = ("dt", "iterations", "move_time")
#: The levels that run pymunk scenes (the screened one on some of the changes).
DYNAMIC = ("dynamic", "screened")


def _check_options(args: argparse.Namespace) -> None:
    """Every option range, before any file is read or any proof started."""
    if not 0 < args.tolerance < 0.5:
        raise UsageError("--tolerance must be between 0 and 0.5")
    if args.cases < 0:
        raise UsageError("--cases must not be negative")
    for opt in (*SOLVER_OPTIONS, "hold"):
        v = getattr(args, opt)
        if v is not None and v <= 0:
            raise UsageError(f"--{opt.replace('_', '-')} must be positive")
    if args.accuracy is not None:
        if not 0 < args.accuracy < 0.5:
            raise UsageError("--accuracy must be between 0 and 0.5 (fraction of stroke)")
        if any(getattr(args, o) is not None for o in SOLVER_OPTIONS):
            raise UsageError("--accuracy chooses --dt, --iterations and --move-time")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError("--jobs must be at least 1")
    if args.logic_method != "auto" and args.level != "logic":
        raise UsageError("--logic-method chooses how the logic level checks (--level logic)")
    if not args.recheck and args.level not in DYNAMIC:
        raise UsageError("--no-recheck turns off the re-run of a dynamic proof's failing "
                         "changes (--level dynamic or screened)")
    if args.hold is not None and args.level not in (*DYNAMIC, "timing"):
        raise UsageError("--hold sets how long a dynamic proof holds each change (--level "
                         "dynamic, screened or timing)")
    if args.scheduler is not None and args.level not in DYNAMIC:
        raise UsageError("--scheduler runs the cases of a dynamic proof (--level dynamic or "
                         "screened)")
    if args.report:  # before a proof that may take minutes, not after it
        check_output(args.report, "report", [("design", args.design), ("spec", args.spec)])
    if args.trace_every is not None:
        if not args.trace or args.level not in DYNAMIC:
            raise UsageError("--trace-every spaces the samples of a dynamic --trace")
        if args.trace_every <= 0:
            raise UsageError("--trace-every must be positive")
    if args.trace:
        if args.level in ("logic", "timing"):
            raise UsageError(f"--trace records body poses: the {args.level} level has none (use "
                             "--level kinematic or dynamic)")
        if args.prune:
            raise UsageError("--trace records the whole scene: it cannot be taken with --prune")
        check_output(args.trace, "trace", [("design", args.design), ("spec", args.spec),
                                           ("report", args.report)])


def run(args: argparse.Namespace) -> int:
    _check_options(args)
    design = load_design_or_spec(args.design, args)
    spec = load_spec(args.spec) if args.spec else design.spec
    lib = library_for_design(design.cell_sources, args.cell_dirs, args.design)
    try:
        trace = _recorder(args, design)
        report = _prove(args, design, spec, lib, trace)
    except UsageError as e:  # the options were checked: this is about the design, name it
        raise UsageError(f"{args.design}: {e}") from None
    report.source = {"design": args.design, "spec": args.spec or design.spec.path}
    print(report.summary_text())
    screen = report.figures.get("screen")
    if screen:  # how many changes ran in pymunk, how many the timing level cleared
        print(screen["text"])
    if args.report:
        write_atomic(args.report, dumps(report.to_json()))
    if trace is not None:
        doc = trace.to_json(report, list(spec.inputs), list(spec.outputs), report.source)
        write_atomic(args.trace, pose_trace.dumps(doc))
    return EXIT_OK if report.passed else EXIT_FAILED


def _recorder(args: argparse.Namespace, design: Design) -> pose_trace.TraceRecorder | None:
    """The pose recorder ``--trace`` asks for (None: nothing is recorded)."""
    if not args.trace:
        return None
    if design.mechanism is None:
        raise UsageError("the design has no geometry (compile it with this mechc version)")
    return pose_trace.TraceRecorder(
        design.mechanism, every=args.trace_every or pose_trace.EVERY_S,
        move_time=args.move_time or DynSettings().move_time)


def _prove(args: argparse.Namespace, design: Design, spec: Spec | SeqSpec, lib: Library,
           trace: pose_trace.TraceRecorder | None = None) -> ProofReport:
    """The proof at ``args.level`` of ``design`` against ``spec`` (a ProofReport), with a
    progress bar while a kinematic or dynamic proof runs (shown after 1.5 s)."""
    settings = ProofSettings(tolerance=args.tolerance, seed=args.seed, cases=args.cases,
                             logic_method=args.logic_method,
                             prune=args.prune, accuracy=args.accuracy, dt=args.dt,
                             iterations=args.iterations, move_time=args.move_time,
                             hold=args.hold, recheck=args.recheck, trace=trace,
                             jobs=args.jobs or available_cores(), scheduler=args.scheduler)
    if args.level == "logic":
        return prove(design, spec, lib, args.level, settings)
    what = ("sequential " if spec_kind(spec) == "sequential" else "") + args.level
    where = (f" on {args.scheduler}" if args.scheduler
             else f" on {settings.jobs} processes"
             if args.level in DYNAMIC and settings.jobs > 1 and not trace else "")
    bar = Progress(1, f"{what} proof of {Path(args.design).name}{where}")

    tick = bar.counter({"dynamic": "input changes", "screened": "input changes",
                        "timing": "cell measurements"}.get(args.level, "states"))

    try:
        return prove(design, spec, lib, args.level, settings, tick)
    finally:
        bar.close()
