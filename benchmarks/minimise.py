"""Two-level minimisation: mechc's default engine against sympy's SOPform (issue 2).

    python benchmarks/minimise.py [--sizes 6 8 10 12] [--functions 3] [--cap 120]
    python benchmarks/minimise.py --mcnc DIR

Random single-output functions, seeded: each of the 2**n rows is off with probability 0.5, on
with 0.4 and don't-care with 0.1. For each, ``mechc.passes.minimise.minimise`` runs twice: with
its default options (which also minimise the complement and look for XOR forms, for the
mapper) and with ``complements=False`` (the sum of products alone, what SOPform computes). Both
are timed in this process; SOPform (same minterms and don't-cares) runs in a forked child with
a wall-clock cap and is reported as skipped past it. Ratios are SOPform seconds over mechc
seconds for the same function, summarised by their geometric mean. Literal counts are compared
on the functions where SOPform finished, and SOPform's answer is checked on every care row.

``--mcnc DIR`` compiles every .pla in DIR (MCNC benchmark PLAs, not shipped with mechc) through
minimise, map and place (``--full``: every stage of ``compile_spec``), checks the netlist with
the logic-level proof (exhaustive up to 20 inputs, sampled beyond), and prints inputs, outputs,
terms (summed over outputs), literals, cells and seconds per file, or the stage that failed.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing as mp
import sys
import time
from pathlib import Path

import numpy as np

from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import Cube
from mechc.passes.minimise import MinimiseOptions, minimise

P_OFF, P_ON, P_DC = 0.5, 0.4, 0.1


def random_table(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.choice([0, 1, 2], size=1 << n, p=[P_OFF, P_ON, P_DC]).astype(np.int8)


def table_spec(table: np.ndarray, n: int) -> Spec:
    f = OutputSpec("f", on=[Cube.minterm(int(m), n) for m in np.flatnonzero(table == 1)],
                   dc=[Cube.minterm(int(m), n) for m in np.flatnonzero(table == 2)])
    return Spec("random", "bool", [f"x{k}" for k in range(n)], ["f"], {"f": f})


def run_mechc(table: np.ndarray, n: int, complements: bool) -> dict:
    spec = table_spec(table, n)
    t0 = time.perf_counter()
    eq = minimise(spec, MinimiseOptions(complements=complements))
    seconds = time.perf_counter() - t0
    c = eq.covers["f"]
    return {"terms": c.terms, "literals": c.literals, "seconds": seconds, "proven": c.proven}


def _sopform_child(table: np.ndarray, n: int, conn) -> None:
    from sympy import symbols
    from sympy.logic import SOPform

    xs = symbols(f"x0:{n}")
    t0 = time.perf_counter()
    expr = SOPform(list(xs), np.flatnonzero(table == 1).tolist(),
                   np.flatnonzero(table == 2).tolist())
    seconds = time.perf_counter() - t0
    terms = _sop_terms(expr, xs)
    conn.send({"seconds": seconds, "terms": len(terms),
               "literals": sum(len(t) for t in terms), "cubes": terms})


def _sop_terms(expr, xs) -> list[list[tuple[int, bool]]]:
    """SOPform's answer as terms of (input index, positive?)."""
    from sympy import And, Not, Or
    from sympy.logic.boolalg import BooleanFalse, BooleanTrue

    index = {x: k for k, x in enumerate(xs)}
    if isinstance(expr, BooleanFalse):
        return []
    if isinstance(expr, BooleanTrue):
        return [[]]
    out = []
    for term in (expr.args if isinstance(expr, Or) else (expr,)):
        lits = term.args if isinstance(term, And) else (term,)
        out.append([(index[lit.args[0]], False) if isinstance(lit, Not) else (index[lit], True)
                    for lit in lits])
    return out


def run_sopform(table: np.ndarray, n: int, cap: float) -> dict | None:
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_sopform_child, args=(table, n, child))
    proc.start()
    child.close()
    result = parent.recv() if parent.poll(cap) else None
    if proc.is_alive():
        proc.terminate()
    proc.join()
    return result


