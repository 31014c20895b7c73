"""Speed against accuracy: every simulation level on the benchmark circuits, a grid of dynamic
settings, pruned against whole scenes, where the methods break, and peers in the same run.

``python benchmarks/speed_accuracy.py [--quick] [--out DIR]`` or ``mechc bench``. Writes
``speed_accuracy.csv``, ``speed_accuracy.png`` (output error against seconds per input change,
log-log, one series per circuit, Pareto fronts and default settings marked) and
``stability.png`` (the stability map and the breakdown sweeps) into ``--out``, and the error
model ``accuracy_model.json`` (into the package with ``--write-model``, which a full run does by
default). The summary ends in ``name: value`` lines. Every ratio is of two figures measured in
this run, on this machine.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mechc.bench import stability
from mechc.cells.library import Library, load_library
from mechc.ir.design import Design
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import compile_spec
from mechc.proofs.accuracy import MODEL_PATH, ErrorModel, ModelPoint
from mechc.proofs.dynamic import PRUNE_DEFAULT, prove_dynamic
from mechc.proofs.kinematic import prove_kinematic
from mechc.proofs.logic import prove_logic
from mechc.proofs.report import ProofReport
from mechc.proofs.settings import dyn_settings

ROOT = Path(__file__).resolve().parents[2]
_clock = time.process_time  # CPU seconds of this process: the machine is shared, and every
#                             timed path here is single-threaded
EXAMPLES = ROOT / "examples"
BREAKING = ("solver", "contact", "settle")  # failure kinds that say the numerics did not hold
COLUMNS = ["section", "circuit", "level", "variant", "dt_s", "iterations", "move_time_s",
           "spring_factor", "mass_factor", "cases", "seconds", "seconds_per_case",
           "error_fraction", "max_violation_mm", "passed", "solver_ok", "failure_kinds",
           "steps", "default", "margin_deg"]


@dataclass
class Circuit:
    name: str
    design: Design
    max_cases: int | None = None  # dynamic changes run (None: the proof's own plan)
    note: str = ""
    sequential: bool = False  # proved by mechc.proofs.seq_logic / seqmech, never pruned


@dataclass
class Bench:
    lib: Library
    quick: bool
    rows: list[dict] = field(default_factory=list)
    summary: dict[str, object] = field(default_factory=dict)
    log: list[str] = field(default_factory=list)

    def say(self, text: str) -> None:
        print(text, flush=True)
        self.log.append(text)

    def row(self, **kw) -> dict:
        r = {c: kw.get(c, "") for c in COLUMNS}
        self.rows.append(r)
        return r


# ---- circuits ----------------------------------------------------------------------------------
def circuits(quick: bool, say) -> list[Circuit]:
    from mechc.bench.circuits import random_compiled
    from mechc.frontends import load_spec
    from mechc.passes.assemble import MechOptions
    from mechc.pipeline import CompileOptions

    out = [Circuit("sorter", compile_spec(load_spec(EXAMPLES / "sorter.bool"))),
           Circuit("full_adder", compile_spec(load_spec(EXAMPLES / "full_adder.bool")))]
    fsm = EXAMPLES / "speedctl.fsm"
    if fsm.exists():
        try:
            from mechc.frontends.fsm import parse_fsm_file

            d = compile_spec(parse_fsm_file(fsm))
            out.append(Circuit("speedctl", d, sequential=True))
        except Exception as e:  # another issue's front end: measure it only once it compiles
            say(f"note: {fsm.name} does not compile yet ({type(e).__name__}: {e}); skipped")
    else:
        say("note: examples/speedctl.fsm does not exist yet; skipped")
    for cells, cases in ((30, None), (100, 6 if quick else 24)):
        d = random_compiled(cells, seed=cells)
        note = ""
        if not d.stats["design_checks"]["passed"]:  # measure the physics, not the force budget
            d = random_compiled(cells, seed=cells,
                                options=CompileOptions(mech=MechOptions(actuator_force=1e4)))
            note = "actuators rated 1e4 N (the 100 N default fails the force check)"
        out.append(Circuit(f"random{cells}", d, cases, note))
    return out


def _cells(d: Design) -> int:
    return len(d.netlist.cells)


def _solver_ok(r: ProofReport) -> bool:
    return not any(r["failure_kinds"].get(k) for k in BREAKING)


def _dyn(b: Bench, c: Circuit, st: DynSettings, prune: bool | None = None,
         max_cases: int | None = None, freeze: str | None = None) -> tuple[ProofReport, float]:
    kw = {} if prune is None else {"prune": prune}
    if freeze is not None:
        kw["freeze"] = freeze
    t0 = _clock()
    r = prove_dynamic(c.design, c.design.spec, b.lib, st, extra=0,
                      max_cases=max_cases if max_cases is not None else c.max_cases, **kw)
    return r, _clock() - t0


# ---- 1. every level at its defaults -----------------------------------------------------------
def levels(b: Bench, cs: list[Circuit]) -> None:
    b.say("\n== levels (defaults) ==")
    errs, per_case = [], []
    for c in cs:
        d = c.design
        try:
            t0 = _clock()
            lr = _logic(c)
            tl = _clock() - t0
            t0 = _clock()
            kr = _kinematic(b, c)
            tk = _clock() - t0
            st = dyn_settings(d)
            t0 = _clock()
            dr = _sequential_dynamic(b, c, st) if c.sequential else _dyn(b, c, st)[0]
            td = _clock() - t0
        except Exception as e:  # the sequential provers are another issue's, still moving
            if not c.sequential:
                raise
            b.say(f"note: {c.name} not measured ({type(e).__name__}: {e})")
            continue
        spc = td / max(1, dr["cases"])
        errs.append(dr["max_position_error_fraction"])
        per_case.append(spc)
        b.row(section="levels", circuit=c.name, level="logic", cases=lr.get("cases", ""),
              seconds=tl, seconds_per_case=tl / max(1, lr.get("cases", 1)),
              error_fraction=0.0, passed=lr["passed"])
        states = kr.get("cases", kr.get("steps", 0)) + kr.get("transitions", 0)
        b.row(section="levels", circuit=c.name, level="kinematic", cases=states,
              seconds=tk, seconds_per_case=tk / max(1, states),
              error_fraction=0.0, passed=kr["passed"])
        b.row(section="levels", circuit=c.name, level="dynamic", dt_s=st.dt,
              iterations=st.iterations, move_time_s=st.move_time, cases=dr["cases"],
              seconds=td, seconds_per_case=spc, error_fraction=dr["max_position_error_fraction"],
              max_violation_mm=dr["max_joint_violation_mm"], passed=dr["passed"],
              solver_ok=_solver_ok(dr), failure_kinds=_kinds(dr), steps=dr.get("steps", ""),
              default=True,
              variant="pruned" if dr.get("pruning", {}).get("enabled") else "whole")
        if not kr["passed"]:
            b.say(f"{c.name}: the kinematic proof FAILS ({kr.get('failure_count')} failures)")
        b.say(f"{c.name:11s} {_cells(d):3d} cells  logic {tl * 1e3:7.1f} ms  kinematic "
              f"{tk:6.3f} s ({states} states and changes)  dynamic "
              f"{dr['cases']:3d} changes {td:6.2f} s = {spc:.3f} s/change, error "
              f"{dr['max_position_error_fraction']:.5f} of stroke, joint "
              f"{dr['max_joint_violation_mm']:.4f} mm, "
              f"{'pass' if dr['passed'] else 'FAIL ' + _kinds(dr)}"
              + (f"  [{c.note}]" if c.note else ""))
        b.summary[f"{c.name}_default_error"] = dr["max_position_error_fraction"]
        b.summary[f"{c.name}_default_passed"] = dr["passed"]
        b.summary[f"{c.name}_default_case_seconds"] = round(spc, 4)
    b.summary["default_error"] = max(errs)
    b.summary["default_case_seconds"] = round(float(np.mean(per_case)), 4)


def _logic(c: Circuit) -> ProofReport:
    if c.sequential:
        from mechc.proofs.seq_logic import prove_sequential

        return prove_sequential(c.design.netlist, c.design.spec)
    return prove_logic(c.design.netlist, c.design.spec)


def _kinematic(b: Bench, c: Circuit) -> ProofReport:
    if c.sequential:
        from mechc.proofs.seq_mechanism import prove_sequential_kinematic

        return prove_sequential_kinematic(c.design, c.design.spec, b.lib)
    return prove_kinematic(c.design, c.design.spec, b.lib)


def _sequential_dynamic(b: Bench, c: Circuit, st: DynSettings) -> ProofReport:
    from mechc.proofs.seq_mechanism import prove_sequential_dynamic

    return prove_sequential_dynamic(c.design, c.design.spec, b.lib, st)


def _kinds(r: ProofReport) -> str:
    return " ".join(f"{k}={v}" for k, v in r["failure_kinds"].items())


# ---- 2. the settings grid --------------------------------------------------------------------
def grid(b: Bench, cs: list[Circuit]) -> list[dict]:
    if b.quick:
        dts, its, mts = (1e-4, 2.5e-4, 5e-4, 1e-3), (5, 20, 60), (0.04, 0.08)
    else:
        dts = (1e-4, 1.5e-4, 2.5e-4, 3.5e-4, 5e-4, 1e-3, 2e-3)
        its, mts = (3, 5, 10, 20, 40, 60), (0.04, 0.08, 0.16)
    names = ("sorter", "full_adder")
    b.say(f"\n== dynamic settings grid ({len(dts)} steps x {len(its)} iteration counts x "
          f"{len(mts)} move times on {', '.join(names)}) ==")
    out = []
    for c in [c for c in cs if c.name in names]:
        for dt in dts:
            for it in its:
                for mt in mts:
                    st = dyn_settings(c.design, dt=dt, iterations=it, move_time=mt)
                    r, secs = _dyn(b, c, st, prune=False)
                    out.append(b.row(section="grid", circuit=c.name, level="dynamic",
                                     variant="whole", dt_s=dt, iterations=it, move_time_s=mt,
                                     cases=r["cases"], seconds=secs,
                                     seconds_per_case=secs / max(1, r["cases"]),
                                     error_fraction=r["max_position_error_fraction"],
                                     max_violation_mm=r["max_joint_violation_mm"],
                                     passed=r["passed"], solver_ok=_solver_ok(r),
                                     failure_kinds=_kinds(r), steps=r["steps"],
                                     default=(dt, it, mt) == (2.5e-4, 60, 0.08)))
        b.say(f"{c.name}: {sum(1 for r in out if r['circuit'] == c.name)} settings run")
    return out


def error_model(rows: list[dict], overhead: float, source: str) -> ErrorModel:
    """Per setting: the worst circuit's error (inf where the solver broke), the most steps."""
    keys = sorted({(r["dt_s"], r["iterations"], r["move_time_s"]) for r in rows})
    pts = []
    for k in keys:
        rs = [r for r in rows if (r["dt_s"], r["iterations"], r["move_time_s"]) == k]
        ok = all(r["solver_ok"] for r in rs)
        err = max(float(r["error_fraction"]) for r in rs) if ok else math.inf
        steps = max(r["steps"] / max(1, r["cases"]) for r in rs)
        pts.append(ModelPoint(k[0], k[1], k[2], err, ok, steps))
    return ErrorModel(pts, overhead, source)


