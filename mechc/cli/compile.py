"""``mechc compile``: a spec becomes a design JSON, with a summary on the terminal."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from mechc.backends.design_json import (
    check_design,
    design_bytes,
    design_from_json,
    design_to_json,
    dumps_design,
    write_atomic,
)
from mechc.cells.library import Library, load_library
from mechc.cells.sources import library_for_design
from mechc.cli.common import (
    StageProgress,
    by_type,
    check_output,
    compile_options,
    compile_path,
)
from mechc.cli.tolerance import robust_design, robust_options, wants_robust
from mechc.errors import EXIT_FAILED, EXIT_OK, UsageError
from mechc.frontends import SPEC_SUFFIXES, check_spec_path
from mechc.ir.design import Design
from mechc.proofs import ProofSettings, prove
from mechc.proofs.kinematic import EXHAUSTIVE_MAX_INPUTS
from mechc.proofs.report import failure_text, sampled_text
from mechc.ui import Progress


def register(sub) -> None:
    c = sub.add_parser("compile", help="compile a spec to a netlist JSON",
                       description="Parse SPEC (" + ", ".join(SPEC_SUFFIXES) + "), minimise "
                       "every output exactly (or synthesise a flow table), map to library cells, "
                       "place and dimension them, check the design, prove it (logic, and "
                       "kinematic where cheap) and write it as JSON. The output file is written "
                       "atomically: on any error, or a failed proof, an existing file is left "
                       "untouched. A compile that runs for more than 2 s names its stages on "
                       "stderr.")
    c.add_argument("spec", help="specification file (" + ", ".join(SPEC_SUFFIXES) + ")")
    c.add_argument("-o", "--output", help="output JSON file (default: SPEC with .json suffix); "
                   "a name ending in .gz is written gzip-compressed, and reads back as it is")
    compile_options(c)
    c.add_argument("--timings", action="store_true",
                   help="record seconds per stage in stats.seconds (the file then differs "
                   "from run to run)")
    c.add_argument("--print-netlist", action="store_true",
                   help="also print the netlist in canonical text form")
    robust_options(c)
    c.add_argument("-q", "--quiet", action="store_true",
                   help="print only the file line and the verdict (no equations, no progress); "
                   "errors and failures are still printed")
    c.add_argument("--equations", action="store_true",
                   help=f"print every equation, also for a design of more than {SHORT_OUTPUTS} "
                   "outputs or long ones (left out by default; the file always has them)")
    c.add_argument("--no-prove", action="store_true",
                   help="do not prove the design before writing it (by default compile runs the "
                   "logic proof, and the kinematic proof where it is cheap, on the design as "
                   "written, and refuses to write one its proofs reject: exit 1)")
    c.set_defaults(func=run)


#: Above this many outputs, or this many characters of equations, the summary leaves the
#: equations out (``--equations`` prints them; the design file always has them).
SHORT_OUTPUTS = 20
SHORT_CHARS = 2000

#: The kinematic proof runs at compile only for designs of at most this many cells times
#: states visited (cells x (2^n + n 2^(n-1) x 21) for n inputs); above, the summary says it was
#: skipped and how to run it. The examples are at most 1.5e4 (sevenseg.bool: 21 cells x 688
#: states); a 6-input random spec of 98 cells is 4e5 and its proof took 1.1 s; a 10-input
#: design of 1600 cells is 1.7e8 (minutes).
KINEMATIC_AT_COMPILE_MAX = 1_000_000


def run(args: argparse.Namespace) -> int:
    check_spec_path(args.spec)  # a directory or a design given as the spec: say so first
    out = args.output or str(Path(args.spec).with_suffix(".json"))
    check_output(out, "output", [("spec", args.spec)])
    stages = StageProgress("compile", enabled=not args.quiet)
    try:
        return compile_and_write(args, out, stages)
    finally:
        stages.close()


def compile_and_write(args: argparse.Namespace, out: str, stages: StageProgress) -> int:
    """Compile, check, prove, write and summarise (see ``run``)."""
    met = True
    if wants_robust(args):  # --tol/--yield: dimensions chosen by tolerance runs
        design, met = robust_design(args)
    else:
        design = compile_path(args.spec, args, stages=stages)
    for w in getattr(getattr(design, "sequential", None), "warnings", None) or []:
        print(f"warning: {w}", file=sys.stderr)
    stages.start("check file")
    t0 = time.perf_counter()
    text = dumps_design(design_to_json(design, timings=args.timings))
    obj = json.loads(text)  # what is checked and proved is what the file will hold
    try:  # the same checks simulate and draw make on reading it, before anything is written
        check_design(obj, out)
    except UsageError as e:
        raise UsageError(f"refusing to write {out}: {str(e).removeprefix(out + ': ')} (the "
                         f"options asked for more than a design can carry: --output-load "
                         f"{args.output_load:g} N, --actuator-force {args.actuator_force:g} N, "
                         f"--stroke {args.stroke:g} mm)") from None
    stages.end("check file", time.perf_counter() - t0)
    st = design.stats
    dc = st.get("design_checks", {})
    proofs = [] if args.no_prove else prove_written(obj, out, args, stages, dc)
    refused = [r for r in proofs if r.get("refuse")]
    if refused:
        if dc and not dc["passed"]:
            check_failures(dc, f"{out} is not written either")
        for r in refused:
            print(f"PROOF FAILED: {r['text']}", file=sys.stderr)
        print(f"{out} was NOT written (an existing file there is unchanged): the design fails "
              "its own proof; --no-prove writes it for inspection", file=sys.stderr)
        return EXIT_FAILED
    checks_failed = bool(dc) and not dc["passed"]
    written = rejected_path(out) if checks_failed and os.path.exists(out) else out
    stages.start("write")
    t0 = time.perf_counter()
    write_atomic(written, design_bytes(text, written))
    stages.end("write", time.perf_counter() - t0)
    print(f"{args.spec} -> {written}: {st['cells']} cells ({by_type(st['cells_by_type'])}), "
          f"{st['parts']} parts, {literals(st)}{minimality(st)}, "
          f"{stages.total():.2f} s")
    if not args.quiet:
        for line in details(design, args):
            print(f"  {line}")
        if args.print_netlist:
            print(design.netlist.to_text(), end="")
    if checks_failed:
        kept = f" ({out} is unchanged)" if written != out else ""
        check_failures(dc, f"the design was written to {written} for inspection{kept}")
        for r in proofs:
            print(f"  {r['text']}")
        return EXIT_FAILED
    verdict = []
    if dc:
        verdict.append(f"design checks: {dc['count']} passed (min transmission angle "
                       f"{dc['min_transmission_angle_deg']}°)")
    verdict += [r["text"] for r in proofs]
    for line in verdict:
        print(f"  {line}")
    summary = stages.summary()
    if summary and not args.quiet:
        print(summary, file=sys.stderr)
    return EXIT_OK if met else EXIT_FAILED


def rejected_path(out: str) -> str:
    """Where a design that fails its design checks goes when ``out`` already holds a file: next
    to it, so the user's earlier design is never replaced by one the checks reject."""
    for suffix in (".json.gz", ".json"):
        if out.endswith(suffix):
            return out[: -len(suffix)] + ".rejected" + suffix
    return out + ".rejected"