def sop_agrees(terms, table: np.ndarray, n: int) -> bool:
    rows = np.arange(1 << n, dtype=np.int64)
    got = np.zeros(len(rows), dtype=bool)
    for term in terms:
        hit = np.ones(len(rows), dtype=bool)
        for k, pos in term:
            hit &= ((rows >> (n - 1 - k)) & 1).astype(bool) == pos
        got |= hit
    care = table != 2
    return bool((got[care] == (table[care] == 1)).all())


def geomean(xs: list[float]) -> float:
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else float("nan")


def benchmark(sizes: list[int], functions: int, cap: float, seed: int) -> None:
    print(f"random functions: each row off/on/don't-care with p = {P_OFF}/{P_ON}/{P_DC}; "
          f"{functions} per size; SOPform capped at {cap:.0f} s")
    head = (f"{'n':>3} {'#':>2} {'on':>5} {'dc':>4} | {'default':>21} {'proven':>6} | "
            f"{'sop only':>8} | {'SOPform':>21} | {'ratio':>7} {'ratio':>7} {'lits':>5}")
    print(head)
    print(f"{'':>18}| {'terms lits seconds':>21} {'':>6} | {'seconds':>8} | "
          f"{'terms lits seconds':>21} | {'default':>7} {'sop':>7} {'Δ':>5}")
    print("-" * len(head))
    summary: dict[int, dict] = {}
    all_no_worse = True
    skipped = 0
    wrong_sopform = 0
    for n in sizes:
        s = summary.setdefault(n, {"ratio": [], "ratio_sop": [], "proven": 0, "done": 0,
                                   "skipped": 0})
        for i in range(functions):
            table = random_table(n, seed + 1000 * n + i)
            d = run_mechc(table, n, complements=True)
            so = run_mechc(table, n, complements=False)
            ref = run_sopform(table, n, cap)
            s["proven"] += d["proven"]
            mech = f"{d['terms']:5d} {d['literals']:5d} {d['seconds']:9.3f}"
            row = (f"{n:3d} {i:2d} {int((table == 1).sum()):5d} {int((table == 2).sum()):4d} | "
                   f"{mech} {'yes' if d['proven'] else 'NO':>6} | {so['seconds']:8.3f} | ")
            if ref is None:
                skipped += 1
                s["skipped"] += 1
                print(row + f"{'skipped (> cap)':>21} | {'-':>7} {'-':>7} {'-':>5}")
                continue
            if not sop_agrees(ref["cubes"], table, n):
                wrong_sopform += 1
            s["done"] += 1
            r1 = ref["seconds"] / d["seconds"]
            r2 = ref["seconds"] / so["seconds"]
            s["ratio"].append(r1)
            s["ratio_sop"].append(r2)
            delta = d["literals"] - ref["literals"]
            all_no_worse &= delta <= 0
            print(row + f"{ref['terms']:5d} {ref['literals']:5d} {ref['seconds']:9.3f} | "
                  f"{r1:7.1f} {r2:7.1f} {delta:+5d}")
    print()
    print("ratio = SOPform seconds / mechc seconds on the same function (geometric mean); "
          "'default' includes the complement and XOR-form searches, 'sop' is "
          "minimise(complements=False)")
    for n, s in summary.items():
        print(f"speedup_{n}_inputs: {geomean(s['ratio']):.1f}" if s["ratio"]
              else f"speedup_{n}_inputs: n/a (SOPform skipped on all {s['skipped']})")
        print(f"speedup_sop_only_{n}_inputs: {geomean(s['ratio_sop']):.1f}" if s["ratio_sop"]
              else f"speedup_sop_only_{n}_inputs: n/a")
        print(f"proven_{n}_inputs: {s['proven']}/{functions}")
        print(f"sopform_skipped_{n}_inputs: {s['skipped']}/{functions}")
    print(f"literals_no_worse: {'yes' if all_no_worse else 'no'}")
    print(f"sopform_skipped: {skipped}")
    print(f"sopform_wrong_answers: {wrong_sopform}")