def step_overhead(b: Bench, c: Circuit) -> float:
    """Per-step work outside pymunk's solver, in solver iterations: from one change run at two
    iteration counts (time per step is a + b * iterations)."""
    times = {}
    for it in (10, 60):
        st = DynSettings(iterations=it, violation_limit=0.1)
        sc = Scene.build(c.design.mechanism, b.lib, _types(c.design), st,
                         {k: 0.0 for k in c.design.spec.inputs})
        name = c.design.spec.inputs[0]
        t0 = _clock()
        r = sc.move(name, 1.0)
        times[it] = (_clock() - t0) / r.steps
    per_it = (times[60] - times[10]) / 50
    return max(0.0, (times[10] - 10 * per_it) / per_it) if per_it > 0 else 0.0


def _types(d: Design) -> dict[str, str]:
    return {c.id: c.cell for c in d.netlist.cells.values()}


# ---- 3. pruned against whole scenes ---------------------------------------------------------
def pruning(b: Bench, cs: list[Circuit]) -> None:
    """Whole scene against pruned scenes at the default freeze (``prune.FREEZE``) and with
    every still body frozen ("all": what pruning could save if dwelling outputs were trusted
    to stay still; not the default, see docs/performance.md)."""
    b.say("\n== pruned scenes against the whole scene (default settings) ==")
    variants = (("whole", False, None), ("pruned", True, None), ("pruned_all", True, "all"))
    for c in cs:
        if c.sequential:
            b.say(f"{c.name}: not pruned (MEMORY cells hold state: each change needs the "
                  "scene the last one left)")
            continue
        repeat = 1 if b.quick and _cells(c.design) > 50 else 2
        st = dyn_settings(c.design)
        best: dict[str, float] = {}
        reports: dict[str, dict] = {}
        for _ in range(repeat):  # interleaved, best of: the machine is shared
            for key, prune, freeze in variants:
                r, secs = _dyn(b, c, st, prune=prune, freeze=freeze)
                if key not in best or secs < best[key]:
                    best[key], reports[key] = secs, r
        w, p, pa = reports["whole"], reports["pruned"], reports["pruned_all"]
        if not p["pruning"]["enabled"]:
            b.say(f"{c.name}: not pruned ({p['pruning']['reason']})")
            continue
        speed = best["whole"] / best["pruned"]
        speed_all = best["whole"] / best["pruned_all"]
        d_err = abs(p["max_position_error_fraction"] - w["max_position_error_fraction"])
        same = _same_verdict(w, p)
        for key, r in reports.items():
            b.row(section="pruning", circuit=c.name, level="dynamic", variant=key, dt_s=st.dt,
                  iterations=st.iterations, move_time_s=st.move_time, cases=r["cases"],
                  seconds=best[key], seconds_per_case=best[key] / max(1, r["cases"]),
                  error_fraction=r["max_position_error_fraction"],
                  max_violation_mm=r["max_joint_violation_mm"], passed=r["passed"],
                  solver_ok=_solver_ok(r), failure_kinds=_kinds(r), steps=r["steps"],
                  default=(key == "pruned") == PRUNE_DEFAULT and key != "pruned_all")
        pr = p["pruning"]
        solver = solver_speedup(b, c)
        b.say(f"{c.name:11s} whole {best['whole']:6.2f} s  pruned {best['pruned']:6.2f} s  = "
              f"{speed:4.2f}x (solver alone {solver:4.2f}x; all still bodies frozen "
              f"{best['pruned_all']:5.2f} s = {speed_all:4.2f}x, verdict "
              f"{'same' if _same_verdict(w, pa) else 'DIFFERENT'})  error "
              f"{w['max_position_error_fraction']:.5f} -> {p['max_position_error_fraction']:.5f}"
              f" ({pa['max_position_error_fraction']:.5f})  joint "
              f"{w['max_joint_violation_mm']:.4f} -> {p['max_joint_violation_mm']:.4f} mm "
              f"({pa['max_joint_violation_mm']:.4f})  verdict {'same' if same else 'DIFFERENT'}"
              f"  scene {pr['mean_cells']:.1f} of {pr['circuit_cells']} cells, "
              f"{pr['mean_constraints']:.0f} of {w['scene']['constraints']} constraints "
              f"({pa['pruning']['mean_constraints']:.0f} all frozen), "
              f"{pr['escalated_cases']} of {p['cases']} escalated")
        b.summary[f"{c.name}_pruned_speedup"] = round(speed, 3)
        b.summary[f"{c.name}_pruned_all_frozen_speedup"] = round(speed_all, 3)
        b.summary[f"{c.name}_pruned_solver_speedup"] = round(solver, 3)
        b.summary[f"{c.name}_pruned_error_delta"] = round(d_err, 6)
        b.summary[f"{c.name}_pruned_same_verdict"] = same
        b.summary[f"{c.name}_pruned_escalated"] = f"{pr['escalated_cases']}/{p['cases']}"
        if c.name == "random30":
            b.summary["pruned_speedup"] = round(speed, 3)
            b.summary["pruned_all_frozen_speedup"] = round(speed_all, 3)
            b.summary["pruned_solver_speedup"] = round(solver, 3)
            b.summary["pruned_error_delta"] = round(d_err, 6)


