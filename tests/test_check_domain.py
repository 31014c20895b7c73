"""The design checks' angles taken in the cheap domain (tangents from cross and dot products,
only the extreme converted to degrees) against the degree-domain formulas they replaced
(arccos / arctan2 on every state), on every example and on designs with the cells that use the
other closed forms (threshold generators, three-bar gates, an amplifier: slots and dyads):
every state's angle and every check's figure agree to 1e-9 degrees."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.boolfile import parse_bool
from mechc.frontends.fsm import parse_fsm_file
from mechc.ir.netlist import CellInst, Netlist
from mechc.parts import groove, rod
from mechc.parts.base import angle_between_lines
from mechc.parts.poses import Angles, Poses
from mechc.passes.map import MapOptions
from mechc.physics import closed_form
from mechc.physics.measures import CheckStats
from mechc.pipeline import CompileOptions, compile_netlist, compile_spec
from mechc.proofs.kinematic import sweep
from mechc.proofs.seq_mechanism import prove_sequential_kinematic
from tests.helpers import EXAMPLES

LIB = load_library()
EXAMPLE_FILES = sorted(p for p in EXAMPLES.iterdir()
                       if p.suffix in (".bool", ".pla", ".blif", ".fsm"))
ANGLES = ("transmission angle", "distance from toggle")
#: designs whose cells solve by the slot and dyad closed forms (no example uses those cells)
OTHER_CELLS = ["threshold full_adder.bool", "threshold fv157.bool", "three_bar_and",
               "three_bar_or", "amplifier"]


def single_cell(name: str, cell_type: str, inputs: list[str], expr: str):
    cls = LIB[name]
    nl = Netlist(inputs)
    nl.add_cell(CellInst("c1", name, cell_type, tuple(inputs), ("z",)),
                pin_names=cls.input_names(len(inputs)))
    nl.set_output("z", "z")
    spec = parse_bool(f"inputs {' '.join(inputs)}\noutputs z\nz = {expr}\n")
    return compile_netlist(spec, nl, library=LIB)


def compiled(case) -> object:
    if not isinstance(case, str):
        spec = parse_fsm_file(case) if case.suffix == ".fsm" else load_spec(case)
        return compile_spec(spec)
    if case.startswith("threshold "):
        return compile_spec(load_spec(EXAMPLES / case.split()[1]),
                            CompileOptions(map=MapOptions(target="threshold")))
    if case == "amplifier":
        return single_cell("amplifier", "AMPLIFIER", ["a"], "a")
    kind = case.rsplit("_", 1)[1].upper()
    return single_cell(case, kind, ["a", "b"], "a | b" if kind == "OR" else "a & b")


def degree_domain(monkeypatch) -> None:
    """The formulas before the cheap domain: every state's angle in degrees by arccos or
    arctan2, stored as degrees."""
    def line_deg(ax, ay, bx, by):
        return angle_between_lines(ax, ay, bx, by)

    def complement_deg(ax, ay, bx, by):
        return 90.0 - angle_between_lines(ax, ay, bx, by)

    def arccos_deg(c):
        return np.degrees(np.arccos(np.clip(c, 0.0, 1.0)))

    def law_of_cosines(self, key, d2, r2, l2):  # the acute angle between sides r and l
        c = np.abs(r2 + l2 - d2) / (2.0 * np.sqrt(r2 * l2))
        self[key] = arccos_deg(c)

    for mod, names in ((rod, {"line_tan": line_deg, "line_cotan": complement_deg}),
                       (groove, {"arccos_tan": arccos_deg, "line_cotan": complement_deg}),
                       (closed_form, {"line_tan": line_deg})):
        for name, fn in names.items():
            monkeypatch.setattr(mod, name, fn)
    monkeypatch.setattr(Angles, "set_tan", Angles.__setitem__)
    monkeypatch.setattr(Angles, "set_sides", law_of_cosines)


class Keep(CheckStats):
    """The check statistics, and every state's angles in degrees."""

    def __init__(self, mech):
        super().__init__(mech)
        self.states: dict[str, list[np.ndarray]] = {}

    def add(self, poses: Poses) -> None:
        super().add(poses)
        for kind in ("transmission", "singular_margin"):
            for jid, deg in getattr(poses, kind).items():
                self.states.setdefault(f"{kind} {jid}", []).append(np.ravel(deg).copy())


