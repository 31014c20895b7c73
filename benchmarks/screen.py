"""The screened proof (``mechc simulate``'s default, ``--level screened``) against the whole-scene
dynamic proof (``--level dynamic``), both run here on the same circuits, in one process, one
after the other.

    python benchmarks/screen.py [--only NAME ...] [--random N] [--hold SECONDS] [--out DIR]

What is timed: the whole dynamic proof on one process (the reference), the screened proof as
``mechc simulate`` runs it by default (``--jobs`` = every core this process may use,
``mechc.proofs.parallel.available_cores``), and the screened proof on one process too. The
row's ``speedup`` is the first against the second (the must-hold's measure);
``speedup_same_jobs`` the first against the third (what the screen alone buys). The cell
timing tables are built (or read from the cache) before any clock starts. The 1-minute load
average before and after each circuit is in the row: the seconds are only comparable within
a row.

Circuits: those of ``benchmarks/timing.py`` (the sorter, the full adder, random23, random81, the
2-bit adder with carry-in), ``--extra-random SEED:CELLS`` compiled random specs never used for a
margin (``--extra-only``: those alone) and ``--random`` held-out random specs (3-4 inputs, 1-2
outputs, seeds 9100..; compiled by mechc as ``mechc.bench.circuits.random_compiled`` compiles). For
each: both proofs' seconds and verdicts, the ratio, how many changes the screen ran in pymunk, and,
from the dynamic proof's own record of every change, whether any change the screen cleared failed
there (the soundness check) and how the worst joint stretch and contact overrun over all changes
compare with the worst over the changes the screen chose to run before any fallback: their ratio
and their gap as a share of the limit (the basis of ``mechc.proofs.screen.JOINT_HEADROOM`` and
``CONTACT_HEADROOM``), and how near the changes the screen cleared came to each limit of the
dynamic proof in the whole scene (``cleared_*_share``, ``cleared_nearest``: a share of 1 would be
a failing change cleared). ``--hold`` shortens the hold after each move, so that the settle
limit falls among the changes: there the settle margin decides and is tested. Writes
``screen.csv`` and ``screen.png`` (seconds of both proofs per circuit) to ``--out`` (default
docs/perf); ``--chart-from CSV`` redraws the chart of an earlier run.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import LIB, circuits  # noqa: E402

from mechc.ir.spec import OutputSpec, Spec  # noqa: E402
from mechc.logic.cubes import DC, Cube  # noqa: E402
from mechc.pipeline import compile_spec  # noqa: E402
from mechc.proofs.dynamic import prove_dynamic  # noqa: E402
from mechc.proofs.parallel import available_cores  # noqa: E402
from mechc.proofs.screen import _columns, _kind, decide, prove_screened  # noqa: E402
from mechc.proofs.settings import ProofSettings, dyn_settings  # noqa: E402
from mechc.proofs.timing import cell_tables  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def heldout(k: int) -> list[tuple[str, object, None]]:
    """``k`` random specs never used to set the screen's margins, compiled."""
    out = []
    for j in range(k):
        seed = 9100 + j
        rng = np.random.default_rng(seed)
        n_in, n_out = 3 + j % 2, 1 + (j // 2) % 2
        funcs = {}
        for o in range(n_out):
            t = rng.random(1 << n_in)
            on = np.flatnonzero(t < 0.45)
            dc = np.flatnonzero((t >= 0.45) & (t < 0.5))
            funcs[f"z{o}"] = OutputSpec(f"z{o}", on=[Cube.minterm(int(x), n_in) for x in on],
                                        dc=[Cube.minterm(int(x), n_in) for x in dc])
        spec = Spec(f"heldout{seed}", "bool", [f"x{i}" for i in range(n_in)], list(funcs),
                    funcs)
        out.append((f"heldout{seed}", compile_spec(spec), None))
    return out


def failed_changes(rec: list[dict], report, st) -> set[int]:
    """Indices of the plan's changes the dynamic proof failed (from its record and its
    listed failures, matched by target vector and moving input)."""
    bad = set()
    listed = {(tuple(sorted(f["inputs"].items())), f["moving"]) for f in report.failures
              if "inputs" in f}
    for i, r in enumerate(rec):
        key = (tuple(sorted(r["inputs"].items())), r["moving"])
        if (key in listed or r["max_violation_mm"] > st.violation_limit
                or r["max_penetration_mm"] > st.penetration_limit
                or not math.isfinite(r["settle_time_s"])):
            bad.add(i)
    return bad


def settle_early(dec: list[dict], rec: list[dict], st) -> dict[str, float]:
    """How much later than predicted the whole scene settled, as a share of its settle, at
    worst over the changes without a heavy cell (those a screen may clear) and over the heavy
    ones, every change of the plan that settled after the move (the basis of
    ``mechc.proofs.screen.MODEL_ERROR``; negative: every prediction late)."""
    worst = {"settle_early_worst": -math.inf, "settle_early_worst_heavy": -math.inf,
             "settle_early_worst_cleared": -math.inf}
    for d, r in zip(dec, rec):
        s = r["settle_time_s"]
        if math.isfinite(s) and s > 0:
            m = s + st.move_time
            e = (m - d["predicted_settle_s"]) / m
            keys = ["settle_early_worst_heavy" if d["heavy"] else "settle_early_worst"]
            if d["route"] == "timing":
                keys.append("settle_early_worst_cleared")
            for k in keys:
                worst[k] = max(worst[k], e)
    return {k: round(v, 4) if v > -math.inf else "" for k, v in worst.items()}


def cleared_nearest(dec: list[dict], rec: list[dict], spec, st, tolerance: float,
                    stroke: float) -> dict[str, object]:
    """How near the changes the screen cleared came to each limit of the dynamic proof, in
    the whole scene, as a share of that limit (1 or more: a failing change was cleared): the
    settle after the move of ``settle_time``, a held output's excursion and a rest error of
    the tolerance, the joint stretch and contact overrun of their limits, the input's lag at
    the end of the stall limit. What a wrong margin would cost: a share near 1 is a change
    the screen nearly passed wrongly."""
    n = len(spec.inputs)
    share = {"settle": 0.0, "held": 0.0, "rest": 0.0, "stretch": 0.0, "overrun": 0.0,
             "stall": 0.0}
    which = {k: "" for k in share}
    # what the spec asks after every change, in one evaluation
    want = spec.values_at(_columns([sum(int(r["inputs"][nm]) << (n - 1 - k)
                                        for k, nm in enumerate(spec.inputs)) for r in rec], n))
    for i, (d, r) in enumerate(zip(dec, rec)):
        if d["route"] != "timing":
            continue
        rest = max([abs(r["final"][o] - int(want[o][i])) for o in r["final"]
                    if o in want and int(want[o][i]) != DC] or [0.0])
        s = r["settle_time_s"]
        got = {"settle": s / st.settle_time if math.isfinite(s) else math.inf,
               "held": max(r["held_deviation"].values(), default=0.0) / tolerance,
               "rest": rest / tolerance,
               "stretch": r["max_violation_mm"] / st.violation_limit,
               "overrun": r["max_penetration_mm"] / st.penetration_limit,
               "stall": r["servo_lag_end_mm"] / (tolerance * stroke)}
        for k, v in got.items():
            if v > share[k]:
                share[k], which[k] = v, f"{i} ({d['moving']} to {d['to']})"
    top = max(share, key=share.get)
    return {**{f"cleared_{k}_share": round(v, 4) for k, v in share.items()},
            "cleared_nearest": f"{top} {share[top]:.3f} on change {which[top]}"
            if share[top] > 0 else ""}


def worst_witness_gaps(design, rec: list[dict], st, settings) -> dict[str, float]:
    """Over the changes the screen may clear (no reason to run but being a witness): how far
    each one's joint stretch, contact overrun and held-output excess over its closed form went
    beyond the *mildest* change switching any of its (cell kind, direction) alike, as a share
    of the limit (of the tolerance for the excess): every witness the worst choice (the basis
    of ``JOINT_HEADROOM``, ``CONTACT_HEADROOM`` and ``HELD_MARGIN_SHARE``)."""
    pairs, timed, dec = decide(design, design.spec, LIB, settings, st)
    tables, _ = cell_tables(design, LIB, None, list(design.spec.inputs), pairs)
    kind = {c.id: _kind(c, tables.get(c.id)) for c in design.netlist.cells.values()}
    ks = [{(kind[c], d) for c, d in t["switched"].items()} for t in timed]
    free = [i for i, d in enumerate(dec) if all(w.startswith("witness") for w in d["why"])]
    excess = [max([dev - timed[i]["closed_form_swing"].get(o, 0.0)
                   for o, dev in r["held_deviation"].items()] or [0.0])
              for i, r in enumerate(rec)]
    vals = {"stretch": ([r["max_violation_mm"] for r in rec], st.violation_limit),
            "overrun": ([r["max_penetration_mm"] for r in rec], st.penetration_limit),
            "held_excess": (excess, settings.tolerance)}
    out = {}
    for name, (v, lim) in vals.items():
        mild: dict = {}
        for i, k in enumerate(ks):
            for key in k:
                mild[key] = min(mild.get(key, math.inf), v[i])
        out[f"worst_witness_{name}_gap"] = round(max(
            ((v[i] - max(mild[key] for key in ks[i])) / lim for i in free if ks[i]),
            default=0.0), 4)
    out["held_excess_of_tolerance"] = round(max(excess, default=0.0) / settings.tolerance, 4)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append", default=[], metavar="NAME")
    ap.add_argument("--random", type=int, default=4, metavar="N",
                    help="held-out random specs (default %(default)s)")
    ap.add_argument("--extra-random", action="append", default=[], metavar="SEED:CELLS",
                    help="also a compiled random spec of about CELLS cells, never used to set "
                         "a margin (repeatable)")
    ap.add_argument("--extra-only", action="store_true",
                    help="measure only the --extra-random circuits")
    ap.add_argument("--hold", type=float, metavar="SECONDS",
                    help="hold each change this long after its move (default: the proof's "
                         "own); a short hold puts the settle limit among the changes, where "
                         "the settle margin is tested")
    ap.add_argument("--out", default=str(ROOT / "docs" / "perf"))
    ap.add_argument("--chart-from", metavar="CSV", help="only redraw the chart of this CSV")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.chart_from:
        with open(args.chart_from, newline="") as f:
            chart(list(csv.DictReader(f)), out / "screen.png")
        return
    rows = []
    every = circuits(True, args.extra_random)
    k = len(every) - len(args.extra_random)
    base, extra = every[:k], every[k:]
    todo = extra if args.extra_only else [*base, *heldout(args.random), *extra]
    for name, design, _ in todo:
        if args.only and name not in args.only:
            continue
        spec = design.spec
        st = dyn_settings(design, LIB)
        if args.hold is not None:
            st.settle_time = args.hold
        settings = ProofSettings()
        cores = available_cores()
        load0 = os.getloadavg()[0]
        decide(design, spec, LIB, settings, st)  # the timing tables, built or cached
        rec: list[dict] = []
        t0 = time.perf_counter()
        full = prove_dynamic(design, spec, LIB, st, record=rec)
        t_full = time.perf_counter() - t0
        t0 = time.perf_counter()
        scr = prove_screened(design, spec, LIB, ProofSettings(jobs=cores), st=st)
        t_scr = time.perf_counter() - t0
        if cores > 1:
            t0 = time.perf_counter()
            scr1 = prove_screened(design, spec, LIB, settings, st=st)
            t_scr1 = time.perf_counter() - t0
        else:
            scr1, t_scr1 = scr, t_scr
        sc = scr.figures["screen"]
        routes = [d["route"] for d in sc["decisions"]]
        # the report is the same whatever the processes (the dynamic proof's promise)
        same_jobs_agree = (scr1.passed == scr.passed and routes
                           == [d["route"] for d in scr1.figures["screen"]["decisions"]])
        dec = sc["decisions"]
        ran = [i for i, d in enumerate(dec) if d["route"] == "dynamic"]
        # the changes the screen chose before any fallback: what calibrated it
        chose = [i for i in ran if not any(w.startswith("calibration failed")
                                           for w in dec[i]["why"])]
        bad = failed_changes(rec, full, st)
        missed = sorted(i for i in bad if dec[i]["route"] == "timing")
        worst = {k: max((r[k] for r in rec), default=0.0)
                 for k in ("max_violation_mm", "max_penetration_mm")}
        worst_ran = {k: max((rec[i][k] for i in chose), default=0.0) for k in worst}
        rho = {k: worst[k] / worst_ran[k] if worst_ran[k] > 0 else float("nan")
               for k in worst}
        row = {"circuit": name, "cells": len(design.netlist.cells), "changes": len(rec),
               "ran_in_pymunk": len(ran), "chosen_by_screen": len(chose),
               "cleared_by_timing": sc["cleared_by_timing"],
               "calibration": "passed" if sc["calibration"] == "passed"
               else sc["calibration"][0],
               "fell_back": sc.get("fell_back", 0), "jobs": cores,
               "dynamic_s": round(t_full, 2), "screened_s": round(t_scr, 2),
               "screened_jobs1_s": round(t_scr1, 2),
               "speedup": round(t_full / t_scr, 2),
               "speedup_same_jobs": round(t_full / t_scr1, 2), "dynamic_passed": full.passed,
               "screened_passed": scr.passed, "screened_jobs1_agrees": same_jobs_agree,
               "changes_failed_by_dynamic": len(bad),
               "failed_changes_cleared": len(missed),
               "worst_stretch_mm": round(worst["max_violation_mm"], 5),
               "stretch_all_over_ran": round(rho["max_violation_mm"], 3),
               "worst_overrun_mm": round(worst["max_penetration_mm"], 5),
               "overrun_all_over_ran": round(rho["max_penetration_mm"], 3),
               # what the plan's worst change reached beyond the worst the screen ran, as a
               # share of the limit (the basis of JOINT_HEADROOM and CONTACT_HEADROOM)
               "stretch_gap_of_limit": round((worst["max_violation_mm"]
                                              - worst_ran["max_violation_mm"])
                                             / st.violation_limit, 4),
               "overrun_gap_of_limit": round((worst["max_penetration_mm"]
                                              - worst_ran["max_penetration_mm"])
                                             / st.penetration_limit, 4),
               **settle_early(dec, rec, st),
               **cleared_nearest(dec, rec, spec, st, settings.tolerance,
                                 design.mechanism.ctx.stroke),
               **worst_witness_gaps(design, rec, st, settings),
               "load_before": round(load0, 2), "load_after": round(os.getloadavg()[0], 2)}
        rows.append(row)
        print(row, flush=True)
    if not rows:
        return
    with open(out / "screen.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    chart(rows, out / "screen.png")
    print(f"\n| circuit | cells | changes | ran in pymunk | dynamic s (1 process) | screened s "
          f"({rows[0]['jobs']} processes) | speed-up | screened s (1 process) | speed-up, same "
          "processes | verdicts (dynamic / screened) | failed changes cleared | calibration | "
          "load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['circuit']} | {r['cells']} | {r['changes']} | {r['ran_in_pymunk']} | "
              f"{r['dynamic_s']} | {r['screened_s']} | {r['speedup']}x | "
              f"{r['screened_jobs1_s']} | {r['speedup_same_jobs']}x | "
              f"{'pass' if r['dynamic_passed'] else 'FAIL'} / "
              f"{'pass' if r['screened_passed'] else 'FAIL'} | {r['failed_changes_cleared']} | "
              f"{r['calibration']} | {r['load_before']}-{r['load_after']} |")
    unsound = [r["circuit"] for r in rows if r["failed_changes_cleared"]
               or r["screened_passed"] != r["dynamic_passed"]
               or not r["screened_jobs1_agrees"]]
    print(f"changes the dynamic proof failed that the screen cleared: "
          f"{sum(r['failed_changes_cleared'] for r in rows)}"
          + (f" (in {', '.join(unsound)})" if unsound else ""))


def chart(rows: list[dict], path: Path) -> None:
    """Both proofs' seconds per circuit (log scale), with the screened run's share of changes
    in pymunk."""
    fig, ax = plt.subplots(figsize=(9, 4))
    x = np.arange(len(rows))
    dyn = [float(r["dynamic_s"]) for r in rows]
    scr = [float(r["screened_s"]) for r in rows]
    jobs = rows[0].get("jobs") or "?"
    ax.bar(x - 0.2, dyn, 0.4, label="whole dynamic proof, 1 process")
    ax.bar(x + 0.2, scr, 0.4, label=f"screened proof, {jobs} processes (the default)")
    for k, r in enumerate(rows):
        same = r.get("speedup_same_jobs")
        ax.text(k + 0.2, scr[k] * 1.1, f"{r['ran_in_pymunk']}/{r['changes']}\n"
                f"{float(r['speedup']):.1f}x"
                + (f"\n({float(same):.1f}x)" if same not in (None, "") else ""),
                ha="center", va="bottom", fontsize=7)
    ax.set_xticks(x, [r["circuit"] for r in rows], rotation=20, fontsize=8)
    ax.set_yscale("log")
    ax.set_ylim(top=max(dyn + scr) * 12)  # room for the labels above the tallest bars
    ax.set_ylabel("seconds, wall clock (log)")
    ax.set_title("screened vs whole dynamic proof (changes in pymunk / all; speed-up; "
                 "(speed-up on 1 process each))", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
