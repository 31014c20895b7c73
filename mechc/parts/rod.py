"""``rod``: a link of ``length`` pinned at ``pa`` on body a and ``pb`` on body b (a massless
two-force member).

Closed forms: a rod from a known body places a slider (a quadratic, the root zero at the design
pose) or a lever (where the lever's circle meets the rod's). Drawn as a line between pin
circles; pymunk's PinJoint."""

from __future__ import annotations

import math

import numpy as np
import pymunk

from mechc.ir.mechanism import GROUND, Body, Joint
from mechc.parts.base import (
    JointKind,
    Placer,
    SceneBuilder,
    Shape,
    cross,
    is_number,
    lever_arm,
    line_cotan,
    line_tan,
    placed_key,
    placed_position,
    position,
    shifted,
    side_of,
    sized,
)
from mechc.parts.poses import Poses


def slider_from_rod(j: Joint, slider: Body, other: Body | None, poses: Poses,
                    size: int) -> None:
    """A rod of fixed length between a known body and the slider: the root that is zero at the
    design pose (the branch the mechanism is built on)."""
    mine, theirs = (j.pb, j.pa) if j.b == slider.id else (j.pa, j.pb)
    ox, oy = position(other, poses, theirs)
    wx, wy = mine[0] - ox, mine[1] - oy
    e = slider.axis
    we = wx * e[0] + wy * e[1]
    disc = we * we - (wx * wx + wy * wy) + j.length ** 2
    we0 = (mine[0] - theirs[0]) * e[0] + (mine[1] - theirs[1]) * e[1]
    s = side_of(we0)
    ok = disc >= 0
    u = -we + s * np.sqrt(np.where(ok, disc, 0.0))
    poses.u[slider.id] = np.where(ok, u, np.nan) * np.ones(size)
    poses.mark(slider.id, ~np.broadcast_to(ok, (size,))
               | np.broadcast_to(poses.bad.get(other.id if other else GROUND,
                                               np.zeros(size, bool)), (size,)))
    # rod direction against the slider's travel
    px, py = mine[0] + poses.u[slider.id] * e[0] - ox, mine[1] + poses.u[slider.id] * e[1] - oy
    mu = line_cotan(px, py, e[0], e[1])  # 90° less the rod's angle to the travel (tangent)
    arm = lever_arm(other, poses, theirs)
    if arm is not None:  # the lever arm's side of the pair
        mu = np.minimum(mu, line_tan(arm[0], arm[1], px, py))
    mu = mu * np.ones(size)
    poses.transmission.set_tan(j.id, mu)
    poses.singular_margin.set_tan(j.id, mu)


