"""Where the methods break, mechc says so (docs/performance.md): each test drives a method past its
limit and asserts the specific failure the proof reports, next to a control run that passes — so a
test fails both if the detection is removed and if it fires on a sound run.

Where each breaks is measured by ``benchmarks/speed_accuracy.py`` (stability.png); the cases
here are taken well past those limits so they do not sit on a knife edge.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from mechc.bench import stability
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.physics.closed_form import solve
from mechc.physics.measures import MIN_SINGULAR_MARGIN_DEG
from mechc.pipeline import compile_spec
from mechc.proofs.dynamic import prove_dynamic
from mechc.proofs.settings import dyn_settings
from tests.helpers import EXAMPLES

LIB = load_library()
CASES = 4  # the first changes of the full adder's Gray tour


@pytest.fixture(scope="module")
def adder():
    return stability.strong_actuators(compile_spec(load_spec(EXAMPLES / "full_adder.bool")))


def run(d, **kw):
    st = dyn_settings(d, **kw)
    return prove_dynamic(d, d.spec, LIB, st, extra=0, max_cases=CASES, prune=False,
                         recheck=False)  # the failures at these settings are the subject


# ---- kinematic closed forms at a toggle --------------------------------------------------------
def test_closed_form_flags_states_past_a_toggle_and_never_clips():
    part, u_t = stability.toggle_part(arm=30.0, rod=50.0)
    fr = np.array([0.0, 0.5, 0.9, 0.99, 0.9999, 1.0001, 1.01, 1.2])
    poses = solve(part, {"sl": u_t * fr}, len(fr))
    th, bad = poses.theta["lev"], poses.bad["lev"]
    margin = poses.singular_margin["rod"]
    before, past = fr < 1, fr > 1
    # past the toggle the loop cannot close: no angle, marked bad (a clipped arccos would give
    # a finite angle here)
    assert np.isnan(th[past]).all() and bad[past].all()
    assert np.isfinite(th[before]).all() and not bad[before].any()
    # approaching it the reported distance from toggle shrinks to nothing, and the design check
    # limit catches the last states before it
    m = margin[before]
    assert np.all(np.diff(m) < 0) and m[0] == pytest.approx(90.0) and m[-1] < 1.0
    assert (m < MIN_SINGULAR_MARGIN_DEG).sum() == 2  # 0.99 (8.9°) and 0.9999 (0.9°)


def test_closed_form_agrees_with_an_independent_root_find_up_to_the_toggle():
    """Loop closure |pin - slider end| = rod solved by bracketing (scipy brentq) on the lever
    angle: the closed form agrees to 1e-9 rad even 1e-4 of the travel before the toggle."""
    arm, rod = 30.0, 50.0
    part, u_t = stability.toggle_part(arm, rod)
    fr = np.array([0.2, 0.7, 0.95, 0.999, 0.9999])
    th = solve(part, {"sl": u_t * fr}, len(fr)).theta["lev"]
    for f, t in zip(fr, th):
        x = -rod + u_t * f

        def closure(a, x=x):
            px, py = -arm * math.sin(a), arm * math.cos(a)  # pin, lever turned by a from up
            return math.hypot(px - x, py - arm) - rod

        # the design branch: the pin swings left (positive a) as the slider pulls left, until
        # it lies on the line from the pivot to the slider end (rod and arm in line); the
        # distance to the end falls monotonically on the way, so the root is bracketed once
        a_line = math.atan2(arm, x) - math.pi / 2
        ref = brentq(closure, 0.0, a_line, xtol=1e-15)
        assert t == pytest.approx(ref, abs=1e-9)


# ---- pymunk past its limits ------------------------------------------------------------------
def test_control_run_passes(adder):
    r = run(adder)
    assert r["passed"], r["failures"]


def test_too_large_time_step_is_detected_as_solver_error(adder):
    """dt = 2 ms (8x the default): joints stretch past 0.5 % of stroke; the proof fails with
    'solver' failures naming the joint, never passes."""
    r = run(adder, dt=2e-3)
    assert not r["passed"]
    assert r["failure_kinds"].get("solver", 0) >= 1
    msg = next(f["message"] for f in r["failures"] if f["kind"] == "solver")
    assert "stretched" in msg and r["max_joint_violation_mm"] > r["settings"][
        "violation_limit_mm"]


def test_too_few_solver_iterations_are_detected(adder):
    """One iteration per step (measured break: <= 3 on this circuit)."""
    r = run(adder, iterations=1)
    assert not r["passed"]
    assert r["failure_kinds"].get("solver", 0) >= 1


def test_stiff_springs_break_the_step_and_are_detected(adder):
    """Spring forces x10 (same equilibria): at the default 0.25 ms step a contact is overrun
    (reported 'contact'); at 0.1 ms the same mechanism passes, so it is the step, not the
    mechanism."""
    stiff = stability.stiffen(adder, 10.0)
    coarse = run(stiff)
    assert not coarse["passed"]
    assert coarse["failure_kinds"].get("contact", 0) >= 1
    assert coarse["max_contact_penetration_mm"] > coarse["settings"]["penetration_limit_mm"]
    fine = run(stiff, dt=1e-4)
    assert fine["passed"], fine["failures"]


def test_extreme_mass_ratio_is_detected(adder):
    """Output bars 10^4 times lighter than the rest: the bars never come to rest within the hold
    time ('settle') and outputs end away from the closed form."""
    r = run(stability.scale_masses(adder, 1e-4))
    assert not r["passed"]
    assert r["failure_kinds"].get("settle", 0) >= 1
