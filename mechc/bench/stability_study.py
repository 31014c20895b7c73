"""Where the simulation methods break: the dynamic proof of the full adder against time step x
spring rate, solver iterations and mass ratio (on the variants of :mod:`mechc.bench.stability`),
and the closed form's error as a lever and rod run into their toggle.
"""

from __future__ import annotations

import math

import numpy as np

from mechc.bench import stability
from mechc.bench.circuits import Circuit
from mechc.bench.harness import Bench, clock, failure_kinds, solver_ok
from mechc.physics.closed_form import solve
from mechc.proofs.dynamic import prove_dynamic
from mechc.proofs.settings import dyn_settings


def stability_study(b: Bench, c: Circuit) -> dict:
    b.say("\n== stability (full adder, first 4 changes, strong actuators) ==")
    base = stability.strong_actuators(c.design)
    cases = 4

    def run(d, section, **kw):
        st = dyn_settings(base, **{k: v for k, v in kw.items() if k in ("dt", "iterations")})
        t0 = clock()
        r = prove_dynamic(d, d.spec, b.lib, st, extra=0, max_cases=cases, prune=False,
                          recheck=False)  # timed: the proof at these settings only
        secs = clock() - t0
        vio = r["max_joint_violation_mm"]
        row = b.row(section=section, circuit=c.name, level="dynamic", dt_s=st.dt,
                    iterations=st.iterations, move_time_s=st.move_time,
                    spring_factor=kw.get("k", 1.0), mass_factor=kw.get("m", 1.0),
                    cases=r["cases"], seconds=secs, seconds_per_case=secs / max(1, r["cases"]),
                    error_fraction=r["max_position_error_fraction"], max_violation_mm=vio,
                    passed=r["passed"], solver_ok=solver_ok(r), failure_kinds=failure_kinds(r),
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
            f"{'ok' if r['passed'] else short_kinds(r['failure_kinds'])}" for r in rows))
    toggle(b)
    return {"map": mapping, "iterations": iters, "mass": masses}


def short_kinds(kinds: str) -> str:
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
    import mpmath  # here, not at the top: ``mechc`` loads this module for every command

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

