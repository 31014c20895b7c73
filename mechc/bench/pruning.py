"""Pruned scenes against the whole scene at default settings: wall-clock speed-up, the solver's
speed-up alone, and whether the error and the verdict stay the same.
"""

from __future__ import annotations

import math

from mechc.bench.circuits import Circuit
from mechc.bench.harness import (
    Bench,
    cell_count,
    clock,
    failure_kinds,
    scene_types,
    solver_ok,
    time_dynamic,
)
from mechc.physics.scene import Scene
from mechc.proofs.dynamic import PRUNE_DEFAULT, plan
from mechc.proofs.prune import build_scene, plan_case
from mechc.proofs.settings import dyn_settings


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
        repeat = 1 if b.quick and cell_count(c.design) > 50 else 2
        st = dyn_settings(c.design)
        best: dict[str, float] = {}
        reports: dict[str, dict] = {}
        for _ in range(repeat):  # interleaved, best of: the machine is shared
            for key, prune, freeze in variants:
                r, secs = time_dynamic(b, c, st, prune=prune, freeze=freeze)
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
                  solver_ok=solver_ok(r), failure_kinds=failure_kinds(r), steps=r["steps"],
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
    d, mech = c.design, c.design.mechanism
    names = list(d.spec.inputs)
    n = len(names)
    st = dyn_settings(d)
    cur, state = 0, {k: 0.0 for k in names}
    t_whole = t_pruned = 0.0
    for vec in plan(n, 0, 0)[:cases]:
        k = n - (cur ^ vec).bit_length()
        name, target = names[k], float((vec >> (n - 1 - k)) & 1)
        whole = Scene.build(mech, b.lib, scene_types(d), st, dict(state))
        pc = plan_case(d.netlist, mech, b.lib, scene_types(d), state, name, target)
        pruned = build_scene(pc, d.netlist, mech, b.lib, scene_types(d), st, state)
        for sc, acc in ((whole, "w"), (pruned, "p")):
            t0 = clock()
            for _ in range(steps):
                sc.space.step(st.dt)
            if acc == "w":
                t_whole += clock() - t0
            else:
                t_pruned += clock() - t0
        state[name] = target
        cur = vec
    return t_whole / t_pruned if t_pruned > 0 else math.nan