def mcnc(directory: str, full: bool) -> None:
    from mechc.cells.library import load_library
    from mechc.errors import MechcError
    from mechc.frontends import load_spec
    from mechc.passes.map import map_equations
    from mechc.passes.minimise import MinimiseOptions as Opts
    from mechc.passes.minimise import minimise as run_minimise
    from mechc.passes.place import place
    from mechc.pipeline import compile_spec
    from mechc.proofs.logic import prove_logic

    lib = load_library(())

    def logic_stages(spec, progress):
        """Spec -> equations -> netlist -> layout, the stages of issue 2 (no mechanism)."""
        secs = {}
        t = time.perf_counter()
        progress("minimise")
        eq = run_minimise(spec, Opts())
        secs["minimise"] = time.perf_counter() - t
        progress("map")
        nl = map_equations(eq, lib).netlist
        progress("place")
        place(nl)
        stats = {"terms": eq.terms, "literals": eq.literals, "cells": len(nl.cells),
                 "minimisation": {"proven": eq.proven, "outputs": {
                     o: {"method": c.method} for o, c in eq.covers.items()}}}
        return nl, stats, secs

    files = sorted(Path(directory).glob("*.pla"))
    if not files:
        print(f"no .pla files in {directory}")
        return
    print("seconds: 'min.' = the minimise stage, 'total' = "
          + ("the whole compile (all stages)" if full else "minimise + map + place"))
    print(f"{'file':<14} {'in':>4} {'out':>4} {'terms':>6} {'lits':>6} {'cells':>6} "
          f"{'min. s':>7} {'total s':>8} {'minimum':>9} {'logic check':>22}")
    done = 0
    for path in files:
        stages: list[str] = ["parse"]
        t0 = time.perf_counter()
        try:
            spec = load_spec(path)
            if full:
                design = compile_spec(spec, progress=stages.append)
                nl, st, secs = design.netlist, design.stats, design.seconds
            else:
                nl, st, secs = logic_stages(spec, stages.append)
            seconds = time.perf_counter() - t0
            stages.append("logic check")
            report = prove_logic(nl, spec)
        except (MechcError, Exception) as e:  # report and go on with the next file
            print(f"{path.name:<14} FAILED in stage '{stages[-1]}' after "
                  f"{time.perf_counter() - t0:.2f} s: {type(e).__name__}: {e}")
            continue
        methods = {o["method"] for o in st["minimisation"]["outputs"].values()}
        minimal = "proven" if st["minimisation"]["proven"] else "/".join(sorted(methods))
        check = (("pass" if report["passed"] else "FAIL")
                 + (" exhaustive" if report.get("exhaustive", True) else
                    f" {report['cases']} sampled"))
        print(f"{path.name:<14} {spec.n:4d} {len(spec.outputs):4d} {st['terms']:6d} "
              f"{st['literals']:6d} {st['cells']:6d} {secs['minimise']:7.2f} "
              f"{seconds:8.2f} {minimal:>9} {check:>22}")
        done += report["passed"]
    print(f"mcnc_compiled_and_checked: {done}/{len(files)}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[6, 8, 10, 12])
    p.add_argument("--functions", type=int, default=3, help="random functions per size")
    p.add_argument("--cap", type=float, default=120.0, help="SOPform wall-clock cap, s")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--mcnc", metavar="DIR", help="compile every .pla in DIR instead")
    p.add_argument("--full", action="store_true",
                   help="with --mcnc: run every compile stage (mechanism synthesis and design "
                   "checks too), not just minimise, map and place")
    args = p.parse_args(argv)
    if args.mcnc:
        mcnc(args.mcnc, args.full)
    else:
        benchmark(args.sizes, args.functions, args.cap, args.seed)
    return 0


if __name__ == "__main__":
    sys.exit(main())
