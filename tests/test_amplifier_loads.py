"""AMPLIFIER driving heavy loads: the toggle spring's snap past dead centre must not slam the
output onto its stop (the 2-bit adder's force amplifiers landed at 15x the driven speed, the
output slider at 5.4 m/s, and overran their loads' contacts by 1.2 mm). Closed forms against an
independent integration of T's motion, and the pymunk model of an amplifier whose loads hold
still while it switches (nothing but its dashpot takes the snap)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_bool
from mechc.ir.mechanism import Demand, SynthContext
from mechc.ir.netlist import CellInst, Netlist
from mechc.passes.assemble import MechOptions
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import CompileOptions, compile_netlist

LIB = load_library()
CTX = SynthContext()
#: an output that must hold about 100 N either way: two AND inputs whose springs hold ~40 N
#: each, as on the 2-bit adder's carry input (its amplifier a12 needed 5034 N mm of hold)
HEAVY = Demand(100.0, 100.0)


def _toggle_torque(theta: float, d: dict) -> float:
    """Counter-clockwise torque (N mm) on T, from the spring's endpoints: E on T at radius e
    (above Q at theta = 0), G fixed at g below Q; torque = (E - Q) x force on E."""
    e, g = d["toggle_e"], d["toggle_g"]
    ex, ey = -e * math.sin(theta), e * math.cos(theta)  # E relative to Q
    dx, dy = ex, ey + g  # G -> E
    length = math.hypot(dx, dy)
    f = d["toggle_rate"] * (length - d["toggle_rest"])  # tension pulls E towards G
    fx, fy = -f * dx / length, -f * dy / length
    return ex * fy - ey * fx


def _land(d: dict, inertia: float, dashpot: float) -> float:
    """T's speed (rad/s) on reaching its on stop, integrated from dead centre at the roller
    speed: spring torque plus the loads pushing with their whole demand, the dashpot on the
    output slider (arm r_o cos theta, rod level), ``inertia`` of T and its output (kg mm^2)."""
    w0 = d["speed"] * d["r_r"] / d["rc"]

    def rhs(_t, y):
        theta, w = y
        arm = d["r_o"] * math.cos(theta)
        torque = _toggle_torque(theta, d) + d["load_torque"] - dashpot * w * arm * arm
        return [w, torque * 1000.0 / inertia]  # N mm -> kg mm^2 / s^2

    hit = lambda _t, y: y[0] - d["theta_on"]  # noqa: E731
    hit.terminal = True
    r = solve_ivp(rhs, (0.0, 1.0), [0.0, w0], events=hit, max_step=1e-4, rtol=1e-8)
    assert r.status == 1, "T never reached its stop"
    return float(r.y_events[0][0][1])


def _inertia(part) -> float:
    """T (its own mass at half C's radius, as the cell's damping uses) and the output slider
    at the crank's smallest arm."""
    d = part.data["design"]
    t = next(b for b in part.bodies if b.role == "output toggle")
    out = next(b for b in part.bodies if b.role == "AMPLIFIER output")
    arm = d["r_o"] * math.cos(d["theta_on"])
    return t.mass * (0.5 * d["rc"]) ** 2 + out.mass * arm * arm


def test_landing_check_flags_an_undamped_heavy_amplifier_and_bounds_the_damped_one():
    from mechc.stdlib.amplifier import (
        LANDING_RATIO,
        MAX_LANDING_RATIO,
        SNAP_WORK_LIMIT,
        AmpDesign,
        landing_speed,
        roller_matched_speed,
        snap_work,
    )

    cls = LIB["amplifier"]
    # without a dashpot the heavy design fails its landing check, the light one has none to
    # fail (and gets no dashpot)
    bare = cls.synthesise("a", CTX, 1, {"landing_ratio": 0}, HEAVY)
    (slam,) = cls.checks("a", bare, CTX)
    assert slam.where == "amplifier a" and "slam" in slam.name
    assert slam.value == snap_work(AmpDesign(**bare.data["design"])) > SNAP_WORK_LIMIT
    assert slam.limit == SNAP_WORK_LIMIT and not slam.passed
    light = cls.synthesise("a", CTX, 1, {}, Demand(0.5, 0.5))
    assert light.data["design"]["dashpot"] == 0.0
    assert light.data["snap_work_N_mm"] <= SNAP_WORK_LIMIT
    assert cls.checks("a", light, CTX) == []
    part = cls.synthesise("a", CTX, 1, {}, HEAVY)
    d = part.data["design"]
    (landing,) = cls.checks("a", part, CTX)
    amp = AmpDesign(**d)
    assert landing.value == landing_speed(amp) / roller_matched_speed(amp) <= MAX_LANDING_RATIO
    assert landing.passed
    # a dashpot sized for more than MAX_LANDING_RATIO x the driven speed fails the check
    loose = cls.synthesise("a", CTX, 1, {"landing_ratio": 2 * MAX_LANDING_RATIO}, HEAVY)
    (too_fast,) = cls.checks("a", loose, CTX)
    assert too_fast.value > MAX_LANDING_RATIO and not too_fast.passed
    # the snap work against an independent quadrature of the spring torque from its endpoints
    half = max(d["theta_on"], -d["theta_off"])
    grid = np.linspace(0.0, half, 2001)
    energy = abs(np.trapezoid([_toggle_torque(t, d) for t in grid], grid))
    assert snap_work(AmpDesign(**d)) == pytest.approx(energy + d["load_torque"] * half, rel=1e-4)
    assert snap_work(AmpDesign(**d)) > 10 * SNAP_WORK_LIMIT
    # independent integration of T's motion: undamped, the heavy design lands at > 10 x the
    # roller speed; its dashpot brings that under LANDING_RATIO, within the closed-form bound,
    # and heavier moving parts (the loads) only slow it
    w0 = d["speed"] * d["r_r"] / d["rc"]
    inertia = _inertia(part)
    assert _land(d, inertia, 0.0) > 10.0 * w0
    for m in (inertia, 5 * inertia):
        damped = _land(d, m, d["dashpot"])
        assert damped <= LANDING_RATIO * w0
        assert damped <= landing_speed(AmpDesign(**d)) * (1 + 1e-9)


