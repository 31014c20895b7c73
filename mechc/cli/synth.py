"""``mechc synth three-bar | dyad | triad | adder``: dimensional synthesis from the command line.

Exit status (as for the rest of mechc): 0 a design/solution was found, 1 none exists or the
design fails its checks (the --json answer is still printed, with the reason), 2 bad input.
"""

from __future__ import annotations

import argparse
import json
import math
import textwrap
from dataclasses import replace

import numpy as np

from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.linkage_synthesis import three_bar_gate as tb
from mechc.linkage_synthesis.adders import LongBarAdder, bar_shortening, long_bar_adder
from mechc.linkage_synthesis.defects import check_dyads
from mechc.linkage_synthesis.examples import EXAMPLES
from mechc.linkage_synthesis.mk_circles import ANGLE_NAMES, SynthesisError, solve_chain
from mechc.linkage_synthesis.positions import load_positions
from mechc.ui import finite_float, int_at_least

SYNTH_DESCRIPTION = """\
Dimensional synthesis: find link lengths and pivots.

  mechc synth three-bar --sep 50 --stroke 40 --output 70    3-bar AND/OR gate lengths
  mechc synth dyad fig4.pos --free beta2=-110               M/K-circle dyad, 3-5 positions
  mechc synth triad --example figA5                         M/K/T-circle triad, 4-7 positions
  mechc synth adder --weights 1,2 --lever 60 --bars 300,300 --range1 0:20 --range2 0:20

Every subcommand takes --json (machine-readable answer on stdout) and --plot FILE (.png, .svg,
.pdf).  Exit status: 0 found, 1 no healthy design / no solution (the answer says why), 2 bad
input.  The positions file format is described in 'mechc synth dyad --help'.
"""

POSITIONS_HELP = """\
Positions file: a header naming the columns, then one line per position ('#' comments):

  x     y     alpha   beta          (a triad adds gamma)
  0     0     0       0
  1.75  1     -50     -110
  3.5   2     -90     ?
  5.5   1     -110    ?

Angles are rotations from position 1 in degrees: beta of the first link W, alpha of the second
link Z, gamma of the third link V.  '?' marks unknowns; only one angle column (the free link)
may have them; its given values after position 1 are the free choices, and unknown ones the
program solves or searches for.  'free beta' on a line of its own names the free link when no
column has unknowns.  Worked examples of Mather & Erdman (2023) are built in: --example NAME.
"""


