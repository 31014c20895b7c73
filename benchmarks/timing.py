"""How well the timing level (``mechc simulate --level timing``) predicts what the whole-scene
dynamic proof measures, change by change, and what each costs.

    python benchmarks/timing.py [--quick] [--iterations N] [--out DIR]

Circuits: the sorter and the full adder (examples), compiled random specs of about 30 and 80
cells (as ``benchmarks/speed_accuracy.py``'s ``random30`` and ``random100``), and a 2-bit adder
with carry-in. For each input change of the dynamic proof's plan (the first ``--cases`` on the
big ones) the whole mechanism runs in pymunk from rest in its start state, as
``mechc.proofs.dynamic`` runs it; for every output that switches the benchmark measures when it
crosses mid-stroke and from when it stays within 0.5 % of stroke of its end (from the start of
the input's move) and compares both with the timing level's prediction for the same change.
Writes ``timing.csv`` and ``timing.png`` (predicted against measured settle and switch times,
the +-15 % band) to ``--out`` (default docs/perf) and prints the summary.
"""

from __future__ import annotations

import argparse
import csv
import time
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from mechc.bench.circuits import EXAMPLES, adder2_spec, random_compiled  # noqa: E402
from mechc.cells.characterise import crossing, settled_at  # noqa: E402
from mechc.cells.library import load_library  # noqa: E402
from mechc.frontends import load_spec  # noqa: E402
from mechc.passes.assemble import MechOptions  # noqa: E402
from mechc.physics.scene import Scene  # noqa: E402
from mechc.pipeline import CompileOptions, compile_spec  # noqa: E402
from mechc.proofs.dynamic import plan  # noqa: E402
from mechc.proofs.settings import ProofSettings, dyn_settings  # noqa: E402
from mechc.proofs.timing import cell_tables, predict_changes, prove_timing  # noqa: E402

LIB = load_library()
ROOT = Path(__file__).resolve().parents[1]
BAND = 0.15


def circuits(quick: bool, extra: list[str] = ()) -> list[tuple[str, object, int | None]]:
    """(name, design, changes measured: None for the proof's whole plan). ``extra``: more
    compiled random specs, ``SEED:CELLS`` each (8 changes with ``quick``, else 16)."""
    out = [("sorter", compile_spec(load_spec(EXAMPLES / "sorter.bool")), None),
           ("full_adder", compile_spec(load_spec(EXAMPLES / "full_adder.bool")), None)]
    for cells, cases in ((30, 12 if quick else None), (100, 6 if quick else 24)):
        d = random_compiled(cells, seed=cells)
        if not d.stats["design_checks"]["passed"]:  # as the speed benchmark: the physics only
            d = random_compiled(cells, seed=cells,
                                options=CompileOptions(mech=MechOptions(actuator_force=1e4)))
        out.append((f"random{len(d.netlist.cells)}", d, cases))
    out.append(("adder2_cin", compile_spec(adder2_spec()), 6 if quick else 16))
    for item in extra:
        seed, cells = (int(v) for v in item.split(":"))
        d = random_compiled(cells, seed=seed)
        out.append((f"random{len(d.netlist.cells)}_seed{seed}", d, 8 if quick else 16))
    return out