def _and_pair(params: dict | None = None):
    """An amplifier on input a driving two ANDs with input b; the ANDs' outputs carry 20 N so
    the amplifier must hold about what the adder's a12 holds (the ANDs need no amplifier: b's
    actuator is rated 1 kN). ``params``: the amplifier's."""
    nl = Netlist(["a", "b"])
    nl.add_cell(CellInst("amp", "amplifier", "AMPLIFIER", ("a",), ("y",), params or {}),
                pin_names=["A"])
    for i in range(2):
        nl.add_cell(CellInst(f"g{i}", "and", "AND", ("y", "b"), (f"z{i}",)),
                    pin_names=["A", "B"])
        nl.set_output(f"z{i}", f"z{i}")
    spec = parse_bool("inputs a b\noutputs z0 z1\nz0 = a & b\nz1 = a & b\n")
    opts = CompileOptions(mech=MechOptions(actuator_force=1000.0, output_load=20.0),
                          amplify=False)
    return compile_netlist(spec, nl, opts, library=LIB)


def test_an_undamped_heavy_amplifier_fails_the_design_checks():
    """The landing rule is a design check of the compiled design, not an exception."""
    from mechc.stdlib.amplifier import SNAP_WORK_LIMIT

    checks = _and_pair({"landing_ratio": 0}).mechanism.checks
    # the strength checks also find its toggle spring and its crank arm too weak for this load:
    # see test_switching_with_its_loads_held_still_does_not_slam_the_output
    failed = [c for c in checks if not c.passed and c.where not in ("amp.toggle17", "amp.T")]
    assert [(c.where, "slam" in c.name) for c in failed] == [("amplifier amp", True)]
    assert failed[0].value > SNAP_WORK_LIMIT == failed[0].limit


def test_switching_with_its_loads_held_still_does_not_slam_the_output():
    """b off holds both AND bars off, so the amplifier's output moves nothing but the ANDs'
    input sliders: all the snap of a ~100 N toggle goes into T and its output (the adder's
    a12 on cin -> 0). Before the dashpot T reached 17-35 x its driven speed and its loads'
    contacts were overrun by up to 2.3 mm."""
    d = _and_pair()
    # every design check passes but two strength checks, findings about the amplifier at loads
    # this heavy, pinned here: holding 5.2 N m over its short toggle arm, the toggle spring
    # needs 2.2 kN/mm and 2.9 kN at dead centre, which no music-wire coil of 6 mm or less (and
    # 3 coils or more) gives; and T's 6 x 3 mm crank arm (38.6 mm) bends at 231 MPa
    failed = d.stats["design_checks"]["failed"]
    assert [f.split(":")[0] for f in failed] == [
        "lever bending (38.6 mm arm) at amp.T",
        "spring wire stress (6 mm music wire) at amp.toggle17"], failed
    dd = d.mechanism.cells["amp"].data["design"]
    assert dd["hold_required"] > 3000.0  # really a heavy toggle (N mm)
    types = {c.id: c.cell for c in d.netlist.cells.values()}
    st = DynSettings(violation_limit=0.005 * d.mechanism.ctx.stroke)
    sc = Scene.build(d.mechanism, LIB, types, st, {"a": 1.0, "b": 0.0})
    tb = sc.bodies["amp.T"]
    w0 = dd["speed"] * dd["r_r"] / dd["rc"]
    # not measured: a scene starts with each AND bar's 45 N spring against a hook that is just
    # touching, and pymunk's slide-joint contact acts only once overrun, so the 2.4 g bar
    # jumps 1.2 mm into it in the first step (the cells' model, amplifier or not)
    sc.move("a", 0.0)
    fastest = 0.0
    orig = sc.space.step

    def step(dt):
        nonlocal fastest
        orig(dt)
        fastest = max(fastest, abs(tb.angular_velocity))

    sc.space.step = step
    for target in (1.0, 0.0):
        r = sc.move("a", target)
        assert r.max_penetration <= st.penetration_limit, (target, r.max_penetration)
        assert r.max_violation <= st.violation_limit, (target, r.worst_joint, r.max_violation)
        assert math.isfinite(r.settle_time)
        assert np.allclose([r.final["z0"], r.final["z1"]], 0.0, atol=0.05)
        stop = dd["theta_on"] if target else dd["theta_off"]
        assert abs(tb.angle - stop) < math.radians(1.0)  # T swung (its output drives no output)
    assert fastest <= 4.0 * w0, fastest / w0