def _same_verdict(a: dict, b: dict) -> bool:
    return a["passed"] == b["passed"] and set(a["failure_kinds"]) == set(b["failure_kinds"])


def solver_speedup(b: Bench, c: Circuit, cases: int = 4, steps: int = 150) -> float:
    """pymunk's step alone (no measuring), whole scene against each change's pruned scene."""
    from mechc.proofs.dynamic import plan
    from mechc.proofs.prune import build_scene, plan_case

    d, mech = c.design, c.design.mechanism
    names = list(d.spec.inputs)
    n = len(names)
    st = dyn_settings(d)
    cur, state = 0, {k: 0.0 for k in names}
    t_whole = t_pruned = 0.0
    for vec in plan(n, 0, 0)[:cases]:
        k = n - (cur ^ vec).bit_length()
        name, target = names[k], float((vec >> (n - 1 - k)) & 1)
        whole = Scene.build(mech, b.lib, _types(d), st, dict(state))
        pc = plan_case(d.netlist, mech, b.lib, _types(d), state, name, target)
        pruned = build_scene(pc, d.netlist, mech, b.lib, _types(d), st, state)
        for sc, acc in ((whole, "w"), (pruned, "p")):
            t0 = _clock()
            for _ in range(steps):
                sc.space.step(st.dt)
            if acc == "w":
                t_whole += _clock() - t0
            else:
                t_pruned += _clock() - t0
        state[name] = target
        cur = vec
    return t_whole / t_pruned if t_pruned > 0 else math.nan


