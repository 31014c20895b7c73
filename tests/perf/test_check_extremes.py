"""The transmission angle of a lever placed by a rod, kept as d² and converted at the extreme
only (``Angles.set_sides``, ``Angles.min_deg``), against closed forms of a four-bar's extreme
transmission angle and against the smallest of every state's angle (the per-state formula the
extreme path replaced)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechc.ir.mechanism import Body, Joint, Part
from mechc.parts.poses import Angles, sides_tan
from mechc.physics.closed_form import solve
from mechc.physics.measures import CheckStats


def fourbar(ground: float, crank: float, coupler: float, rocker: float) -> Part:
    """Crank on (0, 0), rocker on (ground, 0), design pose with the crank straight up and the
    rocker pin above the ground line."""
    a = (0.0, crank)
    d = math.hypot(ground, crank)
    al = (rocker * rocker - coupler * coupler + d * d) / (2 * d)
    h = math.sqrt(rocker * rocker - al * al)
    ex, ey = (a[0] - ground) / d, a[1] / d
    b = max(((ground + al * ex - s * h * ey, al * ey + s * h * ex) for s in (1, -1)),
            key=lambda p: p[1])
    c = Body("crank", "lever", [[(0.0, 0.0), a, (1.0, 0.0)]], 0.01, pivot=(0.0, 0.0))
    r = Body("rocker", "lever", [[(ground, 0.0), b, (ground + 1, 0.0)]], 0.01,
             pivot=(ground, 0.0))
    return Part([c, r], [Joint("rod", "rod", "crank", "rocker", pa=a, pb=b, length=coupler)])


def crank_turns(n: int) -> np.ndarray:
    """A full turn of the crank from its design pose (+90°), through the two crank angles at
    which it lies along the ground line (0° and 180°: turns -90° and +90°) exactly."""
    return np.concatenate([np.linspace(-math.pi, math.pi, n), [-math.pi / 2, math.pi / 2]])


def acute_deg(r: float, l: float, d: float) -> float:
    """The law of cosines: the acute angle between sides r and l of a triangle with third
    side d."""
    return math.degrees(math.acos(min(1.0, abs(r * r + l * l - d * d) / (2 * r * l))))


# the smallest angle at d = g - c for the first three, at d = g + c for the last
@pytest.mark.parametrize("g, c, l, r", [(40.0, 10.0, 40.0, 30.0), (50.0, 12.0, 45.0, 38.0),
                                        (30.0, 8.0, 26.0, 20.0), (45.0, 10.0, 30.0, 30.0)])
def test_extreme_transmission_of_a_crank_rocker_is_the_closed_form(g, c, l, r):
    """A Grashof crank-rocker's transmission angle is smallest with the crank along the ground
    line, d = g - c or g + c (the classic closed form): the extreme path must give it."""
    part = fourbar(g, c, l, r)
    th = crank_turns(4001)
    poses = solve(part, {"crank": th}, len(th))
    assert not poses.bad["rocker"].any()
    want = min(acute_deg(r, l, g - c), acute_deg(r, l, g + c))
    got = poses.transmission.min_deg("rod")
    assert got == pytest.approx(want, rel=1e-12, abs=1e-12)
    assert poses.singular_margin.min_deg("rod") == got
    # the same as the smallest of every state's angle (what the check read before)
    every = poses.transmission["rod"]
    assert abs(got - float(np.nanmin(every))) <= 1e-9 * got
    stats = CheckStats(_mech_of(part))
    stats.add(poses)
    assert stats.mu["rod"] == got and stats.sing["rod"] == got


def test_a_crank_that_cannot_turn_round_reports_0_past_the_toggle():
    """A non-Grashof linkage driven through a full turn: the states past the toggle cannot
    assemble and count as 0°; where it assembles the smallest angle is the closed form's."""
    part = fourbar(40.0, 25.0, 30.0, 20.0)
    th = crank_turns(2001)
    poses = solve(part, {"crank": th}, len(th))
    bad = poses.bad["rocker"]
    assert bad.any() and not bad.all()
    assert poses.transmission.min_deg("rod") == 0.0
    ok = ~bad
    some = solve(part, {"crank": th[ok][:5]}, 5)
    d = np.hypot(25.0 * np.cos(th[ok][:5] + math.pi / 2) - 40.0,
                 25.0 * np.sin(th[ok][:5] + math.pi / 2))
    want = min(acute_deg(20.0, 30.0, float(v)) for v in d)
    assert some.transmission.min_deg("rod") == pytest.approx(want, abs=1e-9)


def test_extreme_path_equals_every_state_on_odd_inputs():
    """NaN states are left out, all NaN gives NaN, a d² of 0 (undefined per state) and
    dimensions per state take the every-state path: always the smallest of sides_tan."""
    rng = np.random.default_rng(5)
    r2, l2 = 900.0, 1600.0
    cases = [rng.uniform(100.0, 4900.0, 300), rng.uniform(0.0, 9000.0, 300),
             np.array([np.nan, 2500.0, 1000.0, np.nan]), np.array([0.0, 1200.0, 2000.0]),
             np.array([np.inf, 1500.0])]
    for d2 in cases:
        a = Angles()
        a.set_sides("j", d2, r2, l2)
        ref = np.degrees(np.arctan(sides_tan(d2, r2, l2)))
        assert a.min_deg("j") == pytest.approx(float(np.nanmin(ref)), rel=1e-12, abs=1e-12)
        np.testing.assert_array_equal(a["j"], ref)
    a = Angles()
    a.set_sides("j", np.array([np.nan, np.nan]), r2, l2)
    assert math.isnan(a.min_deg("j"))
    per_state = rng.uniform(800.0, 1000.0, 50)
    d2 = rng.uniform(600.0, 4000.0, 50)
    a.set_sides("k", d2, per_state, l2)
    assert a.min_deg("k") == pytest.approx(
        float(np.nanmin(np.degrees(np.arctan(sides_tan(d2, per_state, l2))))), rel=1e-12)


def _mech_of(part: Part):
    """The smallest mechanism CheckStats needs: no cells, so only the angle minima run."""
    class Mech:
        order: list[str] = []
        cells: dict = {}

        @staticmethod
        def body_index():
            return {b.id: b for b in part.bodies}

    return Mech()


def test_the_shared_extreme_is_worked_out_once_and_only_for_an_unchanged_array():
    """The transmission and toggle checks share one d² array: the second reading reuses the
    first's extreme only while the array is read-only and the sides are the same."""
    d2 = np.array([900.0, 1600.0, 2500.0])
    d2.flags.writeable = False
    t, m = Angles(), Angles()
    t.set_sides("j", d2, 900.0, 1600.0)
    m.set_sides("j", d2, 900.0, 1600.0)
    first = t.min_deg("j")
    assert m.min_deg("j") == first == pytest.approx(acute_deg(30.0, 40.0, 30.0), abs=1e-12)
    other = Angles()
    other.set_sides("j", d2, 900.0, 2500.0)  # the same d², other sides: its own extreme
    assert other.min_deg("j") == pytest.approx(acute_deg(30.0, 50.0, 30.0), abs=1e-12)
    assert abs(other.min_deg("j") - first) > 10
    w = np.array([900.0, 1600.0, 2500.0])  # writable: worked out on every reading
    a = Angles()
    a.set_sides("j", w, 900.0, 1600.0)
    assert a.min_deg("j") == pytest.approx(first, abs=1e-12)
    w[0] = 1250.0
    assert a.min_deg("j") == pytest.approx(acute_deg(30.0, 40.0, math.sqrt(1250.0)), abs=1e-12)