def measure(design, changes, names, st) -> tuple[list[dict], float]:
    """Whole-scene runs of ``changes``: per change the switching times of every output."""
    mech = design.mechanism
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    n = len(names)
    out = []
    t0 = time.perf_counter()
    for cur, vec in changes:
        start = {nm: float((cur >> (n - 1 - k)) & 1) for k, nm in enumerate(names)}
        k = n - (cur ^ vec).bit_length()
        sc = Scene.build(mech, LIB, types, st, start)
        r = sc.move(names[k], float((vec >> (n - 1 - k)) & 1))
        t = np.concatenate([[0.0], r.t])
        got = {"__scene_settle_s": st.move_time + r.settle_time,
               "__stretch_mm": r.max_violation}
        for o, s in r.outputs.items():
            s = np.concatenate([[s[0]], s])
            got[o] = {"switch_s": crossing(t, s), "settle_s": settled_at(t, s)}
        out.append(got)
    return out, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=str(ROOT / "docs" / "perf"))
    ap.add_argument("--only", action="append", default=[], metavar="NAME",
                    help="measure only this circuit (repeatable)")
    ap.add_argument("--extra-random", action="append", default=[], metavar="SEED:CELLS",
                    help="also a compiled random spec of about CELLS cells (repeatable)")
    ap.add_argument("--iterations", type=int, metavar="N",
                    help="solver iterations of the whole-scene reference (default: the "
                         "dynamic proof's own); the timing level and its tables unchanged: "
                         "how far the reference itself moves with the solver")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    summary = []
    for name, design, cases in circuits(args.quick, args.extra_random):
        if args.only and name not in args.only:
            continue
        spec = design.spec
        names = list(spec.inputs)
        st = dyn_settings(design, LIB)
        vectors = plan(len(names), 16, 0)
        if cases is not None:
            vectors = vectors[:cases]
        changes = list(zip([0, *vectors], vectors))
        t0 = time.perf_counter()
        tables, tabs = cell_tables(design, LIB, None, names, changes)
        t_char = time.perf_counter() - t0
        t0 = time.perf_counter()
        pred = predict_changes(design, LIB, names, changes, st, tables, detail=True)
        t_pred = time.perf_counter() - t0
        t0 = time.perf_counter()
        full = prove_timing(design, spec, LIB, ProofSettings())
        t_level = time.perf_counter() - t0
        ref_st = st if args.iterations is None else replace(st, iterations=args.iterations)
        meas, t_dyn = measure(design, changes, names, ref_st)
        errs, cf_errs, sw_errs, nets_early = [], [], [], []
        for p, m in zip(pred, meas):
            # what the screened proof reads: the latest settle of any switching net, against
            # the scene's own settle (every output within 0.5 % of its end); > 0 is early
            if p["switched"] and np.isfinite(m["__scene_settle_s"]):
                nets_early.append((m["__scene_settle_s"] - p["nets_settle_s"])
                                  / m["__scene_settle_s"])
            for o, po in p["outputs"].items():
                mo = m.get(o)
                if mo is None or not np.isfinite(mo["switch_s"]):
                    continue
                e = (po["settle_s"] - mo["settle_s"]) / mo["settle_s"]
                ecf = (po["closed_form_settle_s"] - mo["settle_s"]) / mo["settle_s"]
                es = (po["switch_s"] - mo["switch_s"]) / mo["switch_s"]
                errs.append(e)
                cf_errs.append(ecf)
                sw_errs.append(es)
                rows.append({"circuit": name, "moving": p["moving"], "to": p["to"],
                             "output": o, "path_cells": len(po["path"]),
                             "predicted_settle_s": po["settle_s"],
                             "measured_settle_s": round(mo["settle_s"], 6),
                             "closed_form_settle_s": po["closed_form_settle_s"],
                             "predicted_switch_s": po["switch_s"],
                             "measured_switch_s": round(mo["switch_s"], 6)})
        e = np.abs(np.array(errs))
        summary.append({
            "circuit": name, "cells": len(design.netlist.cells), "changes": len(changes),
            "outputs_timed": len(e),
            "within_15pct": int(np.sum(e <= BAND)),
            "max_settle_error": float(e.max()) if len(e) else 0.0,
            "mean_settle_error": float(e.mean()) if len(e) else 0.0,
            "max_switch_error": float(np.max(np.abs(sw_errs))) if sw_errs else 0.0,
            "max_settle_early": float(max(0.0, -min(errs))) if errs else 0.0,
            "max_settle_late": float(max(0.0, max(errs))) if errs else 0.0,
            "max_nets_settle_early": float(max(0.0, max(nets_early))) if nets_early else 0.0,
            "max_closed_form_settle_error": float(np.max(np.abs(cf_errs))) if cf_errs else 0.0,
            "timing_s_per_change": t_pred / max(1, len(changes)),
            "dynamic_s_per_change": t_dyn / max(1, len(changes)),
            "tables": dict(tabs.found), "characterise_s": t_char,
            "timing_level_s": t_level, "timing_level_cases": full.cases,
            "timing_level_passed": full.passed,
            # the whole scene's own figures (what moves with the solver's iterations)
            "scene_settle_max_s": max((m["__scene_settle_s"] for m in meas), default=0.0),
            "scene_stretch_max_mm": max((m["__stretch_mm"] for m in meas), default=0.0)})
        print(f"{name}: {summary[-1]}", flush=True)
    with open(out / "timing.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    chart(rows, out / "timing.png")
    allerr = [abs(r["predicted_settle_s"] - r["measured_settle_s"]) / r["measured_settle_s"]
              for r in rows]
    print(f"all circuits: {sum(e <= BAND for e in allerr)} of {len(allerr)} settle times within "
          f"15 %, worst {max(allerr):.3%}")
    for s in summary:
        print(f"  {s['circuit']:12s} {s['cells']:3d} cells {s['changes']:3d} changes: settle "
              f"max err {s['max_settle_error']:.2%} (closed form alone "
              f"{s['max_closed_form_settle_error']:.2%}; late {s['max_settle_late']:.2%}, "
              f"early {s['max_settle_early']:.2%}; screen's nets settle early "
              f"{s['max_nets_settle_early']:.2%}), switch max err "
              f"{s['max_switch_error']:.2%}; timing {s['timing_s_per_change'] * 1e3:.2f} ms/"
              f"change vs dynamic {s['dynamic_s_per_change']:.3f} s/change "
              f"({s['dynamic_s_per_change'] / max(s['timing_s_per_change'], 1e-9):.0f}x); "
              f"whole scene: latest settle {s['scene_settle_max_s'] * 1e3:.1f} ms, largest "
              f"stretch {s['scene_stretch_max_mm']:.4f} mm")


def chart(rows: list[dict], path: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    names = sorted({r["circuit"] for r in rows})
    for ax, key, title in ((axes[0], "settle", "settle time (within 0.5 % of stroke)"),
                           (axes[1], "switch", "switching time (mid-stroke)")):
        for nm in names:
            rs = [r for r in rows if r["circuit"] == nm]
            ax.scatter([r[f"measured_{key}_s"] * 1e3 for r in rs],
                       [r[f"predicted_{key}_s"] * 1e3 for r in rs], s=14, label=nm, alpha=0.7)
        lo = min(min(r[f"measured_{key}_s"], r[f"predicted_{key}_s"]) for r in rows) * 1e3
        hi = max(max(r[f"measured_{key}_s"], r[f"predicted_{key}_s"]) for r in rows) * 1e3
        x = np.linspace(lo * 0.9, hi * 1.1, 10)
        ax.plot(x, x, "k-", lw=0.8)
        ax.plot(x, x * (1 + BAND), "k:", lw=0.8, label="±15 %")
        ax.plot(x, x * (1 - BAND), "k:", lw=0.8)
        ax.set_xlabel("whole-scene dynamic, measured (ms from the move's start)")
        ax.set_ylabel("timing level, predicted (ms)")
        ax.set_title(title, fontsize=10)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