# ---- 4. where the methods break ---------------------------------------------------------------
def stability_study(b: Bench, c: Circuit) -> dict:
    b.say("\n== stability (full adder, first 4 changes, strong actuators) ==")
    base = stability.strong_actuators(c.design)
    cases = 4

    def run(d, section, **kw):
        st = dyn_settings(base, **{k: v for k, v in kw.items() if k in ("dt", "iterations")})
        t0 = _clock()
        r = prove_dynamic(d, d.spec, b.lib, st, extra=0, max_cases=cases, prune=False)
        secs = _clock() - t0
        vio = r["max_joint_violation_mm"]
        row = b.row(section=section, circuit=c.name, level="dynamic", dt_s=st.dt,
                    iterations=st.iterations, move_time_s=st.move_time,
                    spring_factor=kw.get("k", 1.0), mass_factor=kw.get("m", 1.0),
                    cases=r["cases"], seconds=secs, seconds_per_case=secs / max(1, r["cases"]),
                    error_fraction=r["max_position_error_fraction"], max_violation_mm=vio,
                    passed=r["passed"], solver_ok=_solver_ok(r), failure_kinds=_kinds(r),
                    steps=r["steps"])
        return row

    ks = (1, 10, 100) if b.quick else (1, 3, 10, 30, 100, 300)
    dts = (1e-4, 2.5e-4, 5e-4, 1e-3) if b.quick else (5e-5, 1e-4, 2.5e-4, 5e-4, 1e-3, 2e-3)
    stiff = {k: stability.stiffen(base, k) for k in ks}
    mapping = []
    for k in ks:
        for dt in dts:
            mapping.append(run(stiff[k], "stability_dt_k", dt=dt, k=k))
    its = (1, 3, 5, 20, 60) if b.quick else (1, 2, 3, 5, 10, 20, 60)
    iters = [run(base, "stability_iterations", iterations=it) for it in its]
    ms = (1e-4, 1e-2, 0.1, 1, 100) if b.quick else (1e-4, 1e-3, 1e-2, 1e-1, 1, 10, 100)
    masses = [run(stability.scale_masses(base, m), "stability_mass", m=m) for m in ms]
    dt_sweep = [r for r in mapping if r["spring_factor"] == 1]
    out = {
        "dt_break": _first_break(dt_sweep, "dt_s"),
        "iterations_break": _last_break(iters, "iterations"),
        "spring_factor_break": _first_break([r for r in mapping if r["dt_s"] == 2.5e-4],
                                            "spring_factor"),
        "mass_light_break": _last_break([r for r in masses if r["mass_factor"] <= 1],
                                        "mass_factor"),
        "mass_heavy_break": _first_break([r for r in masses if r["mass_factor"] >= 1],
                                         "mass_factor"),
    }
    for k, v in out.items():
        b.say(f"{k}: {v}")
        b.summary[k] = v
    for name, rows in (("iterations", iters), ("mass", masses)):
        b.say(name + ": " + ", ".join(
            f"{r['iterations'] if name == 'iterations' else r['mass_factor']:g}->"
            f"{'ok' if r['passed'] else _short(r['failure_kinds'])}" for r in rows))
    toggle(b)
    return {"map": mapping, "iterations": iters, "mass": masses}


