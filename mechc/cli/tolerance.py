"""``mechc tolerance``: the yield of a design when it is made (tolerances, pin clearance,
spring error), which dimensions matter, and each output's structural error."""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from mechc.backends.design_json import (
    design_from_json,
    dumps,
    load_design_json,
    write_atomic,
)
from mechc.cells.sources import library_for_design
from mechc.cli.common import check_output
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.tolerance.montecarlo import ToleranceSettings, run
from mechc.tolerance.process import PROCESSES, process
from mechc.tolerance.report import summary, to_json
from mechc.ui import Progress, finite_float, int_at_least


def register(sub) -> None:
    procs = "\n".join(f"  {p.name:6s} {p.what}: +-{p.tol} mm, pin clearance {p.clearance} mm, "
                      f"springs +-{p.spring_tol:.0%}" for p in PROCESSES.values())
    s = sub.add_parser(
        "tolerance", help="yield of a design as made: tolerances, pin clearance, springs",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=f"""\
Monte Carlo over every dimension of a compiled design (joint points, pin holes, stops, pivots,
rod lengths, springs' rate and preload, outlines): each sample is drawn uniformly within the
tolerance and proven at the kinematic level (every input state and every single-input change:
outputs within --proof-tolerance of their positions, outputs that must hold dwelling, no state
binding or unsolvable, transmission angles, distance from toggle, springs' force against what
they must move). Pin clearance is lost motion at every pin, taken up the worst way. Samples are
solved together (one evaluation of the closed forms over samples x states).

Prints the yield with its 95 % (Wilson) interval, the checks that fail most, each output's
structural error (scatter of its rest positions against the stroke) and the dimensions that
matter most (finite differences of the closed forms; regression of the samples' margin).

processes (--process; explicit --tol/--clearance/--spring-tol override it):
{procs}

Exit status: 0 when the yield reaches --yield, 1 when it does not, 2 bad input.""")
    s.add_argument("design", metavar="DESIGN.json", help="a compiled design (mechc compile)")
    s.add_argument("--process", choices=list(PROCESSES), default=None,
                   help="take the tolerances of a process (default: --tol 0.1 --clearance 0.05 "
                   "--spring-tol 0.1)")
    s.add_argument("--tol", type=finite_float, default=None, metavar="MM",
                   help="every dimension +-MM (default 0.1)")
    s.add_argument("--clearance", type=finite_float, default=None, metavar="MM",
                   help="diametral play of every pin in its hole (default 0.05)")
    s.add_argument("--spring-tol", type=finite_float, default=None, metavar="FRACTION",
                   help="springs' rate and preload +-FRACTION (default 0.1)")
    s.add_argument("--samples", type=int_at_least(1), default=10_000, metavar="N",
                   help="Monte Carlo samples (default: %(default)s)")
    s.add_argument("--seed", type=int, default=0, help="seed of the draws (default: 0)")
    s.add_argument("--yield", dest="yield_level", type=finite_float, default=0.99,
                   metavar="F", help="target yield; the structural margin is quoted at it "
                   "(default: %(default)s)")
    s.add_argument("--proof-tolerance", type=finite_float, default=0.05, metavar="F",
                   help="outputs must sit within F of stroke of their positions, as "
                   "`mechc simulate --tolerance` (default: %(default)s)")
    s.add_argument("--json", metavar="REPORT.json", help="write the report as JSON")
    s.add_argument("--chart", metavar="CHART.png",
                   help="write the sensitivity chart (PNG)")
    s.add_argument("--cells", action="append", default=[], dest="cell_dirs", metavar="DIR",
                   help="extra directory of cell files the design was compiled with")
    s.set_defaults(func=run_command)


def settings_from(args: argparse.Namespace) -> ToleranceSettings:
    base = process(args.process) if args.process else None
    pick = lambda v, p, d: v if v is not None else (p if base is not None else d)  # noqa: E731
    s = ToleranceSettings(
        tol=pick(args.tol, base and base.tol, 0.1),
        clearance=pick(args.clearance, base and base.clearance, 0.05),
        spring_tol=pick(args.spring_tol, base and base.spring_tol, 0.1),
        samples=args.samples, seed=args.seed, proof_tolerance=args.proof_tolerance,
        yield_level=args.yield_level)
    s.check()
    return s


def run_command(args: argparse.Namespace) -> int:
    s = settings_from(args)
    if not args.design.lower().endswith(".json"):
        raise UsageError(f"{args.design}: expected a compiled design (.json); compile the spec "
                         "first with `mechc compile`")
    if args.json:
        check_output(args.json, "report", [("design", args.design)])
    if args.chart:
        check_output(args.chart, "chart", [("design", args.design), ("report", args.json)])
    design = design_from_json(load_design_json(args.design), args.design)
    lib = library_for_design(design.cell_sources, args.cell_dirs, args.design)
    bar = Progress(s.samples, f"tolerance run of {Path(args.design).name}")
    try:
        result = run(design, lib, s, lambda done, total: bar.update(done, "samples"))
    except UsageError as e:
        raise UsageError(f"{args.design}: {e}") from None
    finally:
        bar.close()
    print(summary(result, args.design))
    if args.json:
        write_atomic(args.json, dumps(to_json(result, args.design)))
    if args.chart:
        _chart(result, args.chart, Path(args.design).stem)
    return EXIT_OK if result.yield_ >= s.yield_level else EXIT_FAILED


def _chart(result, path: str, title: str) -> None:
    """The chart through a temporary file and a rename (an existing file survives a failure)."""
    # matplotlib only when a chart is asked for (start-up time of every other run)
    from mechc.tolerance.chart import sensitivity_chart
    p = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", suffix=".png", dir=p.parent or ".")
    os.close(fd)
    try:
        sensitivity_chart(result, tmp, title)
        os.chmod(tmp, 0o644)
        os.replace(tmp, p)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