def check_failures(dc: dict, what: str) -> None:
    """The failed design checks on stderr: the first 20, and how many more."""
    print(f"DESIGN CHECKS FAILED ({len(dc['failed'])} of {dc['count']}); {what}:",
          file=sys.stderr)
    for text in dc["failed"][:20]:
        print(f"  {text}", file=sys.stderr)
    if len(dc["failed"]) > 20:
        print(f"  ... and {len(dc['failed']) - 20} more (stats.design_checks in the design)",
              file=sys.stderr)


def literals(st: dict) -> str:
    return "" if st.get("literals") is None else f"{st['literals']} literals, "


def minimality(st: dict) -> str:
    if st["minimisation"].get("skipped"):
        return f"no two-level minimise ({st['minimisation']['skipped']})"
    methods = {v["method"] for v in st["minimisation"]["outputs"].values()}
    if st["minimisation"]["proven"]:
        return "minimum proven"
    if "per-output" in methods:
        return "per-output minimum covers, shared (fewer parts than the multi-output cover)"
    if "espresso" in methods:
        return "heuristic cover (espresso-style, wide PLA): not proven minimal"
    return "minimum NOT proven (time limit or too many primes)"


def prove_written(obj: dict, out: str, args: argparse.Namespace, stages: StageProgress,
                  dc: dict) -> list[dict]:
    """The logic proof, and where it is cheap enough the kinematic proof, of the design as it
    will be written (read back from its JSON text). Each result: its summary ``text`` and
    ``refuse`` when the design must not be handed out: a wrong output anywhere, or a design
    check the proof finds failing that compile's own checks passed."""
    design = design_from_json(obj, out)
    spec = design.spec
    lib = library_for_design(design.cell_sources, args.cell_dirs, out)
    results = []
    stages.start("prove logic")
    rep = prove(design, spec, lib, "logic", ProofSettings())
    stages.end("prove logic", rep.seconds)
    results.append(proof_result(rep, dc))
    if not rep.passed:
        return results
    n = len(design.netlist.inputs)
    states = ((1 << n) + n * (1 << max(n - 1, 0)) * 21 if n <= EXHAUSTIVE_MAX_INPUTS
              else 512 * 22)  # beyond: a sample of 512 states and 512 changes of 21 points
    work = len(design.netlist.cells) * states
    if design.mechanism is None:
        return results
    if work > KINEMATIC_AT_COMPILE_MAX:
        results.append({"text": f"kinematic proof skipped at compile ({len(design.netlist.cells)}"
                        f" cells x {n} inputs is above the compile budget; run: mechc simulate "
                        f"{out} --level kinematic)"})
        return results
    bar = Progress(1, "compile: kinematic proof", enabled=not args.quiet)
    stages.start("prove kinematic")
    try:
        rep = prove(design, spec, lib, "kinematic", ProofSettings(), bar.counter("states"))
    finally:
        bar.close()
    stages.end("prove kinematic", rep.seconds)
    results.append(proof_result(rep, dc))
    return results