def _short(kinds: str) -> str:
    return "/".join(k.split("=")[0] for k in kinds.split())


def _first_break(rows: list[dict], key: str):
    """Smallest value of ``key`` at which the proof failed (None: never in the range)."""
    bad = [r[key] for r in rows if not r["passed"]]
    return min(bad) if bad else None


def _last_break(rows: list[dict], key: str):
    bad = [r[key] for r in rows if not r["passed"]]
    return max(bad) if bad else None


def toggle(b: Bench) -> None:
    """Closed form near a toggle: angle error against a 50-digit solution, and where the
    solver stops returning a pose (it flags; it never clips)."""
    import mpmath

    from mechc.physics.closed_form import solve

    part, u_t = stability.toggle_part()
    fr = np.array([0.5, 0.9, 0.99, 0.999, 1 - 1e-4, 1 - 1e-6, 1 - 1e-8, 1 - 1e-10, 1.0,
                   1 + 1e-10, 1 + 1e-6, 1.01])
    u = u_t * fr
    poses = solve(part, {"sl": u}, len(u))
    th = poses.theta["lev"]
    margin = poses.singular_margin["rod"]
    mpmath.mp.dps = 50
    arm, rod = 30, 50
    for f, t, m, bad in zip(fr, th, margin, poses.bad["lev"]):
        x = mpmath.mpf(-rod) + mpmath.mpf(float(u_t)) * mpmath.mpf(float(f))
        # pin P = arm (cos phi, sin phi), |P - E| = rod with E = (x, arm): cos(phi - psi) = c,
        # psi the direction of E; the design pose (phi = 90 deg) is on the minus branch
        d2 = x * x + arm * arm
        ref = None
        c = (arm * arm + d2 - rod * rod) / (2 * arm * mpmath.sqrt(d2))
        if abs(c) <= 1:
            phi = mpmath.atan2(arm, x)
            ref = float(phi - mpmath.acos(c) - mpmath.pi / 2)
        err = abs(float(t) - ref) if (ref is not None and np.isfinite(t)) else math.nan
        b.row(section="toggle", circuit="lever+rod", level="kinematic",
              variant=f"{f:.12g} of the way", error_fraction=err,
              margin_deg=float(m), passed=not bool(bad),
              failure_kinds="flagged" if bad else "")
    ok = [(f, e) for f, e in zip(fr, [r["error_fraction"] for r in b.rows[-len(fr):]])
          if isinstance(e, float) and np.isfinite(e)]
    worst = max(e for _, e in ok)
    flagged = int(np.count_nonzero(poses.bad["lev"]))
    b.say(f"toggle: closed-form angle error up to {worst:.2e} rad at margin "
          f"{float(np.min(margin[np.isfinite(th)])):.2g} deg; {flagged} of {len(u)} states past "
          "the toggle flagged unsolvable (NaN, bad), none clipped")
    b.summary["toggle_worst_angle_error_rad"] = float(f"{worst:.3g}")
    b.summary["toggle_states_flagged"] = flagged


