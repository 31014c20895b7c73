"""Every simulation level (logic, kinematic, dynamic; sequential provers for sequential
circuits) at its default settings on every benchmark circuit: time per case and output error.
"""

from __future__ import annotations

import numpy as np

from mechc.bench.circuits import Circuit
from mechc.bench.harness import Bench, cell_count, clock, failure_kinds, solver_ok, time_dynamic
from mechc.physics.scene import DynSettings
from mechc.proofs.kinematic import prove_kinematic
from mechc.proofs.logic import prove_logic
from mechc.proofs.report import ProofReport
from mechc.proofs.seq_logic import prove_sequential
from mechc.proofs.seq_mechanism import prove_sequential_dynamic, prove_sequential_kinematic
from mechc.proofs.settings import dyn_settings


def levels(b: Bench, cs: list[Circuit]) -> None:
    b.say("\n== levels (defaults) ==")
    errs, per_case = [], []
    for c in cs:
        d = c.design
        try:
            t0 = clock()
            lr = _logic(c)
            tl = clock() - t0
            t0 = clock()
            kr = _kinematic(b, c)
            tk = clock() - t0
            st = dyn_settings(d)
            t0 = clock()
            dr = _sequential_dynamic(b, c, st) if c.sequential else time_dynamic(b, c, st)[0]
            td = clock() - t0
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
              solver_ok=solver_ok(dr), failure_kinds=failure_kinds(dr), steps=dr.get("steps", ""),
              default=True,
              variant="pruned" if dr.get("pruning", {}).get("enabled") else "whole")
        if not kr["passed"]:
            b.say(f"{c.name}: the kinematic proof FAILS ({kr.get('failure_count')} failures)")
        b.say(f"{c.name:11s} {cell_count(d):3d} cells  logic {tl * 1e3:7.1f} ms  kinematic "
              f"{tk:6.3f} s ({states} states and changes)  dynamic "
              f"{dr['cases']:3d} changes {td:6.2f} s = {spc:.3f} s/change, error "
              f"{dr['max_position_error_fraction']:.5f} of stroke, joint "
              f"{dr['max_joint_violation_mm']:.4f} mm, "
              f"{'pass' if dr['passed'] else 'FAIL ' + failure_kinds(dr)}"
              + (f"  [{c.note}]" if c.note else ""))
        b.summary[f"{c.name}_default_error"] = dr["max_position_error_fraction"]
        b.summary[f"{c.name}_default_passed"] = dr["passed"]
        b.summary[f"{c.name}_default_case_seconds"] = round(spc, 4)
    b.summary["default_error"] = max(errs)
    b.summary["default_case_seconds"] = round(float(np.mean(per_case)), 4)


def _logic(c: Circuit) -> ProofReport:
    if c.sequential:
        return prove_sequential(c.design.netlist, c.design.spec)
    return prove_logic(c.design.netlist, c.design.spec)


def _kinematic(b: Bench, c: Circuit) -> ProofReport:
    if c.sequential:
        return prove_sequential_kinematic(c.design, c.design.spec, b.lib)
    return prove_kinematic(c.design, c.design.spec, b.lib)


def _sequential_dynamic(b: Bench, c: Circuit, st: DynSettings) -> ProofReport:
    # timed: the proof at these settings only, as the combinational one (harness.time_dynamic)
    return prove_sequential_dynamic(c.design, c.design.spec, b.lib, st, recheck=False)

