"""Designs pushed towards where the simulation methods break, for the stability map and tests.

Each variant keeps the statics the kinematic reference assumes and changes only what the
numerics feel, so a failing proof is the method failing, not the mechanism:

- :func:`stiffen` multiplies every spring's rate by ``k`` at the same rest length (so every force
  scales by ``k`` and the equilibria stay where they were) and its damping by √k (the same
  damping ratio); natural frequencies rise by √k, and an explicit spring force then needs a
  √k times smaller step;
- :func:`scale_masses` multiplies the masses of the cells' bars (the output members) by ``m``:
  a light bar between springs and stops is a stiff system for the step, a heavy one a poorly
  conditioned one for the iterative joint solver;
- :func:`toggle_part` is a lever driven by a rod from a slider whose travel runs into the
  toggle (rod and lever arm in line): the closed form's discriminant goes to zero there.

Actuators are made strong (:func:`strong_actuators`) so that a stall never hides what is being
measured.
"""

from __future__ import annotations

import copy
import math

from mechc.ir.design import Design
from mechc.ir.mechanism import Body, Joint, Part


def strong_actuators(d: Design, rated_N: float = 1e6) -> Design:
    out = copy.deepcopy(d)
    for a in out.mechanism.actuators.values():
        a["rated_force_N"] = rated_N
    return out


def stiffen(d: Design, k: float) -> Design:
    out = strong_actuators(d)
    for part in out.mechanism.cells.values():
        for s in part.springs:
            s.rate *= k
            s.damping *= math.sqrt(k)
    return out


def scale_masses(d: Design, m: float) -> Design:
    out = strong_actuators(d)
    for part in out.mechanism.cells.values():
        for b in part.bodies:
            if "bar" in b.id.rsplit(".", 1)[-1]:
                b.mass *= m
    return out


def toggle_part(arm: float = 30.0, rod: float = 50.0) -> tuple[Part, float]:
    """A lever (pivot at the origin, arm ``arm``) whose pin is pulled by a rod of length ``rod``
    from a horizontal slider. Returns the part and the slider displacement ``u_toggle`` at
    which rod and arm fall in line (the loop's discriminant is zero); beyond it the parts
    cannot assemble. Design pose: arm vertical, slider end at (x0, arm)."""
    x0 = -rod  # slider end straight left of the pin: the rod horizontal
    pin = (0.0, arm)
    lever = Body("lev", "lever", [[(0.0, 0.0), pin, (2.0, arm)]], 0.01, pivot=(0.0, 0.0))
    slider = Body("sl", "slider", [[(x0 - 5, arm - 2), (x0 + 5, arm - 2), (x0 + 5, arm + 2),
                                    (x0 - 5, arm + 2)]], 0.01, axis=(1.0, 0.0))
    j = Joint("rod", "rod", "sl", "lev", pa=(x0, arm), pb=pin, length=rod)
    # in line: slider end, pin and pivot collinear, pin on the far side: |end - pivot| =
    # rod + arm, the end on the line y = arm -> x = -sqrt((rod + arm)^2 - arm^2)
    x_toggle = -math.sqrt((rod + arm) ** 2 - arm * arm)
    return Part([slider, lever], [j]), x_toggle - x0