def proof_result(rep, dc: dict) -> dict:
    """One proof's line for the summary, and whether it refuses the design (design-check
    failures that compile's checks already reported fail compile there, file written)."""
    # an engine that counts failure kinds says so; else its listed failures (the wrong
    # positions are listed before the design checks) tell whether any output was wrong
    kinds = rep.failure_kinds or {}
    wrong = (sum(v for k, v in kinds.items() if k != "design check") if kinds
             else sum(1 for f in rep.failures if f.get("kind") != "design check"))
    checks_known = bool(dc) and not dc["passed"]
    refuse = not rep.passed and (wrong > 0 or not checks_known)
    verdict = "proved" if rep.passed else "FAILED"
    text = (f"{rep.level} proof: {verdict}, {sampled_text(rep.cases, rep.coverage)}, "
            f"{rep.failure_count} failures, {rep.seconds:.2f} s")
    text += rep.nothing_moved()
    if not rep.passed:
        text += "".join(f"\n  {failure_text(f)}" for f in rep.failures[:5])
    return {"text": text, "refuse": refuse}


def details(design: Design, args: argparse.Namespace) -> list[str]:
    """The summary's body: equations (left out for a big design unless --equations), the
    sequential notes, the interconnect, the cells used and the amplifiers."""
    st = design.stats
    lines: list[str] = []
    if st.get("names"):
        lines.append("names: " + ", ".join(f"{v} as {k}" for k, v in st["names"].items()))
    if st["minimisation"].get("time_limited"):
        lines.append("time limit ran out (best answer found used): "
                     f"{', '.join(st['minimisation']['time_limited'])}")
    eq_lines = []
    for o in design.spec.outputs:
        eq_lines.append(f"{o} = {design.equations[o]}")
        if design.implemented.get(o) and design.implemented[o] != design.equations[o]:
            eq_lines.append(f"{' ' * len(o)}   built as {design.implemented[o]}")
    size = sum(len(x) for x in eq_lines)
    outs = len(design.spec.outputs)
    if args.equations or (outs <= SHORT_OUTPUTS and size <= SHORT_CHARS):
        lines += eq_lines
    else:
        lines.append(f"equations of {outs} output(s) not shown ({size} characters): "
                     "--equations prints them; the design file has them under \"equations\"")
    se = getattr(design, "sequential", None)
    if se is not None:
        lines += merged_rows_lines(design)
        for m in se.memories:
            lines.append(f"MEMORY {m}: set = {se.text(se.set_names[m])}, reset = "
                         f"{se.text(se.reset_names[m])}, initial {se.initial[m]}")
        if se.checked.get("sr_overlap_total_states"):
            lines.append(f"note: SET and RESET of a memory are both on in "
                         f"{se.checked['sr_overlap_total_states']} total state(s) that the spec "
                         "never reaches (every reachable one was checked)")
        for h in se.essential_hazards:
            lines.append(f"essential hazard: state {h['state']}, {h['input']} {h['from']} -> "
                         f"{h['to']}: {h['requires']}")
        lines += ordering_lines(st.get("sequential", {}).get("ordering"))
    if st.get("levels"):
        lines.append(levels_line(st["levels"]))
    if "planes" in st:
        lines.append(f"interconnect: {st['rods']} rods, {st['rod_length_mm']:g} mm of rod, "
                     f"{st['bends']} bends, {st['planes']['count']} planes "
                     f"({plane_list(st['planes']['used'])})")
    lines += cells_used(design, load_library(args.cell_dirs))
    amps = list(st.get("amplified", {}).items())
    for net, why in amps[:SHORT_OUTPUTS]:
        lines.append(f"AMPLIFIER on {net}: {why}")
    if len(amps) > SHORT_OUTPUTS:
        lines.append(f"... and {len(amps) - SHORT_OUTPUTS} more amplified nets "
                     "(stats.amplified in the design file)")
    return lines