def measure(design) -> Keep:
    keep = Keep(design.mechanism)
    if design.sequential is not None:
        prove_sequential_kinematic(design, design.spec, LIB, random_walks=0, stats=keep)
    else:
        sweep(design, LIB, samples=5, stats=keep)
    return keep


def figures(keep: Keep) -> dict[tuple[str, str], float]:
    return {(c.name, c.where): c.value for c in keep.checks() if c.name in ANGLES}


@pytest.mark.parametrize("case", EXAMPLE_FILES + OTHER_CELLS, ids=str)
def test_cheap_domain_angles_equal_the_degree_domain_ones(case, monkeypatch):
    design = compiled(case)
    cheap = measure(design)
    with monkeypatch.context() as m:
        degree_domain(m)
        ref = measure(design)
    fast, slow = figures(cheap), figures(ref)
    assert fast.keys() == slow.keys() and fast  # every example has angle checks
    for key, v in slow.items():
        assert math.isnan(v) == math.isnan(fast[key]), key
        assert abs(fast[key] - v) <= 1e-9 or math.isnan(v), (key, fast[key], v)
    assert cheap.states.keys() == ref.states.keys()
    for key, chunks in ref.states.items():
        a, b = np.concatenate(cheap.states[key]), np.concatenate(chunks)
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=key)
        ok = ~np.isnan(b)
        assert np.max(np.abs(a[ok] - b[ok]), initial=0.0) <= 1e-9, key


def test_angles_keep_what_was_stored_and_convert_the_extreme_only():
    a = Angles()
    a.set_tan("j", np.array([1.0, np.inf, np.nan, math.tan(math.radians(30.0))]))
    a["k"] = np.array([50.0, 40.0])  # degrees, as a cell may store them
    assert a.min_deg("j") == pytest.approx(30.0, abs=1e-12)
    assert a.min_deg("k") == 40.0
    np.testing.assert_allclose(a["j"][[0, 1, 3]], [45.0, 90.0, 30.0], atol=1e-12)
    assert np.isnan(a["j"][2])
    b = Angles()
    b.update(a)
    assert b.min_deg("j") == a.min_deg("j") and set(b) == {"j", "k"}
    assert math.isnan(Angles({"x": np.array([np.nan])}).min_deg("x"))
    assert Poses(transmission={"m": np.array([20.0])}).transmission.min_deg("m") == 20.0


def _slot_part():
    """A lever whose pin (at 45°, 9.9 mm from its pivot) runs in a straight slot on a slider
    that moves across the slot: the groove's closed forms, in both directions."""
    from mechc.ir.mechanism import Body, Joint, Part
    slider = Body("s", "slider", [[(0.0, -20.0), (14.0, -20.0), (14.0, 20.0)]], 0.01,
                  axis=(1.0, 0.0))
    lever = Body("l", "lever", [[(0.0, 0.0), (7.0, 7.0), (1.0, 0.0)]], 0.01, pivot=(0.0, 0.0))
    slot = Joint("g", "groove", "s", "l", p0=(7.0, -20.0), p1=(7.0, 20.0), q=(7.0, 7.0))
    return Part([slider, lever], [slot])


@pytest.mark.parametrize("driver, values", [("s", np.linspace(-6.0, 2.5, 401)),
                                            ("l", np.linspace(-0.7, 0.6, 401))])
def test_slot_angles_equal_the_degree_domain_ones(driver, values, monkeypatch):
    def angles():
        poses = closed_form.solve(_slot_part(), {driver: values}, len(values))
        return {k: getattr(poses, k)[jid] for k in ("transmission", "singular_margin")
                for jid in getattr(poses, k)}

    cheap = angles()
    with monkeypatch.context() as m:
        degree_domain(m)
        ref = angles()
    assert cheap.keys() == ref.keys() and cheap
    for key in ref:
        a, b = np.broadcast_to(cheap[key], values.shape), np.broadcast_to(ref[key], values.shape)
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
        ok = ~np.isnan(b)
        assert ok.any() and np.max(np.abs(a[ok] - b[ok])) <= 1e-9, key
