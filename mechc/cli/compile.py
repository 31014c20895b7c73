"""``mechc compile``: a spec becomes a design JSON, with a summary on the terminal."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from mechc.backends.design_json import (
    check_design,
    design_to_json,
    dumps,
    write_atomic,
)
from mechc.cells.library import Library, load_library
from mechc.cli.common import by_type, check_output, compile_options, compile_path
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.frontends import SPEC_SUFFIXES
from mechc.ir.design import Design


def register(sub) -> None:
    c = sub.add_parser("compile", help="compile a spec to a netlist JSON",
                       description="Parse SPEC (" + ", ".join(SPEC_SUFFIXES) + "), minimise "
                       "every output exactly (or synthesise a flow table), map to library cells, "
                       "place and dimension them, check the design, and write it as JSON. The "
                       "output file is written atomically: on any error an existing file is "
                       "left untouched.")
    c.add_argument("spec", help="specification file (" + ", ".join(SPEC_SUFFIXES) + ")")
    c.add_argument("-o", "--output", help="output JSON file (default: SPEC with .json suffix)")
    compile_options(c)
    c.add_argument("--timings", action="store_true",
                   help="record seconds per stage in stats.seconds (the file then differs "
                   "from run to run)")
    c.add_argument("--print-netlist", action="store_true",
                   help="also print the netlist in canonical text form")
    c.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    out = args.output or str(Path(args.spec).with_suffix(".json"))
    check_output(out, "output", [("spec", args.spec)])
    t0 = time.perf_counter()
    design = compile_path(args.spec, args)
    obj = design_to_json(design, timings=args.timings)
    try:  # the same checks simulate and draw make on reading it, before anything is written
        check_design(obj, out)
    except UsageError as e:
        raise UsageError(f"refusing to write {out}: {str(e).removeprefix(out + ': ')} (the "
                         f"options asked for more than a design can carry: --output-load "
                         f"{args.output_load:g} N, --actuator-force {args.actuator_force:g} N, "
                         f"--stroke {args.stroke:g} mm)") from None
    write_atomic(out, dumps(obj))
    st = design.stats
    methods = {v["method"] for v in st["minimisation"]["outputs"].values()}
    if st["minimisation"]["proven"]:
        how = "minimum proven"
    elif "per-output" in methods:
        how = "per-output minimum covers, shared (fewer parts than the multi-output cover)"
    elif "espresso" in methods:
        how = "heuristic cover (espresso-style, wide PLA): not proven minimal"
    else:
        how = "minimum NOT proven (time limit or too many primes)"
    print(f"{args.spec} -> {out}: {st['cells']} cells ({by_type(st['cells_by_type'])}), "
          f"{st['parts']} parts, {st['literals']} literals, {how}, "
          f"{time.perf_counter() - t0:.2f} s")
    if st.get("names"):
        print("  names: " + ", ".join(f"{v} as {k}" for k, v in st["names"].items()))
    if st["minimisation"].get("time_limited"):
        print(f"  time limit ran out (best answer found used): "
              f"{', '.join(st['minimisation']['time_limited'])}")
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
        for line in ordering_lines(st.get("sequential", {}).get("ordering")):
            print(f"  {line}")
    if "planes" in st:
        print(f"  interconnect: {st['rods']} rods, {st['rod_length_mm']:g} mm of rod, "
              f"{st['bends']} bends, {st['planes']['count']} planes "
              f"({', '.join(map(str, st['planes']['used']))})")
    for line in cells_used(design, load_library(args.cell_dirs)):
        print(f"  {line}")
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


def cells_used(design: Design, lib: Library) -> list[str]:
    """Which library cell realises each logic type, and every user cell the mapper chose (with
    its file, and the standard cells it stands in for), so a user cell never replaces a
    standard one unannounced."""
    names: dict[str, set[str]] = {}
    for c in design.netlist.cells.values():
        names.setdefault(c.type, set()).add(c.cell)
    lines = ["cells used: " + ", ".join(f"{t} {'/'.join(sorted(n))}"
                                        for t, n in sorted(names.items()))]
    for name in sorted(set().union(*names.values()) if names else ()):
        cls = lib[name]
        if cls.standard:
            continue
        std = [s for s in lib.standard_cells(cls.type) if s != name]
        lines.append(f"user cell {name} ({cls.source}) for {cls.type}"
                     + (f", instead of the standard {', '.join(std)}" if std else ""))
    return lines


def ordering_lines(ordering: dict | None) -> list[str]:
    """The ordering requirements as decided at compile: each with its timing inequality and
    the verdict of the dynamic walk over its transitions, and the cure built in."""
    if not ordering:
        return []
    reqs = ordering["requirements"]
    out = [f"ordering requirements ({len(reqs)}; each decided by a dynamic walk of its "
           f"transitions, margin {ordering['margin_s']} s):"] if reqs else []
    for r in reqs:
        verdict = (f"dynamic walk ({r['dynamic_steps']} step(s)): "
                   + ("met" if r["met"] else f"NOT MET ({r['dynamic_failures']} failure(s), "
                                             f"first: {r['first_failure']})"))
        more = len(r["transitions"]) - 1
        out.append(f"  {r['kind']}: {r['requires']} [{r['transitions'][0]}"
                   f"{f' and {more} more' if more else ''}]")
        out.append(f"    inequality: {r['timing']['text']}; {verdict}")
    cure = ordering.get("cure") or {}
    if cure:
        chain = ", ".join(f"{n} x{k}" for n, k in cure["feedback_delay_on"].items())
        out.append(f"feedback delay {'built in' if cure['kept'] else 'tried, not kept'}: "
                   f"{cure['cell']} chain ({cure['delay_per_cell_s']} s each) on {chain}; "
                   f"failing steps {cure['failing_steps_before']} -> "
                   f"{cure['failing_steps_after']}")
    return out
