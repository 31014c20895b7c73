"""An AMPLIFIER or a MEMORY at rest stays at rest. pymunk corrects a stop's overrun towards
none at all, and a slide joint acts only past its limit: a toggle its spring presses onto a
stop ended, by rounding, a hair outside it, the stop let go for a step, and the spring's whole
torque kicked the toggle (about 5 rad/s, its output 0.04 mm) every 70-380 ms. In the 16-bit
adder those kicks, passed on through the gates, kept held outputs off their closed form by up
to 0.011 of the stroke, so no change ever settled before the end of its hold. Stops held with
a slop (:func:`mechc.parts.contact.stiff_stops`) rest a hair in instead. A MEMORY's lever,
thrown onto its stops by its detent and held there the same way, kicked alike."""

from __future__ import annotations

import numpy as np
import pymunk
import pytest

from mechc.bench.circuits import adder2_spec
from mechc.cells.library import load_library
from mechc.frontends.fsm import parse_fsm_file
from mechc.parts.contact import FAR, SLOP, stiff_stops
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import compile_sequential, compile_spec
from tests.helpers import EXAMPLES

LIB = load_library()


@pytest.fixture(scope="module")
def adder2():
    """a1 a0 + b1 b0 + cin = s2 s1 s0, compiled: three amplifiers hold the carries' loads."""
    return compile_spec(adder2_spec())


@pytest.mark.parametrize("state", [0b00000, 0b10110, 0b11111])
def test_held_toggles_do_not_kick(adder2, state):
    """A second at rest: after the first 50 ms (the scene settling from its closed-form start)
    no toggle turns faster than 1 rad/s. Before the stops held with a slop the three toggles
    passed 1 rad/s in 32-70 steps of such a second, in each of these start states."""
    d = adder2
    assert sum(c.type == "AMPLIFIER" for c in d.netlist.cells.values()) >= 2
    names = list(d.spec.inputs)
    start = {nm: float((state >> (len(names) - 1 - k)) & 1) for k, nm in enumerate(names)}
    st = DynSettings()
    types = {c.id: c.cell for c in d.netlist.cells.values()}
    sc = Scene.build(d.mechanism, LIB, types, st, start)
    toggles = [b for bid, b in sc.bodies.items() if bid.endswith(".T")]
    fast = 0
    for step in range(int(1.0 / st.dt)):
        sc.space.step(st.dt)
        if step * st.dt > 0.05:
            fast += sum(abs(t.angular_velocity) > 1.0 for t in toggles)
    assert fast == 0


def test_held_memory_levers_do_not_kick():
    """The speed controller's two MEMORY cells a second at rest from power-up: after the first
    50 ms no part of either moves faster than 30 mm/s (a lever's turn at 30 mm). Before their
    stops held with a slop, one lever (and its output) passed that in 11 steps of the second."""
    d = compile_sequential(parse_fsm_file(EXAMPLES / "speedctl.fsm"))
    mems = {c.id for c in d.netlist.cells.values() if c.type == "MEMORY"}
    assert len(mems) == 2
    st = DynSettings()
    types = {c.id: c.cell for c in d.netlist.cells.values()}
    sc = Scene.build(d.mechanism, LIB, types, st, dict.fromkeys(d.mechanism.inputs, 0.0))
    parts = [b for bid, b in sc.bodies.items()
             if bid.split(".")[0] in mems and b.body_type == pymunk.Body.DYNAMIC]
    fast = 0
    for step in range(int(1.0 / st.dt)):
        sc.space.step(st.dt)
        if step * st.dt > 0.05:
            fast += sum(b.velocity.length + 30.0 * abs(b.angular_velocity) > 30.0
                        for b in parts)
    assert fast == 0


def _pressed_body(x0: float, force: float) -> tuple[int, float]:
    """A 20 g body on a groove, a constant ``force`` (N, pymunk units) pressing it onto a
    contact at ``x0`` (mm), its stops made stiff as the amplifier's toggle, one second: the
    steps it moved faster than 1 mm/s after the first 50 ms, and how far in it rests."""
    dt = 2.5e-4
    sp = pymunk.Space()
    sp.iterations = 60
    body = pymunk.Body(0.02, pymunk.moment_for_circle(0.02, 0.0, 5.0))
    body.position = (x0, 0.0)
    sp.add(body, pymunk.GrooveJoint(sp.static_body, body, (x0 - 100.0, 0.0),
                                    (x0 + 100.0, 0.0), (0.0, 0.0)))
    stop = pymunk.SlideJoint(sp.static_body, body, (x0 + FAR, 0.0), (0.0, 0.0), FAR,
                             FAR + 1000.0)  # as mechc.parts.contact builds a stop
    sp.add(stop)
    stiff_stops(sp, body)
    kicks = 0
    for i in range(int(1.0 / dt)):
        body.apply_force_at_local_point((force, 0.0))
        sp.step(dt)
        kicks += i * dt > 0.05 and abs(body.velocity.x) > 1.0
    return kicks, body.position.x - x0


def test_a_stop_held_with_a_slop_never_lets_go():
    """Wherever the stop stands (rounding differs) and however hard the body is pressed, a
    stop held with a slop never lets the body go, and holds it in by at most ``SLOP``."""
    for x0 in np.linspace(0.0, 2000.0, 9):
        for force in (200.0, 2000.0):
            kicks, rest = _pressed_body(float(x0), force)
            assert kicks == 0, (x0, force)
            assert 0.0 < rest <= SLOP * 1.001, (x0, force, rest)