def lever_from_rod(j: Joint, lever: Body, other: Body | None, poses: Poses,
                   size: int) -> None:
    """A rod from a known body to a pin on the lever: the pin is where the lever's circle
    (about its pivot) meets the rod's circle (about the known end), on the side of the line of
    centres the design pose is on.

    Worked in units of the centre distance d (D = rod end - pivot): the pin sits at
    A·D ± H·D⊥ from the pivot with A = 1/2 + (r² - L²)/(2d²) and H² = r²/d² - A², so one
    division and one square root place it (the lever keeps the arm as its pose: the arctan2 of
    its angle is taken only if the angle is read, :class:`mechc.parts.poses.Turn`, and the pin
    is not read back through it). The transmission angle is kept as d², which it depends on
    alone (arm, rod and D make a triangle of sides r, L, d): the check converts only the
    smallest and largest d² of the states, with the tangent H / |r²/d² - A| of the same
    numbers (:func:`mechc.parts.poses.sides_tan`), which unlike arccos of a cosine stays
    accurate at the toggle (H -> 0). It is the same circle meeting as
    :func:`mechc.geometry.circles.circle_meeting`, kept in these units because it is the hot
    path of every kinematic proof."""
    mine, theirs = (j.pb, j.pa) if j.b == lever.id else (j.pa, j.pb)
    P = lever.pivot
    r2 = (mine[0] - P[0]) ** 2 + (mine[1] - P[1]) ** 2
    L2 = j.length * j.length
    cx, cy = position(other, poses, theirs)
    dx, dy = shifted(cx, -P[0]), shifted(cy, -P[1])  # read only below
    if not (is_number(P[0]) and is_number(P[1]) and is_number(r2) and is_number(L2)
            and dx.shape == dy.shape):  # per-sample dimensions: the in-place steps need
        dx, dy = sized(dx, size), sized(dy, size)  # one shape
    with np.errstate(divide="ignore", invalid="ignore"):  # temporaries reused in place
        d2 = dx * dx  # kept: the transmission angle's domain
        H = dy * dy
        d2 += H
        inv = np.divide(1.0, d2)  # d = 0 or NaN: A, H2 NaN below, the state is bad
        A = inv * (0.5 * (r2 - L2))
        A += 0.5
        u = np.multiply(inv, r2, out=inv)  # r²/d²
        np.multiply(A, A, out=H)
        np.subtract(u, H, out=H)  # H² = r²/d² - A²
        np.sqrt(H, out=H)  # unsolved states (H² < 0, past the toggle, or NaN): NaN
        bad = np.isnan(H)  # the states that cannot assemble
    side = side_of(cross((theirs[0] - P[0], theirs[1] - P[1]), (mine[0] - P[0], mine[1] - P[1])))
    rx = A * dx
    ry = np.multiply(A, dy, out=A)
    t = u  # a spare temporary from here on
    if not isinstance(side, float):  # dimensions as arrays (a tolerance run): per sample
        rx -= side * H * dy
        ry += side * H * dx
    elif side > 0:
        rx -= np.multiply(H, dy, out=t)
        ry += np.multiply(H, dx, out=t)
    else:
        rx += np.multiply(H, dy, out=t)
        ry -= np.multiply(H, dx, out=t)
    if rx.shape != (size,):
        rx, ry = (np.broadcast_to(v, (size,)).copy() for v in (rx, ry))
    # the lever's pose is the arm it turned to: its angle (an arctan2) is taken when read
    mx, my = mine[0] - P[0], mine[1] - P[1]
    phi0 = math.atan2(my, mx) if is_number(mx) and is_number(my) else np.arctan2(my, mx)
    poses.theta.set_arm(lever.id, rx, ry, mx, my, phi0)
    other_bad = poses.bad.get(other.id if other else GROUND)
    if bad.shape != (size,):
        bad = np.broadcast_to(bad, (size,)).copy()
    if other_bad is not None:
        bad |= other_bad
    poses.mark(lever.id, bad, own=True)
    poses.placed[placed_key(lever, mine)] = (shifted(rx, P[0]), shifted(ry, P[1]),
                                             poses.theta.entry(lever.id))
    if other is not None:
        poses.placed[placed_key(other, theirs)] = (cx, cy, poses.theta.entry(other.id))
    # transmission: the angle between the rod and the lever arm (90° is ideal), 0 past the
    # toggle; kept as d² (arm, rod and d make a triangle: the law of cosines), converted at
    # the extreme only (``Angles.set_sides``)
    if d2.shape == (size,):
        d2.flags.writeable = False  # one array serves both checks, unchanged from here on
    else:
        d2 = sized(d2, size)  # a read-only view
    poses.transmission.set_sides(j.id, d2, r2, L2)
    poses.singular_margin.set_sides(j.id, d2, r2, L2)


class Rod(JointKind):
    name = "rod"
    solvers = {("slider", "a"): slider_from_rod, ("slider", "b"): slider_from_rod,
               ("lever", "a"): lever_from_rod, ("lever", "b"): lever_from_rod}

    @classmethod
    def violation(cls, j: Joint, a: Body | None, b: Body | None, poses: Poses, size: int,
                  tol: float) -> np.ndarray | None:
        """|distance - length| > 1e-6, squared: no square root. The smallest and largest
        squared distance decide first: when both are in the band no state breaks the rod
        (None: nothing to mark), and the states are compared one by one only otherwise."""
        ax_, ay_ = placed_position(a, poses, j.pa)
        bx_, by_ = placed_position(b, poses, j.pb)
        g2, ey = bx_ - ax_, by_ - ay_  # the differences are temporaries: squared in place
        g2 *= g2
        ey *= ey
        g2 += ey
        hi2 = (j.length + 1e-6) ** 2
        if is_number(j.length):
            lo2 = (j.length - 1e-6) ** 2 if j.length > 1e-6 else -math.inf
            # NaN states (not placed) break nothing, here as below: fmin/fmax pass them over
            if (g2.size and np.fmax.reduce(g2, axis=None) <= hi2
                    and np.fmin.reduce(g2, axis=None) >= lo2):
                return None
            viol = g2 > hi2
            viol |= g2 < lo2
        else:  # a length per sample (a tolerance run)
            viol = g2 > hi2
            viol |= (j.length > 1e-6) & (g2 < (j.length - 1e-6) ** 2)
        return sized(viol, size)

    @classmethod
    def shapes(cls, j: Joint, at: Placer) -> list[Shape]:
        return [Shape("rod", [at.pt(j.a, j.pa), at.pt(j.b, j.pb)], ref=j.id)]

    @classmethod
    def add_to_scene(cls, scene: SceneBuilder, j: Joint) -> None:
        c = pymunk.PinJoint(scene.body_of(j.a), scene.body_of(j.b), scene.anchor(j.a, j.pa),
                            scene.anchor(j.b, j.pb))
        c.distance = j.length
        scene.measure(j.id, "rod", scene.order_of(j.a), scene.anchor(j.a, j.pa),
                      scene.order_of(j.b), scene.anchor(j.b, j.pb), (j.length,))
        scene.space.add(c)
