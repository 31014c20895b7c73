"""The 3-bar linkage gate of ``000_…`` as library cells: AND, and the same linkage mirrored, OR.

Two input links, one from each input slider, meet at a middle joint M; an output link joins M to
the output slider on the axis between them. The lengths come from
:mod:`mechc.linkage_synthesis.three_bar_gate` (closed form, confirmed numerically), so the
output sits at the same place for FF, FT and TF and moves one full stroke for TT: an AND gate.
Mirrored left to right, "false" and "true" swap at every terminal and the same linkage is an OR
gate (the blog's "the linkages are just reversed"), with every terminal still moving +x from off
to on.

The gate is bilateral: no spring and no one-sided contact, the links drive the output both ways
and the output's load comes back on *both* inputs, including the one standing still. Its input
loads are therefore the output force times the velocity ratio dO/da over every reachable input
state (virtual work), not just along the motion that switches the output.

The 3-bar gate does not dwell perfectly: between FF and FT the output leaves its rest position
and comes back (the "wander": at least 5.8 % of stroke peak to peak over the healthy designs with
sep/stroke 0.2-0.7, from a scan of the synthesis's closed form). The chosen geometry keeps
the excursion *beyond* the output's end of travel (where a downstream bar meets its over-travel
stop, 2 % of stroke) at about 1.5 % and lets the inward excursion, which a downstream output
shows as a glitch, take the rest (about 4.6 %); both numbers are in the part's
``data["three_bar"]`` and the kinematic and dynamic proofs measure them.

That inward wander is almost all of the glitch the proofs see against their 5 % tolerance. For
``examples/sorter.bool --use-cell three_bar_and``, the kinematic proof gives 4.65 % and the
dynamic proof 4.80-4.82 %. The extra 0.15-0.23 % comes from the dynamic model: a rest offset
left by joint stretch of about 0.04 mm (0.2 % of a 20 mm stroke), plus inertia. With 0.32 s
moves instead of 0.08 s it falls to 0.05 %. Making the links wider or narrower changes it by
less than 0.05 %. The geometry can only trade one margin for another:

* against transmission angle: inward 4.52 % at 45.8 deg (sep 0.305, output 2.75);
* against over-travel: inward 4.48 % with 1.80 % outward (sep 0.3125, output 2.19).

The chosen point keeps 48.1 deg and 0.5 % of over-travel. More room needs a larger over-travel
in the bar cells, or a faster-settling dynamic model.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from mechc.cells.builder import Builder, rect
from mechc.cells.cell import Cell
from mechc.errors import DesignError
from mechc.ir.mechanism import Body, Demand, Joint, Point, SynthContext
from mechc.linkage_synthesis import three_bar_gate as tb

# Geometry as fractions of the stroke (the gate scales exactly). Chosen from a scan of healthy
# designs (transmission >= 45 deg, link ratio >= 1/3): the least inward wander whose outward
# excursion stays within 3/4 of the 2 % over-travel of the stdlib bars. See docs/write-a-cell.md.
SEP_RATIO = 0.32  # half the distance between the input pins / stroke
OUTPUT_RATIO = 2.31  # output joint O in state FF, measured from the input pins / stroke
LINK_WIDTH = 0.5  # width of the input links / bar width


@lru_cache(maxsize=64)
def gate_design(stroke: float, sep_ratio: float = SEP_RATIO,
                output_ratio: float = OUTPUT_RATIO) -> tuple[tb.ThreeBarDesign, tb.ThreeBarReport]:
    """The synthesised gate for one stroke, or a DesignError naming the numbers that fail."""
    sep, xo = sep_ratio * stroke, output_ratio * stroke
    ans = tb.synthesise(sep, stroke, output=xo, alternatives=False)
    if not ans.healthy or ans.design is None:
        raise DesignError(f"three_bar: no healthy 3-bar gate for stroke {stroke:g} mm, "
                          f"sep {sep:g} mm, output at {xo:g} mm: {ans.reason}")
    return ans.design, ans.report


def wander_profile(design: tb.ThreeBarDesign, samples: int = 801) -> tuple[float, float]:
    """(inward, outward) excursion of the output, % of stroke, while one input moves and the
    other is off (FF-FT; TF mirrors it): inward is towards the output's other end."""
    s = design.stroke
    st = tb.kinematics(design, 0.0, np.linspace(0.0, s, samples))
    dev = (st.output - st.output[0]) / s * 100.0
    return float(max(dev.max(), 0.0)), float(max(-dev.min(), 0.0))


def velocity_ratios(design: tb.ThreeBarDesign, n: int = 41) -> tuple[np.ndarray, np.ndarray]:
    """dO/da and dO/db over the whole input square [0, stroke]^2 (central differences of the
    closed form); by virtual work the force on each input is the output force times these."""
    s = design.stroke
    g = np.linspace(0.0, s, n)
    a, b = np.meshgrid(g, g)
    h = 1e-6 * s

    def out(x, y):
        return tb.kinematics(design, x, y).output

    return ((out(a + h, b) - out(a - h, b)) / (2 * h),
            (out(a, b + h) - out(a, b - h)) / (2 * h))