def register(sub) -> None:
    p = sub.add_parser("synth", help="dimensional synthesis (3-bar gate, dyads, triads, adders)",
                       description=SYNTH_DESCRIPTION,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    ss = p.add_subparsers(title="synthesis problems", metavar="PROBLEM")
    p.set_defaults(func=lambda args: (p.print_help(), EXIT_OK)[1])

    t = ss.add_parser("three-bar", help="lengths of the 3-bar AND/OR gate",
                      formatter_class=argparse.RawDescriptionHelpFormatter,
                      description=_wrap("Input links from inputs at (0, +sep) and (0, -sep), each "
                      "sliding STROKE to the right, meet at a middle joint; an output link runs "
                      "to an output slider on the x axis.  Finds input and output link lengths "
                      "so that FF, FT and TF leave the output at the same place (an AND gate; "
                      "reversed, an OR gate) on the assembly branch reached from FF, and checks "
                      "the result independently: transmission angles in every state and along "
                      "every input motion, distance to in-line (toggle) configurations, link "
                      "ratio.  A design that fails a check is never reported as healthy; then "
                      "the nearest healthy designs are listed (same sep and stroke with another "
                      "output position; same output with another sep or stroke).",
                      "Exit status 0: healthy design; 1: no healthy design for these numbers."))
    t.add_argument("--sep", type=_positive, required=True, metavar="MM",
                   help="half the distance between the input slides")
    t.add_argument("--stroke", type=_positive, required=True, metavar="MM",
                   help="input travel from false to true")
    t.add_argument("--output", type=finite_float, metavar="MM",
                   help="output joint position (x) in state FF; omitted: the design with the "
                   "largest margin on the checks")
    t.add_argument("--min-angle", type=_angle, default=45.0, metavar="DEG",
                   help="least transmission angle allowed (default: %(default)s)")
    t.add_argument("--min-link-ratio", type=_fraction, default=1 / 3, metavar="R",
                   help="shortest/longest link allowed (default: 1/3; 0 turns the check off)")
    t.add_argument("--max-wander", type=_positive, metavar="PCT",
                   help="also require the output to stay within PCT %% of stroke of its rest "
                   "position during FF-FT and FF-TF (not required by default; reported always)")
    t.add_argument("--no-alternatives", action="store_true",
                   help="skip the search for nearby healthy designs")
    _common(t)
    t.set_defaults(func=cmd_three_bar)

    for kind in ("dyad", "triad"):
        d = ss.add_parser(kind, help=f"M/K{'/T' if kind == 'triad' else ''}-circle "
                          f"{kind} synthesis for {'3-5' if kind == 'dyad' else '4-7'} positions",
                          formatter_class=argparse.RawDescriptionHelpFormatter,
                          description=_wrap(f"Precision-position synthesis of a {kind} (Mather & "
                          "Erdman 2023): standard-form equations, circles of pivots from the "
                          "free choices, circle intersections, and a search for free choices "
                          "that make three circles concurrent.  Every solution is polished on "
                          "the full equations and printed with its residual.") + "\n\n"
                          + POSITIONS_HELP)
        d.add_argument("positions", nargs="?", metavar="POSITIONS",
                       help="positions file (see above)")
        d.add_argument("--example", metavar="NAME",
                       help="a worked example of the paper instead of a file: "
                       + ", ".join(_example_names(kind)))
        d.add_argument("--free", action="append", default=[], metavar="NAMEj=DEG",
                       help="set a free choice, e.g. beta2=-110 (repeatable)")
        d.add_argument("--grid", type=int_at_least(36), default=1440, metavar="N",
                       help="samples per searched angle (default: %(default)s)")
        if kind == "dyad":
            d.add_argument("--defects", action="store_true",
                           help="assemble every pair of solutions into a four-bar and check "
                           "it for circuit and branch defects")
        _common(d)
        d.set_defaults(func=cmd_chain, kind=kind)

    a = ss.add_parser("adder", help="structural error of a long-bar linkage adder",
                      formatter_class=argparse.RawDescriptionHelpFormatter,
                      description=_wrap("The approximate (long-bar) adder of Fig. 2-15 in the "
                      "linkage computer text: a lever with pins at weights W1:W2 along it, pulled "
                      "by bars of lengths L1, L2 from the input slides; the output pin on its own "
                      "slide "
                      "gives X3 ~ (W1 X1 + W2 X2)/(W1 + W2).  Reports the structural error over "
                      "the input ranges (exact loop closure, eqs. 14-15) and the book's "
                      "small-angle bound."))
    a.add_argument("--weights", type=_pair, required=True, metavar="W1,W2",
                   help="positive weights of the two inputs")
    a.add_argument("--lever", type=_positive, required=True, metavar="MM",
                   help="distance between the two input pins of the lever")
    a.add_argument("--bars", type=_pair, required=True, metavar="L1,L2",
                   help="bar lengths")
    a.add_argument("--range1", type=_range, required=True, metavar="LO:HI",
                   help="travel of input 1")
    a.add_argument("--range2", type=_range, required=True, metavar="LO:HI",
                   help="travel of input 2")
    a.add_argument("--samples", type=int_at_least(2), default=41, metavar="N",
                   help="samples per input (default: %(default)s)")
    _common(a)
    a.set_defaults(func=cmd_adder)


def _wrap(*paragraphs: str) -> str:
    return "\n\n".join(textwrap.fill(p, 78) for p in paragraphs)


def _common(p) -> None:
    p.add_argument("--json", action="store_true", help="print the answer as JSON")
    p.add_argument("--plot", metavar="FILE", help="draw the answer to FILE (.png, .svg, .pdf)")


# --- argument types ----------------------------------------------------------------------------


def _positive(text: str) -> float:
    v = finite_float(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text}")
    return v


def _angle(text: str) -> float:
    v = finite_float(text)
    if not 0 < v <= 90:
        raise argparse.ArgumentTypeError(f"a transmission angle lies in (0, 90], got {text}")
    return v


def _fraction(text: str) -> float:
    v = finite_float(text)
    if not 0 <= v <= 1:
        raise argparse.ArgumentTypeError(f"expected a ratio in [0, 1], got {text}")
    return v


def _pair(text: str) -> tuple[float, float]:
    parts = text.split(",")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected two numbers 'A,B', got '{text}'")
    a, b = (_positive(x) for x in parts)
    return a, b


def _range(text: str) -> tuple[float, float]:
    parts = text.split(":")
    if len(parts) != 2:
        raise argparse.ArgumentTypeError(f"expected 'LO:HI', got '{text}'")
    lo, hi = (finite_float(x) for x in parts)
    if not hi > lo:
        raise argparse.ArgumentTypeError(f"expected LO < HI, got '{text}'")
    return lo, hi


def _example_names(kind: str) -> list[str]:
    k = 2 if kind == "dyad" else 3
    return [n for n, e in EXAMPLES.items() if e.problem.k == k]


def _print_json(obj) -> None:
    print(json.dumps(_jsonable(obj), indent=2, allow_nan=False))


def _jsonable(o):
    """Replace non-finite floats by None (JSON has no NaN/Infinity) and numpy scalars."""
    if isinstance(o, dict):
        return {k: _jsonable(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_jsonable(v) for v in o]
    if isinstance(o, (np.floating, float)):
        return float(o) if math.isfinite(o) else None
    if isinstance(o, np.integer):
        return int(o)
    if isinstance(o, np.bool_):
        return bool(o)
    return o


# --- three-bar ---------------------------------------------------------------------------------


def cmd_three_bar(args) -> int:
    cr = tb.Criteria(args.min_angle, args.min_link_ratio, args.max_wander)
    ans = tb.synthesise(args.sep, args.stroke, args.output, cr,
                        alternatives=not args.no_alternatives)
    out = ans.to_json()
    out["request"] = {"sep": args.sep, "stroke": args.stroke, "output": args.output}
    if args.plot:
        # matplotlib loads only when a plot is asked for (start-up time)
        from mechc.linkage_synthesis.plots import plot_three_bar

        seps = np.geomspace(args.sep / 4, args.sep * 4, 25)
        chart = tb.feasible_chart(args.stroke, seps, cr)
        out["chart"] = chart
        plot_three_bar(ans, args.plot, chart, (args.sep, args.output))
    if args.json:
        _print_json(out)
    else:
        _print_three_bar(ans, args)
    return EXIT_OK if ans.healthy else EXIT_FAILED


def _print_three_bar(ans, args) -> None:
    r = ans.report
    d = ans.design
    if ans.healthy:
        print(f"healthy 3-bar gate: input links {d.input_link:.4f}, output link "
              f"{d.output_link:.4f}, output at {d.output_position:.4f} (FF)")
    else:
        print("NO healthy design for the requested numbers.")
        print(f"  reason: {ans.reason}")
    if r is not None:
        print(f"  min transmission angle {r.min_transmission_angle:.2f} deg, gate error "
              f"{r.gate_error:.3g}, singular clearance {r.singular_clearance:.3g}, link ratio "
              f"{r.link_ratio:.3f}, output wander {r.wander:.2f} % of stroke")
    for w in ans.warnings:
        print(f"  warning: {w}")
    for iv in ans.feasible:
        lo, hi = sorted(iv["output"])
        print(f"  healthy output positions for sep {args.sep:g}, stroke {args.stroke:g}: "
              f"{lo:.3f} .. {hi:.3f}")
    for a in ans.alternatives:
        print(f"  alternative ({a['note']}): sep {a['sep']:.4g}, stroke {a['stroke']:.4g}, "
              f"input links {a['input_link']:.4f}, output link {a['output_link']:.4f}, output "
              f"at {a['output_position']:.4f}, min angle {a['min_transmission_angle_deg']:.1f}")
    if args.plot:
        print(f"  plot: {args.plot}")


# --- dyad / triad ------------------------------------------------------------------------------


def _problem(args):
    if args.example and args.positions:
        raise UsageError("give a positions file or --example, not both")
    if args.example:
        if args.example not in EXAMPLES:
            raise UsageError(f"unknown example '{args.example}' (known: "
                             f"{', '.join(_example_names(args.kind))})")
        pr = EXAMPLES[args.example].problem
    elif args.positions:
        pr = load_positions(args.positions)
    else:
        raise UsageError(f"mechc synth {args.kind}: give a positions file or --example NAME")
    want = 2 if args.kind == "dyad" else 3
    if pr.k != want:
        raise UsageError(f"the positions describe a {'dyad' if pr.k == 2 else 'triad'} "
                         f"(angle columns), but this is 'mechc synth {args.kind}'")
    return _apply_free(pr, args.free)


def _apply_free(pr, items: list[str]):
    if not items:
        return pr
    ang = pr.angles.copy()
    name = ANGLE_NAMES[pr.free_link]
    for it in items:
        key, sep, val = it.partition("=")
        key = key.strip().lower()
        if not sep or not key.startswith(name) or not key[len(name):].isdigit():
            raise UsageError(f"--free {it}: expected {name}J=DEG (the free link here is {name})")
        j = int(key[len(name):]) - 1
        if not 1 <= j < pr.n:
            raise UsageError(f"--free {it}: position {j + 1} is not one of 2..{pr.n}")
        try:
            v = float(val)
        except ValueError:
            raise UsageError(f"--free {it}: '{val}' is not a number of degrees") from None
        ang[pr.free_link, j] = np.radians(v)
    return replace(pr, angles=ang)


def cmd_chain(args) -> int:
    pr = _problem(args)
    try:
        res = solve_chain(pr, grid=args.grid)
    except SynthesisError as e:
        raise UsageError(str(e)) from None
    out = {
        "kind": args.kind, "positions": pr.n, "mode": res.mode, "message": res.message,
        "free_link": ["beta", "alpha", "gamma"][pr.free_link],
        "solutions": [s.to_json() for s in res.solutions],
        "rejected_roots": res.rejected,
        "circles": [{"position": pc.position + 1,
                     **{n: (None if c is None else {"centre": [c.centre.real, c.centre.imag],
                                                    "radius": c.radius})
                        for n, c in pc.circles.items()}} for pc in res.circles],
    }
    if res.family:
        out["family"] = [s.to_json() for s in res.family]
    if args.kind == "dyad" and getattr(args, "defects", False):

        out["fourbars"] = [
            {"dyads": [i + 1, j + 1], "defects": check_dyads(res.solutions[i],
                                                             res.solutions[j]).to_json()}
            for i in range(len(res.solutions)) for j in range(len(res.solutions)) if i != j]
    if args.plot:
        # matplotlib loads only when a plot is asked for (start-up time)
        from mechc.linkage_synthesis.plots import plot_chain

        plot_chain(res, args.plot)
    if args.json:
        _print_json(out)
    else:
        _print_chain(res, out, args)
    found = bool(res.solutions) or res.mode == "circle" or bool(res.family)
    return EXIT_OK if found else EXIT_FAILED


def _print_chain(res, out, args) -> None:
    print(f"{args.kind}, {res.problem.n} positions ({res.mode}): {res.message}")
    for i, s in enumerate(res.solutions, start=1):
        links = "  ".join(f"{n} = {L.real:.6f}{L.imag:+.6f}i" for n, L in
                          zip(("W", "Z", "V"), s.links))
        g = s.ground
        extra = "".join(f"  {k} = {v:.6f} deg" for k, v in s.searched.items())
        print(f"  {i}: {links}  ground ({g.real:.6f}, {g.imag:.6f})  residual "
              f"{s.residual:.1e}{extra}")
    for pc in res.circles:
        for n, c in pc.circles.items():
            if c is not None:
                print(f"  {n} circle for position {pc.position + 1}: centre "
                      f"({c.centre.real:.6f}, {c.centre.imag:.6f}), radius {c.radius:.6f}")
    if res.rejected:
        print(f"  {res.rejected} root(s) discarded: residual above 1e-9 after polishing")
    for fb in out.get("fourbars", []):
        d = fb["defects"]
        state = "no defect" if d["ok"] else "; ".join(d["messages"])
        print(f"  four-bar input dyad {fb['dyads'][0]} + dyad {fb['dyads'][1]}: {state}")
    if args.plot:
        print(f"  plot: {args.plot}")


# --- adder -------------------------------------------------------------------------------------


def cmd_adder(args) -> int:
    w1, w2 = args.weights
    lever = args.lever
    wsum = w1 + w2
    ad = LongBarAdder(r1=lever * w2 / wsum, r2=-lever * w1 / wsum, l1=args.bars[0],
                      l2=args.bars[1])
    x1 = np.linspace(*args.range1, args.samples)
    x2 = np.linspace(*args.range2, args.samples)
    X1, X2 = np.meshgrid(x1, x2)
    st = long_bar_adder(ad, X1, X2)
    if not st.ok.all():
        bad = np.argwhere(~st.ok)[0]
        raise UsageError(f"the adder cannot be assembled at X1 = {X1[tuple(bad)]:.4g}, "
                         f"X2 = {X2[tuple(bad)]:.4g} (bars too short for the lever tilt)")
    err = st.error
    k = np.unravel_index(np.argmax(np.abs(err)), err.shape)
    out_range = float(np.ptp(ad.weights[0] * X1 + ad.weights[1] * X2))
    theta_max = float(max(np.max(np.abs(st.theta1)), np.max(np.abs(st.theta2))))
    bound = float(ad.weights[0] * bar_shortening(ad.l1, theta_max)
                  + ad.weights[1] * bar_shortening(ad.l2, theta_max))
    res = {
        "weights": [ad.weights[0], ad.weights[1]], "lever_pins": [ad.r1, ad.r2],
        "bars": [ad.l1, ad.l2],
        "max_abs_error": float(np.abs(err[k])), "at": [float(X1[k]), float(X2[k])],
        "error_pct_of_output_range": float(abs(err[k]) / out_range * 100) if out_range else None,
        "max_bar_angle_deg": float(np.degrees(theta_max)),
        "bound_eq15": bound,
    }
    if args.plot:
        # matplotlib loads only when a plot is asked for (start-up time)
        from mechc.linkage_synthesis.plots import plot_adder

        plot_adder(X1, X2, err, args.plot)
    if args.json:
        _print_json(res)
    else:
        print(f"long-bar adder X3 ~ {ad.weights[0]:.4g} X1 + {ad.weights[1]:.4g} X2: max "
              f"structural error {res['max_abs_error']:.4g} at X1 = {res['at'][0]:.4g}, X2 = "
              f"{res['at'][1]:.4g}")
        if res["error_pct_of_output_range"] is not None:
            print(f"  = {res['error_pct_of_output_range']:.4f} % of the output range; bars tilt "
                  f"at most {res['max_bar_angle_deg']:.3f} deg (eq. 15 bound {bound:.4g})")
    return EXIT_OK

