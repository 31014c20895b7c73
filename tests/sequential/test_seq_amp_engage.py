"""An AMPLIFIER whose input snaps in like a MEMORY output: its wedge must lock and drive.

In the seed-204 random flow table (7 rows) the AMPLIFIER on memory output y2 did not switch:
its input arrived at ~600 mm/s, the friction roller F1 rolled 0.5 mm into the wedge instead of
locking, reached its slot end, and the drive died (details in ``mechc.stdlib.amplifier``, function
``_add_wedge_clutches``). These tests drive a lone amplifier the same way (input at constant
speed into its end, then held) with the loads a4 had (an OR and an AND-NOT input; one more AND
for a fan-out of 3) and check the physics of the wedge against closed forms:

- the idler between R and C rolls on both (001 §2.6, Fig. 17), so while the wedge drives, C's
  surface speed equals R's: T turns at ``speed * r_r / rc`` (equal surface speeds);
- the wedge is one-way: past dead centre the toggle spring may carry T faster than that;
- every switch lands T on the stop its input selects.
"""

from __future__ import annotations

import math

import pytest

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_bool
from mechc.ir.netlist import CellInst, Netlist
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import compile_netlist

LIB = load_library()
GATES = {"or": ("or", "OR"), "and_not": ("and_not", "AND_NOT"), "and": ("and", "AND")}


def amplifier_with_loads(loads: tuple[str, ...], params: dict | None = None):
    """AMPLIFIER a -> ya; each load a two-input gate (x, ya) with x held on, so every load's
    input spring acts on ya."""
    nl = Netlist(["a", "x"])
    nl.add_cell(CellInst("amp", "amplifier", "AMPLIFIER", ("a",), ("ya",), params or {}),
                pin_names=["A"])
    outs = []
    for i, kind in enumerate(loads):
        cell, typ = GATES[kind]
        nl.add_cell(CellInst(f"g{i}", cell, typ, ("x", "ya"), (f"z{i}",)), pin_names=["A", "B"])
        nl.set_output(f"z{i}", f"z{i}")
        outs.append(f"z{i}")
    text = "inputs a x\noutputs " + " ".join(outs) + "\n" + "".join(f"{o} = a\n" for o in outs)
    return compile_netlist(parse_bool(text), nl, library=LIB)


def snap_cycles(design, speed: float, cycles: int = 3, hold: float = 0.15):
    """Drive input a on and off ``cycles`` times at a constant ``speed`` (mm/s) into its ends,
    each end held ``hold`` s. Per switch: T's final angle, its mean speed over the driven swing
    (from 2 deg off its stop to half-way to dead centre) and its largest speed past dead
    centre before the relief (signed in the switching sense)."""
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    st = DynSettings()
    sc = Scene.build(design.mechanism, LIB, types, st, {"a": 0.0, "x": 1.0})
    d = design.mechanism.cells["amp"].data["design"]
    servo, _ = sc.servos["a"]
    tb = sc.bodies["amp.T"]
    S = design.mechanism.ctx.stroke
    pos, out = 0.0, []
    for k in range(2 * cycles):
        on = k % 2 == 0
        sense = 1.0 if on else -1.0
        start, target = (d["theta_off"], S) if on else (d["theta_on"], 0.0)
        a0 = sense * (start + sense * math.radians(2.0))  # angles in the switching sense
        a1 = sense * start / 2
        relief = sense * ((d["theta_on"] if on else d["theta_off"]) - sense * d["coast"])
        t = 0.0
        t0 = t1 = None
        past = 0.0
        for _ in range(int((S / speed + hold) / st.dt)):
            step = math.copysign(min(speed * st.dt, abs(target - pos)), target - pos)
            pos += step
            servo.velocity = (step / st.dt, 0.0)
            before = sense * tb.angle
            sc.space.step(st.dt)
            t += st.dt
            now = sense * tb.angle
            if t0 is None and before < a0 <= now:
                t0 = t
            if t1 is None and before < a1 <= now:
                t1 = t
            if 0.0 < now < relief:
                past = max(past, sense * tb.angular_velocity)
        mean = (a1 - a0) / (t1 - t0) if t0 is not None and t1 is not None else 0.0
        out.append((on, tb.angle, mean, past))
    return out, d


@pytest.mark.parametrize("loads, speed", [(("or", "and_not"), 600.0),
                                          (("or", "and_not"), 1000.0),
                                          (("or", "and_not", "and"), 200.0),
                                          (("or", "and_not", "and"), 600.0)])
def test_snapped_input_locks_the_wedge_and_switches(loads, speed):
    design = amplifier_with_loads(loads)
    assert design.stats["design_checks"]["passed"], design.stats["design_checks"]["failed"]
    switches, d = snap_cycles(design, speed)
    omega = abs(d["speed"]) * d["r_r"] / d["rc"]  # idler: C's surface speed = R's
    for on, angle, mean, past in switches:
        stop = d["theta_on"] if on else d["theta_off"]
        # lands on its stop (0.5 deg of T's 30 deg swing: the output within 2 % of its stroke)
        assert abs(angle - stop) < math.radians(0.5), (on, math.degrees(angle))
        # driven by the locked wedge: the roller-matched speed, neither a stall nor a kick
        # from the input ramming the idler (which drove T at up to 2.4 x this before the fix)
        assert mean == pytest.approx(omega, rel=0.15), (on, mean / omega)
        # one-way: past dead centre the toggle spring carries T ahead of the rollers
        assert past > 1.05 * omega, (on, past / omega)


def test_stopped_rollers_lock_nothing():
    """Rollers at rest (speed 0): the wedge has nothing to transmit, T stays off."""
    design = amplifier_with_loads(("or",), {"speed": 0.0})
    switches, d = snap_cycles(design, 600.0, cycles=1)
    assert abs(switches[0][1] - d["theta_off"]) < math.radians(0.5)
