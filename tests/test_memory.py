"""The MEMORY cell: its detent against a hand calculation, its states in the closed form, and
the pymunk toggle setting, holding, resetting and giving way under too much load."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_bool
from mechc.ir.mechanism import GROUND, Spring
from mechc.ir.netlist import CellInst, Netlist
from mechc.physics.evaluate import evaluate, output_signals
from mechc.physics.scene import DynSettings, Scene
from mechc.pipeline import compile_netlist

LIB = load_library()
TYPES = {"m1": "memory"}


def memory_design(initial: int = 0):
    nl = Netlist(["s", "r"])
    nl.add_cell(CellInst("m1", "memory", "MEMORY", ("s", "r"), ("q",), {"initial": initial}),
                pin_names=["S", "R"], out_pins=["Q"])
    nl.set_output("q", "q")
    # the spec is only the interface here (a MEMORY is not a combinational function)
    return compile_netlist(parse_bool("inputs s r\noutputs q\nq = s & ~r\n"), nl, library=LIB)


def test_detent_torque_matches_a_hand_calculation():
    d = memory_design()
    part = d.mechanism.cells["m1"]
    spring = next(s for s in part.springs if "detent" in s.id)
    lever = next(b for b in part.bodies if b.kind == "lever")
    alpha = math.radians(part.data["alpha_deg"])
    # the spring's end on the lever, turned by alpha about the pivot (clockwise)
    ox, oy = lever.pivot
    rx, ry = spring.pb[0] - ox, spring.pb[1] - oy
    c, s = math.cos(-alpha), math.sin(-alpha)
    px, py = ox + rx * c - ry * s, oy + rx * s + ry * c
    gx, gy = spring.pa
    ell = math.hypot(px - gx, py - gy)
    force = spring.rate * (spring.rest - ell)  # compression pushes the end away from the seat
    ux, uy = (px - gx) / ell, (py - gy) / ell
    torque = (px - ox) * (force * uy) - (py - oy) * (force * ux)  # z of r x F
    assert abs(abs(torque) - part.data["hold_torque_Nmm"]) < 1e-3 * part.data["hold_torque_Nmm"]
    assert torque < 0  # clockwise: towards the on stop, away from upright


def test_closed_form_sets_holds_and_resets():
    mech = memory_design().mechanism
    t = np.linspace(0, 1, 21)
    zero = np.zeros_like(t)
    for prior in (0.0, 1.0):
        st = {"m1": np.full_like(t, prior)}
        p = evaluate(mech, LIB, TYPES, {"s": t, "r": zero}, st)
        q = output_signals(mech, p)["q"]
        assert p.state["m1"][-1] == 1.0 and abs(q[-1] - 1) < 1e-5  # S on: set
        assert p.state["m1"][0] == prior  # S off: holds
        assert np.all(np.diff(q) >= -1e-12)  # the lever only moves towards on
        p = evaluate(mech, LIB, TYPES, {"s": zero, "r": t}, st)
        q = output_signals(mech, p)["q"]
        assert p.state["m1"][-1] == 0.0 and abs(q[-1]) < 1e-5  # R on: reset
    both = evaluate(mech, LIB, TYPES, {"s": np.ones(1), "r": np.ones(1)}, {"m1": np.zeros(1)})
    assert both.bad["m1.toggle"][0]  # S and R together bind the lever: reported, not guessed


def _run(design, load: float | None):
    mech = design.mechanism
    part = mech.cells["m1"]
    if load is not None:  # a soft spring pulling Q towards off with about `load` newtons
        q = part.terminals["Q"]
        k = 1e-4
        stretch = load / k
        part.springs.append(Spring("m1.load", GROUND, q.body, (q.off[0] - stretch - 500, q.off[1]),
                                   q.design_point, k, 500.0, 0.0, load))
    sc = Scene.build(mech, LIB, TYPES, DynSettings(), {"s": 0.0, "r": 0.0})
    out = []
    for name, to in (("s", 1), ("s", 0), ("r", 1), ("r", 0), ("s", 1), ("s", 0)):
        r = sc.move(name, float(to))
        assert r.max_violation < 0.1
        out.append(r.final["q"])
    return out, part.data["rated_load_N"]


def test_dynamic_toggle_sets_holds_resets():
    out, _ = _run(memory_design(), None)
    assert np.allclose(out, [1, 1, 0, 0, 1, 1], atol=0.02), out


@pytest.mark.parametrize("factor,holds", [(0.8, True), (1.6, False)])
def test_holds_its_rated_load_and_gives_way_beyond(factor, holds):
    rated = memory_design().mechanism.cells["m1"].data["rated_load_N"]
    out, _ = _run(memory_design(), factor * rated)
    held = abs(out[1] - 1) < 0.05  # after S is released, Q must stay on
    assert held == holds, (factor, rated, out)