# ---- 5. peers ------------------------------------------------------------------------------
def peers(b: Bench, c: Circuit) -> None:
    b.say("\n== peers in the same run ==")
    try:
        from mechc.bench.fourbar import compare

        r = compare()
    except ModuleNotFoundError as e:
        b.say(f"pylinkage is not installed ({e}); pip install -e '.[bench]'")
        b.summary["kinematic_vs_pylinkage"] = "n/a"
    else:
        fast = r.pylinkage_fast_per_s
        best_peer = max(r.pylinkage_step_per_s, fast or 0.0)
        b.say(f"four-bar: mechc closed form {r.mechc_per_s:,.0f} positions/s; pylinkage "
              f"Linkage.step {r.pylinkage_step_per_s:,.0f}/s, step_fast ({r.pylinkage_backend}) "
              f"{fast or float('nan'):,.0f}/s; rocker pins agree to "
              f"{r.max_difference_mm:.1e} mm")
        kernel = r.numba_kernel_per_s
        b.say(f"floors on the same four-bar, positions only (no angle, transmission, flags or "
              f"closure check): numpy {r.bare_numpy_per_s:,.0f}/s = "
              f"{r.bare_numpy_per_s / best_peer:.2f}x pylinkage's best; compiled scalar loop "
              + (f"{kernel:,.0f}/s = {kernel / best_peer:.2f}x" if kernel else "n/a (no numba)"))
        b.summary["kinematic_vs_pylinkage"] = round(r.mechc_per_s / best_peer, 3)
        b.summary["positions_only_numpy_vs_pylinkage"] = round(r.bare_numpy_per_s / best_peer, 3)
        if kernel:
            b.summary["positions_only_compiled_vs_pylinkage"] = round(kernel / best_peer, 3)
        b.summary["kinematic_vs_pylinkage_step"] = round(r.mechc_per_s / r.pylinkage_step_per_s,
                                                         2)
        b.summary["pylinkage_backend"] = r.pylinkage_backend
        b.summary["fourbar_positions_per_s"] = round(r.mechc_per_s)
        for lvl, rate in (("mechc", r.mechc_per_s), ("pylinkage step", r.pylinkage_step_per_s),
                          ("pylinkage step_fast", fast),
                          ("positions only, numpy", r.bare_numpy_per_s),
                          ("positions only, compiled", kernel)):
            b.row(section="fourbar", circuit="four-bar", level=lvl, cases=r.positions,
                  seconds=(r.positions / rate) if rate else "",
                  error_fraction=r.max_difference_mm)
    # dynamic level against a bare pymunk scene of the same bodies and joints
    d = c.design
    st = dyn_settings(d)
    name = d.spec.inputs[0]
    sc = Scene.build(d.mechanism, b.lib, _types(d), st, {k: 0.0 for k in d.spec.inputs})
    t0 = _clock()
    r = sc.move(name, 1.0)
    t_mechc = _clock() - t0
    bare = Scene.build(d.mechanism, b.lib, _types(d), st, {k: 0.0 for k in d.spec.inputs})
    t0 = _clock()
    for _ in range(r.steps):
        bare.space.step(st.dt)
    t_bare = _clock() - t0
    joints = len(sc.space.constraints)
    per_mechc = t_mechc / (r.steps * joints)
    per_bare = t_bare / (r.steps * joints)
    b.say(f"dynamic ({c.name}, {joints} constraints, {r.steps} steps): "
          f"{per_mechc * 1e9:.0f} ns per joint-step with mechc's measuring and driving, "
          f"{per_bare * 1e9:.0f} ns bare pymunk")
    b.summary["dynamic_vs_bare_pymunk"] = round(per_mechc / per_bare, 3)
    b.row(section="joint_step", circuit=c.name, level="dynamic", variant="mechc",
          steps=r.steps, seconds=t_mechc)
    b.row(section="joint_step", circuit=c.name, level="dynamic", variant="bare pymunk",
          steps=r.steps, seconds=t_bare)