def input_loads(design: tb.ThreeBarDesign, demand: Demand, friction: float) -> list[Demand]:
    """What inputs A and B must deliver each way, over every state: the output may have to push
    (demand.right) or pull (demand.left) plus its own guide friction, in any state."""
    fr, fl = demand.right + friction, demand.left + friction
    out = []
    for c in velocity_ratios(design):
        pos, neg = np.maximum(c, 0.0), np.maximum(-c, 0.0)
        right = float(np.max(np.maximum(fr * pos, fl * neg)))
        left = float(np.max(np.maximum(fr * neg, fl * pos)))
        out.append(Demand(right, left))
    return out


def _bar(p: Point, q: Point, width: float) -> list[Point]:
    """A straight link of ``width`` from p to q (a rectangle along the line)."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    n = math.hypot(dx, dy)
    ox, oy = -dy / n * width / 2, dx / n * width / 2
    return [(p[0] + ox, p[1] + oy), (q[0] + ox, q[1] + oy), (q[0] - ox, q[1] - oy),
            (p[0] - ox, p[1] - oy)]


def build_gate(b: Builder, design: tb.ThreeBarDesign, mirror: bool) -> dict:
    """The linkage on builder ``b`` at the design pose (both inputs at half stroke).

    Inputs A (row 0) and B (row -pitch) carry the pins at (x_pin, axis +- sep); the gate's x
    runs +x (AND) or -x (OR, ``mirror``) from them. Returns the world points it placed."""
    ctx = b.ctx
    S, w, p = ctx.stroke, ctx.bar, ctx.pitch
    sep, m, xo = design.sep, design.m, design.output_position
    yc = -p / 2  # the gate's axis, half-way between the input rows
    sgn = -1.0 if mirror else 1.0
    # room on the left for the mirrored output slider at its off end
    x_pin = xo + S / 2 + w if mirror else 1.0 * S
    pin_a, pin_b = (x_pin, yc + sep), (x_pin, yc - sep)
    M = (x_pin + sgn * m, yc)
    O = (x_pin + sgn * xo, yc)
    a = b.input_slider("A", 0.0, 0.0, x_pin + w / 2)
    bb = b.input_slider("B", 0.0, -p, x_pin + w / 2)
    for sig, pin in ((a, pin_a), (bb, pin_b)):  # a lug from the slider's row to its pin
        b.extend(sig.body, rect(x_pin - w / 2, sig.y, x_pin + w / 2, pin[1]))
    wl = LINK_WIDTH * w
    links = []
    for local, pin, layer in (("link_a", pin_a, 1), ("link_b", pin_b, 2)):
        poly = _bar(pin, M, wl)
        mid = ((pin[0] + M[0]) / 2, (pin[1] + M[1]) / 2)
        b.part.bodies.append(Body(b.name(local), "link", [poly], ctx.mass([poly]), pivot=mid,
                                  layer=layer, role="3-bar input link"))
        links.append(b.name(local))
    if mirror:  # the output runs back under the links to the right edge, on its own plane
        out = b.slider("out", O[0] - w / 2, x_pin + w + 0.6 * S, yc, "3-bar output", layer=3)
    else:
        out = b.slider("out", O[0] - w / 2, O[0] + w / 2 + 0.6 * S, yc, "3-bar output")
    joints = b.part.joints
    joints.append(Joint(b.name("pin_a"), "pin", a.body, links[0], pa=pin_a))
    joints.append(Joint(b.name("pin_b"), "pin", bb.body, links[1], pa=pin_b))
    joints.append(Joint(b.name("pin_m"), "pin", links[0], links[1], pa=M))
    joints.append(Joint(b.name("output_link"), "rod", links[0], out.body, pa=M, pb=O,
                        length=design.output_link))
    b.output(out, "Z")
    return {"pin_a": pin_a, "pin_b": pin_b, "M": M, "O": O, "axis_y": yc}


class _ThreeBar(Cell):
    """Shared by the AND and OR forms; ``mirror`` selects the OR."""

    min_inputs = 2
    max_inputs = 2
    auto_select = False  # bilateral, with a wander: only when asked for (--use-cell)
    mirror = False

    @classmethod
    def cost(cls, n_inputs: int) -> int:
        return 6  # two input sliders, two input links, output link, output slider

    @classmethod
    def synthesise(cls, cid, ctx: SynthContext, n_inputs, params, demand):
        design, rep = gate_design(float(ctx.stroke))
        b = Builder(cid, ctx)
        pts = build_gate(b, design, cls.mirror)
        inward, outward = wander_profile(design)
        la, lb = input_loads(design, demand, ctx.friction)
        b.part.data["three_bar"] = {
            "sep_mm": design.sep, "input_link_mm": design.input_link,
            "output_link_mm": design.output_link, "output_position_mm": design.output_position,
            "mirrored": cls.mirror, "min_transmission_angle_deg": rep.min_transmission_angle,
            "singular_clearance_mm": rep.singular_clearance, "link_ratio": rep.link_ratio,
            "gate_error_mm": rep.gate_error,
            "wander_inward_pct": inward, "wander_outward_pct": outward,
            "points": {k: (list(v) if isinstance(v, tuple) else v) for k, v in pts.items()},
        }
        return b.finish({"A": la, "B": lb})


class ThreeBarAnd(_ThreeBar):
    name = "three_bar_and"
    type = "AND"
    description = "3-bar linkage gate (000_…): output moves only when both inputs are on"


class ThreeBarOr(_ThreeBar):
    name = "three_bar_or"
    type = "OR"
    mirror = True
    description = "3-bar linkage gate mirrored (000_…): output moves when any input is on"
