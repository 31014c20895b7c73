"""``mechc tolerance``: the yield of a design when it is made (tolerances, pin clearance,
spring error), which dimensions matter, and each output's structural error."""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from mechc.backends.design_json import (
    design_from_json,
    dumps,
    load_design_json,
    write_atomic,
)
from mechc.cells.library import load_library
from mechc.cells.sources import library_for_design
from mechc.cli.common import check_output, options_from_args
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.frontends import load_spec
from mechc.tolerance.montecarlo import ToleranceSettings, run
from mechc.tolerance.process import PROCESSES, process
from mechc.tolerance.report import summary, to_json
from mechc.tolerance.robust import robust_compile
from mechc.ui import Progress, finite_float, int_at_least, table


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
structural error (scatter of its rest positions against the stroke), the pairs of parts the
interference bound says may touch (not counted in the yield) and the dimensions that matter
most (finite differences of the closed forms; regression of the samples' margin).

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
    if not args.design.lower().endswith((".json", ".json.gz")):
        raise UsageError(f"{args.design}: expected a compiled design (.json or .json.gz); "
                         "compile the spec first with `mechc compile`")
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


# ---- mechc compile --tol MM --yield F -----------------------------------------------------

def robust_options(c: argparse.ArgumentParser) -> None:
    """``mechc compile``'s options for robust design (this module keeps them with the
    tolerance command's)."""
    g = c.add_argument_group(
        "robust design",
        "with --tol or --process, compile, measure the yield by a tolerance run and change "
        "spring margins, over-travel stops and the stroke until it reaches --yield; the rounds "
        "and what changed are printed (exit 1 if the yield is not reached)")
    g.add_argument("--tol", type=finite_float, default=None, metavar="MM",
                   help="every dimension +-MM: design for it")
    g.add_argument("--process", choices=list(PROCESSES), default=None,
                   help="design for a process's tolerances (see mechc tolerance --help)")
    g.add_argument("--yield", dest="yield_level", type=finite_float, default=0.99,
                   metavar="F", help="target yield (default: %(default)s)")
    g.add_argument("--pin-clearance", type=finite_float, default=None, metavar="MM",
                   help="diametral play of every pin (default 0.05, or the process's)")
    g.add_argument("--spring-tol", type=finite_float, default=None, metavar="FRACTION",
                   help="springs' rate and preload +-FRACTION (default 0.1)")
    g.add_argument("--tol-samples", type=int_at_least(100), default=2000, metavar="N",
                   help="Monte Carlo samples per round (default: %(default)s)")


def wants_robust(args: argparse.Namespace) -> bool:
    return args.tol is not None or args.process is not None


def robust_design(args: argparse.Namespace):
    """The design ``mechc compile --tol`` writes, and whether it met the yield; prints the
    rounds."""
    base = process(args.process) if args.process else None
    pick = lambda v, p, d: v if v is not None else (p if base is not None else d)  # noqa: E731
    s = ToleranceSettings(tol=pick(args.tol, base and base.tol, 0.1),
                          clearance=pick(args.pin_clearance, base and base.clearance, 0.05),
                          spring_tol=pick(args.spring_tol, base and base.spring_tol, 0.1),
                          samples=args.tol_samples, yield_level=args.yield_level)
    s.check()
    spec = load_spec(args.spec)
    opts = options_from_args(args)
    lib = load_library(opts.cell_dirs)
    design, rounds, met = robust_compile(spec, opts, lib, s,
                                         lambda line: print(f"  tolerance round: {line}",
                                                            file=sys.stderr))
    rows = [(i + 1, f"{r.stroke:g}", f"{r.spring_margin:.3g}", f"{r.overtravel:.0%}",
             f"{r.angle_margin:g}", f"{r.result.yield_:.2%}",
             f"[{r.result.ci[0]:.2%}, {r.result.ci[1]:.2%}]",
             r.result.failing[0].key.name + " at " + r.result.failing[0].key.where
             if r.result.failing else "none") for i, r in enumerate(rounds)]
    print(f"robust design for +-{s.tol} mm, pin clearance {s.clearance} mm, springs "
          f"+-{s.spring_tol:.0%}, target yield {s.yield_level:.2%} ({s.samples} samples a "
          "round):")
    print(table(rows, ["round", "stroke mm", "spring margin", "over-travel",
                       "angle margin deg", "yield",
                       "95 % interval", "most frequent failure"]))
    for i, r in enumerate(rounds):
        if r.change:
            print(f"  after round {i + 1}: {r.change}")
    last = rounds[-1]
    if met:
        print(f"  target met: stroke {last.stroke:g} mm, spring margin {last.spring_margin:.3g}"
              f", over-travel {last.overtravel:.0%} of stroke, angle margin "
              f"{last.angle_margin:g} deg")
    else:
        f = last.result.failing[0] if last.result.failing else None
        print(f"  TARGET NOT MET: yield {last.result.yield_:.2%}"
              + (f"; {f.key.name} at {f.key.where} fails in {f.count} samples (worst "
                 f"{f.worst:.4g}{f.key.unit}), which this loop does not change" if f else ""),
              file=sys.stderr)
    return design, met