# ---- charts ---------------------------------------------------------------------------------
def pareto(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Points (time, error) no other point beats in both."""
    front, best = [], math.inf
    for t, e in sorted(points):
        if e < best:
            front.append((t, e))
            best = e
    return front


def chart(b: Bench, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.5, 6))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    circuits_seen = sorted({r["circuit"] for r in b.rows if r["section"] in ("grid", "levels")
                            and r["level"] == "dynamic"})
    floor = 1e-6
    for i, name in enumerate(circuits_seen):
        col = colors[i % len(colors)]
        pts = [r for r in b.rows if r["circuit"] == name and r["section"] == "grid"]
        good = [(r["seconds_per_case"], max(floor, r["error_fraction"])) for r in pts
                if r["solver_ok"]]
        bad = [(r["seconds_per_case"], max(floor, r["error_fraction"])) for r in pts
               if not r["solver_ok"]]
        if good:
            ax.scatter(*zip(*good), s=14, color=col, alpha=0.55, label=f"{name}")
            f = pareto(good)
            ax.plot(*zip(*f), color=col, lw=1.5)
        if bad:
            ax.scatter(*zip(*bad), s=18, marker="x", color=col, alpha=0.6)
        for r in b.rows:
            if (r["circuit"] == name and r["section"] == "pruning"
                    and r["variant"] == "pruned"):
                ax.scatter([r["seconds_per_case"]], [max(floor, r["error_fraction"])],
                           marker="^", s=70, color=col, edgecolor="k", zorder=5)
            if r["circuit"] == name and r["section"] == "levels":
                if r["level"] == "dynamic":
                    ax.scatter([r["seconds_per_case"]], [max(floor, r["error_fraction"])],
                               marker="*", s=220, color=col, edgecolor="k", zorder=5)
                elif r["level"] == "kinematic":
                    ax.scatter([r["seconds_per_case"]], [floor], marker="D", s=40, color=col,
                               edgecolor="k", zorder=5)
        if not good and not bad:
            ax.scatter([], [], color=col, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axhline(0.01, color="grey", ls="--", lw=1)
    ax.text(0.01, 0.0108, "1 % of stroke", color="grey", fontsize=8,
            transform=ax.get_yaxis_transform())
    ax.set_xlabel("seconds per input change (kinematic: per state)")
    ax.set_ylabel("output position error vs closed form (fraction of stroke)")
    ax.set_title("mechc: speed against accuracy\n"
                 "dots: dynamic settings grid, x: solver broke, line: Pareto front,\n"
                 "star: defaults, triangle: pruned, diamond: kinematic (exact, drawn at 1e-6)",
                 fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(True, which="both", alpha=0.25)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def stability_chart(b: Bench, study: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(2, 2, figsize=(11, 8.5))
    m = study["map"]
    ks = sorted({r["spring_factor"] for r in m})
    dts = sorted({r["dt_s"] for r in m})
    z = np.full((len(ks), len(dts)), np.nan)
    for r in m:
        z[ks.index(r["spring_factor"]), dts.index(r["dt_s"])] = max(1e-5, r["error_fraction"])
    ax = axs[0, 0]
    im = ax.imshow(np.log10(z), origin="lower", cmap="viridis", aspect="auto", vmin=-4, vmax=0)
    for r in m:
        i, j = ks.index(r["spring_factor"]), dts.index(r["dt_s"])
        mark = "ok" if r["passed"] else _short(r["failure_kinds"])
        ax.text(j, i, mark.replace("/", "\n"), ha="center", va="center", fontsize=6,
                color="k" if np.log10(z[i, j]) > -1.2 else "w")
    ax.set_xticks(range(len(dts)), [f"{d * 1e3:g}" for d in dts])
    ax.set_yticks(range(len(ks)), [f"{k:g}" for k in ks])
    ax.set_xlabel("time step (ms)")
    ax.set_ylabel("spring rate factor (forces x k, damping x sqrt k)")
    ax.set_title("stability map: log10 output error; text = what mechc reported", fontsize=9)
    fig.colorbar(im, ax=ax, fraction=0.046)
    ax = axs[0, 1]
    its = study["iterations"]
    ax.loglog([r["iterations"] for r in its], [max(1e-5, r["max_violation_mm"]) for r in its],
              "o-", label="largest joint stretch (mm)")
    ax.loglog([r["iterations"] for r in its], [max(1e-5, r["error_fraction"]) for r in its],
              "s-", label="output error (fraction)")
    ax.axhline(0.1, color="r", ls="--", lw=1, label="stretch limit 0.1 mm")
    for r in its:
        if not r["passed"]:
            ax.annotate(_short(r["failure_kinds"]), (r["iterations"], r["max_violation_mm"]),
                        fontsize=6, color="r")
    ax.set_xlabel("solver iterations per step")
    ax.set_title("too few iterations", fontsize=9)
    ax.legend(fontsize=7)
    ax = axs[1, 0]
    ms = study["mass"]
    ax.loglog([r["mass_factor"] for r in ms], [max(1e-5, r["error_fraction"]) for r in ms],
              "s-", label="output error (fraction)")
    ax.loglog([r["mass_factor"] for r in ms], [max(1e-5, r["max_violation_mm"]) for r in ms],
              "o-", label="largest joint stretch (mm)")
    for r in ms:
        if not r["passed"]:
            ax.annotate(_short(r["failure_kinds"]), (r["mass_factor"],
                                                     max(1e-5, r["error_fraction"])),
                        fontsize=6, color="r")
    ax.set_xlabel("bar mass factor (against input sliders and levers)")
    ax.set_title("mass ratio", fontsize=9)
    ax.legend(fontsize=7)
    ax = axs[1, 1]
    tg = [r for r in b.rows if r["section"] == "toggle"]
    mg = [r["margin_deg"] for r in tg]
    er = [r["error_fraction"] for r in tg]
    sel = [(x, y) for x, y in zip(mg, er) if x and np.isfinite(y) and x > 0]
    if sel:
        ax.loglog(*zip(*sel), "o-")
    from mechc.physics.measures import MIN_SINGULAR_MARGIN_DEG

    ax.axvline(MIN_SINGULAR_MARGIN_DEG, color="r", ls="--", lw=1)
    ax.text(MIN_SINGULAR_MARGIN_DEG, 0.5, " design check:\n reported below", color="r",
            fontsize=7, transform=ax.get_xaxis_transform())
    ax.set_xlabel("distance from toggle (deg, transmission angle)")
    ax.set_ylabel("closed-form angle error vs 50 digits (rad)")
    flagged = sum(1 for r in tg if r["failure_kinds"] == "flagged")
    ax.set_title(f"toggle: error grows as the margin closes; {flagged} states past it flagged",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})


# ---- main ---------------------------------------------------------------------------------
def run(quick: bool, out: Path, write_model: Path | None) -> dict:
    import json

    t_start = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    b = Bench(load_library(), quick)
    cs = circuits(quick, b.say)
    for c in cs:
        b.say(f"{c.name}: {_cells(c.design)} cells, {len(c.design.spec.inputs)} inputs"
              + (f" [{c.note}]" if c.note else ""))
    levels(b, cs)
    pruning(b, cs)
    grid_rows = grid(b, cs)
    fa = next(c for c in cs if c.name == "full_adder")
    overhead = step_overhead(b, fa)
    model = error_model(grid_rows, overhead, "benchmarks/speed_accuracy.py"
                        + (" --quick" if quick else ""))
    (out / "accuracy_model.json").write_text(json.dumps(model.to_json(), indent=1) + "\n")
    if write_model:
        write_model.write_text(json.dumps(model.to_json(), indent=1) + "\n")
        b.say(f"error model written to {write_model}")
    b.summary["step_overhead_iterations"] = round(overhead, 2)
    study = stability_study(b, fa)
    peers(b, next(c for c in cs if c.name == "random30"))
    write_csv(b.rows, out / "speed_accuracy.csv")
    chart(b, out / "speed_accuracy.png")
    stability_chart(b, study, out / "stability.png")
    b.summary["wall_seconds"] = round(time.perf_counter() - t_start, 1)
    b.say(f"\nwrote {out / 'speed_accuracy.csv'}, {out / 'speed_accuracy.png'}, "
          f"{out / 'stability.png'}, {out / 'accuracy_model.json'}")
    order = ["pruned_speedup", "pruned_all_frozen_speedup", "pruned_solver_speedup",
             "pruned_error_delta", "default_error",
             "default_case_seconds", "kinematic_vs_pylinkage", "kinematic_vs_pylinkage_step",
             "dynamic_vs_bare_pymunk"]
    for k, v in b.summary.items():
        if k not in order:
            print(f"{k}: {v}")
    for k in order:
        if k in b.summary:
            print(f"{k}: {b.summary[k]}")
    return b.summary


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quick", action="store_true",
                   help="smaller grids and fewer changes on the 100-cell circuit (< 5 min)")
    p.add_argument("--out", default=str(ROOT / "benchmarks" / "out"), metavar="DIR",
                   help="directory for the CSV and PNG files (default: benchmarks/out)")
    p.add_argument("--write-model", nargs="?", const=str(MODEL_PATH), default=None,
                   metavar="PATH", help="also write the error model there (default path: the "
                   "package's, which --accuracy reads; a full run writes it unless --no-model)")
    p.add_argument("--no-model", action="store_true", help="never write the package's model")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(p)
    return run_args(p.parse_args(argv))


def run_args(args: argparse.Namespace) -> int:
    """The benchmark as the command line asks for it (``mechc bench`` and the script)."""
    model = args.write_model
    if model is None and not args.quick and not args.no_model:
        model = str(MODEL_PATH)
    if args.no_model:
        model = None
    run(args.quick, Path(args.out), Path(model) if model else None)
    return 0