def levels_line(lv: dict) -> str:
    """Which logic depth was built and what each cost: 'levels: multi-level chosen (476 parts;
    two-level 1876)'; a two-level design not assembled shows its lower bound, '>= 1210'."""
    names = {"2": "two-level", "multi": "multi-level"}
    bound = ">= " if lv.get("two_level", "assembled") != "assembled" else ""
    others = "; ".join(f"{names[k]} {bound if k == '2' else ''}{v}"
                       for k, v in lv["parts"].items() if k != lv["chosen"])
    line = (f"levels: {names[lv['chosen']]} {'chosen' if lv['asked'] == 'auto' else 'asked'} "
            f"({lv['parts'][lv['chosen']]} parts{'; ' + others if others else ''})")
    multi = lv.get("multi", {})
    if lv["chosen"] == "multi" and multi.get("two_level_outputs"):
        line += ("; built two-level for a static hazard: "
                 + ", ".join(multi["two_level_outputs"]))
    if lv["chosen"] == "multi" and multi.get("cured_outputs"):
        line += "; static hazards cured by cubes: " + ", ".join(multi["cured_outputs"])
    if multi.get("failed"):
        line += f"; multi-level failed: {multi['failed']}"
    return line


def plane_list(used: list[int]) -> str:
    """'0, 1, 3' or, for a contiguous run of more than five, '0-105'."""
    if len(used) > 5 and used == list(range(used[0], used[-1] + 1)):
        return f"{used[0]}-{used[-1]}"
    return ", ".join(map(str, used))


def merged_rows_lines(design: Design) -> list[str]:
    """A flow table whose rows the reduction merged says so: 'flow table: 10 states -> 3 rows
    (merged: a+b+c, ...)', so a machine that collapsed is never silent (KISS2's chained
    transitions, equivalent states)."""
    se = design.sequential
    table = getattr(design.spec, "table", None)
    classes = getattr(se, "classes", None)
    if se.form != "table" or table is None or not classes or len(classes) >= len(table.rows):
        return []
    states = {r.split("@")[0] for r in table.rows}
    rows = (f"{len(table.rows)} flow-table rows" if len(table.rows) != len(states) else "")
    merged = [c for c in classes if len(c) > 1]
    shown = ", ".join("+".join(c) for c in merged[:8]) + (" ..." if len(merged) > 8 else "")
    gone = (getattr(se, "cover", None) or {}).get("unreachable_rows")
    shown = "; ".join(p for p in (f"merged: {shown}" if merged else "",
                                  f"unreachable, not built: {', '.join(gone)}" if gone else "")
                      if p)
    return [f"flow table: {len(states)} states{f' ({rows})' if rows else ''} -> "
            f"{len(classes)} row{'s' if len(classes) > 1 else ''} ({shown})"]


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
