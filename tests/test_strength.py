"""Strength: materials, designed springs, pins, stress and buckling checks, refused loads, the
AMPLIFIER rest check.

Hand calculations here use the textbook formulas written out in the test (Euler, Wahl, the
music-wire strength A / d^m), not the functions under test."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

import mechc.physics.evaluate as evaluate_module
from mechc.cells.library import load_library
from mechc.cli.common import load_spec
from mechc.parts.pushrod import net_rods
from mechc.passes.assemble import MechOptions
from mechc.passes.checks import run_design_checks
from mechc.passes.strength import push_rods, strength_checks
from mechc.pipeline import CompileOptions, compile_spec
from tests.helpers import EXAMPLES
from tests.sequential.test_seq_amp_engage import amplifier_with_loads

LIB = load_library()
SORTER = EXAMPLES / "sorter.bool"
#: Music wire ASTM A228 (Shigley Table 10-4), G (Table 10-5), S_sy = 0.45 S_ut, n_s = 1.2.
A228_A, A228_M, A228_G = 2211.0, 0.145, 81_700.0
WIRES = (0.10, 0.12, 0.14, 0.16, 0.18, 0.20, 0.22, 0.25, 0.28, 0.30, 0.32, 0.36, 0.40, 0.45,
         0.50, 0.56, 0.60, 0.63, 0.70, 0.80, 0.90, 1.00)


def compiled(path=SORTER, **mech):
    return compile_spec(load_spec(str(path)), CompileOptions(mech=MechOptions(**mech)), LIB)


def checks_named(design, word):
    return [c for c in design.mechanism.checks if word in c.name]


@pytest.fixture(scope="module")
def sorter():
    return compiled()


def test_euler_load_of_a_rod_by_hand(sorter):
    """Every rod's buckling check is pi^2 E I / L^2 over its load, I = b h^3 / 12 about the
    plate's thickness (aluminium 6061-T6: E = 68.9 GPa; 6 x 3 mm bars at the default stroke)."""
    rods = {r.id: r for r in push_rods(sorter.mechanism)}
    checks = {c.where: c for c in checks_named(sorter, "rod buckling")}
    assert checks and set(checks) <= set(rods)
    pins = {j.id: j for j in sorter.mechanism.nets["A"].joints}
    pa, pb = pins["net.A.rod2.driver"].pa, pins["net.A.rod2.load"].pa
    length = math.hypot(pb[0] - pa[0], pb[1] - pa[1])  # pin to pin
    rod = rods["net.A.rod2"]
    assert rod.length == pytest.approx(length) and (rod.width, rod.thickness) == (6.0, 3.0)
    i_weak = 6.0 * 3.0 ** 3 / 12.0  # 13.5 mm^4
    p_cr = math.pi ** 2 * 68_900.0 * i_weak / length ** 2
    assert checks["net.A.rod2"].value == pytest.approx(p_cr / rod.load, rel=1e-12)
    # the load is what that rod's load asks in the force budget, plus guide friction
    cid, pin = sorter.mechanism.nets["A"].data["loads"][1].rsplit(".", 1)
    ask = sorter.mechanism.cells[cid].data["input_loads"][pin]
    assert rod.load == pytest.approx(max(ask["right_N"], ask["left_N"]) + 0.02)


def test_axial_stress_and_pins_by_hand(sorter):
    """Axial stress = net demand / (6 x 3 mm); pin shear on a 3 mm pin = F / (pi 1.5^2) against
    0.577 x 370 MPa / 2 (AISI 1018 pins), bearing F / (3 x 3) against 276 / 2 MPa."""
    d = sorter.mechanism.nets["A"].data["demand"]
    f = max(d["right_N"], d["left_N"])
    (c,) = [c for c in checks_named(sorter, "axial stress") if c.where == "net A"]
    assert c.value == pytest.approx(f / 18.0) and c.limit == pytest.approx(138.0)
    (s,) = [c for c in checks_named(sorter, "pin shear") if c.where == "net A"]
    assert s.value == pytest.approx(f / (math.pi * 1.5 ** 2))
    assert s.limit == pytest.approx(0.577 * 370.0 / 2)
    (b,) = [c for c in checks_named(sorter, "pin bearing") if c.where == "net A"]
    assert b.value == pytest.approx(f / 9.0)
    rod = sorter.mechanism.nets["A"].joints[0]
    assert rod.pin_diameter == 3.0 and '"pin_diameter_mm": 3.0' in json.dumps(rod.to_json())


def test_lever_bending_by_hand(sorter):
    """A NOT lever of arm 1.5 x stroke = 30 mm under its cell's load F (the largest of its own
    output demand, the demand of the net it drives and what each of its inputs asks of the
    net it loads, guide friction included): sigma = M / Z = F 30 / (3 x 6^2 / 6)."""
    mech = sorter.mechanism
    (c,) = [c for c in checks_named(sorter, "lever bending") if c.where == "c5.lever"]
    driven = [max(n.data["demand"]["right_N"], n.data["demand"]["left_N"])
              for n in mech.nets.values() if n.data["driver"] == "c5"]
    asks = [max(a["right_N"], a["left_N"]) + 0.02
            for a in mech.cells["c5"].data["input_loads"].values()]
    own = mech.cells["c5"].data["output_demand"]
    f = max(driven + asks + [own["right_N"], own["left_N"]])
    assert c.value == pytest.approx(f * 30.0 / (3.0 * 6.0 ** 2 / 6.0), rel=1e-9)
    assert "30 mm arm" in c.name and c.limit == pytest.approx(138.0)


def test_spring_design_by_hand(sorter):
    """One spring of the design: its coil has the spring's rate (n = G d^4 / (8 D^3 k)), its
    stress is the Wahl-corrected 8 F D / (pi d^3), its allowable 0.45 A / d^m / 1.2, and no
    thinner stocked wire at any index 6..12 keeps that (with at least 3 active coils)."""
    sp = next(s for p in sorter.mechanism.cells.values() for s in p.springs
              if s.id.endswith("spring5"))
    c = sp.coil
    d, D, n, F = c.wire, c.mean_diameter, c.active_coils, sp.max_force
    assert 6 - 1e-9 <= D / d <= 12 + 1e-9
    assert A228_G * d ** 4 / (8 * D ** 3 * n) == pytest.approx(sp.rate, rel=1e-9)
    C = D / d
    wahl = (4 * C - 1) / (4 * C - 4) + 0.615 / C
    tau = wahl * 8 * F * D / (math.pi * d ** 3)
    assert c.stress == pytest.approx(tau, rel=1e-9)
    assert c.allowable == pytest.approx(0.45 * A228_A / d ** A228_M / 1.2, rel=1e-9)
    assert tau <= c.allowable
    for thinner in (w for w in WIRES if w < d):
        for C in range(6, 13):
            Dt = C * thinner
            wahl = (4 * C - 1) / (4 * C - 4) + 0.615 / C
            ok = (wahl * 8 * F * Dt / (math.pi * thinner ** 3)
                  <= 0.45 * A228_A / thinner ** A228_M / 1.2)
            coils = A228_G * thinner ** 4 / (8 * Dt ** 3 * sp.rate)
            assert not (ok and coils >= 3), (thinner, C)
    # largest force: preload, a full stroke and the 2 % over-travel at rate k
    assert F == pytest.approx(sp.preload + sp.rate * 20.0 * 1.02)
    j = sp.to_json()
    assert j["coil"]["wire_mm"] == d and j["max_force_N"] == pytest.approx(F, abs=1e-4)
    again = type(sp).from_json(json.loads(json.dumps(j)))
    assert again.coil.wire == d and again.max_force == pytest.approx(F, abs=1e-4)


def test_a_slender_rod_is_rejected_by_name(sorter):
    """A rod made 10x longer after sizing (its load pin moved out along it; its guides as they
    were: none) buckles: its check fails and names it; the others are unchanged."""
    design = dataclasses.replace(sorter)
    before = {c.where: c for c in strength_checks(design.mechanism) if "buckling" in c.name}
    net = design.mechanism.nets["A"]
    info = max(net.data["rods"], key=lambda r: r["length_mm"])  # 385 mm, the longest
    rid = info["body"]
    pins = {j.id: j for j in net.joints}
    driver, load = pins[f"{rid}.driver"], pins[f"{rid}.load"]
    old = load.pa
    try:
        load.pa = (driver.pa[0] + 10 * (old[0] - driver.pa[0]), old[1])
        after = {c.where: c for c in strength_checks(design.mechanism) if "buckling" in c.name}
    finally:
        load.pa = old
    assert before[rid].passed and not after[rid].passed
    assert after[rid].value == pytest.approx(before[rid].value / 100)
    assert [w for w, c in after.items() if not c.passed] == [rid]


def test_long_pla_rods_get_guides_by_hand(cli, tmp_path):
    """3D-printed PLA (E = 2346.5 MPa) under the default loads: three long rods of the sorter
    would buckle pin to pin; each gets the fewest guides that keep every span within its Euler
    length at a factor 3 (by hand: spans = ceil(L / (pi sqrt(E I / (3 P))))), compile passes,
    and the file reloads in simulate."""
    out = tmp_path / "pla.json"
    rc, _, err = cli("compile", SORTER, "-o", out, "--material", "pla")
    assert rc == 0, err
    d = json.loads(out.read_text())
    assert d["mechanism"]["rules"]["material"] == "pla"
    guided = {}
    for net in d["mechanism"]["nets"].values():
        pins = {j["id"]: j for j in net["joints"]}
        for rod, load in zip(net["data"]["rods"], net["data"]["loads"]):
            rid = rod["body"]
            pa, pb = pins[f"{rid}.driver"]["pa"], pins[f"{rid}.load"]["pa"]
            cell = next(c for c in d["cells"] if c["id"] == load.split(".")[0])
            ask = cell["geometry"]["data"]["input_loads"][load.split(".")[1]]
            p = (ask["right_N"] if pb[0] >= pa[0] else ask["left_N"]) + 0.02
            l_max = math.pi * math.sqrt(2346.5 * 13.5 / (3 * p))
            spans = math.ceil(math.hypot(pb[0] - pa[0], pb[1] - pa[1]) / l_max)
            if spans > 1:
                guided[rid] = spans - 1
            assert net["data"].get("rod_guides", {}).get(rid, 0) == spans - 1, rid
    assert guided == {"net.A.rod2": 1, "net.B.rod1": 1, "net.n1.rod1": 1}
    checks = {c["where"]: c for c in d["mechanism"]["checks"] if "buckling" in c["name"]}
    assert "1 guide: span 192.3 mm" in checks["net.A.rod2"]["name"]
    rc, _, err = cli("simulate", out, "--level", "logic")
    assert rc == 0, err


@pytest.mark.parametrize("spec", sorted(p.name for p in EXAMPLES.iterdir()
                                        if p.suffix in (".bool", ".pla", ".blif", ".fsm",
                                                        ".kiss2")))
def test_every_example_is_strong_enough_at_defaults(spec):
    design = compiled(EXAMPLES / spec)
    names = ("axial stress", "rod buckling", "pin shear", "pin bearing", "spring wire stress")
    found = [c for c in design.mechanism.checks if c.name.startswith(names)]
    assert {c.name.split(" (")[0] for c in found} >= {"axial stress", "spring wire stress"}
    assert all(c.passed for c in found), [c.text() for c in found if not c.passed]


@pytest.mark.parametrize("load", ["1e6", "1e8"])
def test_loads_no_plate_carries_are_refused(cli, tmp_path, load):
    """Beyond 276 MPa x 6 mm x 3 mm = 4968 N (one aluminium bar at yield) compile refuses
    (exit 2), writes nothing and leaves an existing file alone."""
    out = tmp_path / "s.json"
    out.write_text("keep me")
    rc, _, err = cli("compile", SORTER, "-o", out, "--output-load", load)
    assert rc == 2 and "refusing to compile" in err and "4968 N" in err
    assert out.read_text() == "keep me"
    rc, _, err = cli("compile", SORTER, "-o", tmp_path / "a.json", "--actuator-force", load)
    assert rc == 2 and "--actuator-force" in err and not (tmp_path / "a.json").exists()


def test_a_heavy_load_fails_the_strength_checks_and_reloads(cli, tmp_path):
    """3000 N: below what a bar carries at yield, above what the factor 2 allows: exit 1, the
    overloaded parts named, and the file written loads in simulate."""
    out = tmp_path / "heavy.json"
    rc, _, err = cli("compile", SORTER, "-o", out, "--output-load", "3000")
    assert rc == 1 and "axial stress" in err and "spring wire stress" in err
    rc, _, err = cli("simulate", out, "--level", "logic")
    assert rc == 0, err


@pytest.mark.parametrize("name", ["heavy.json", "heavy.json.gz"])
def test_a_design_the_checks_reject_never_replaces_an_existing_file(cli, tmp_path, name):
    """The user's earlier design at -o stays as it was; the rejected one goes beside it."""
    out = tmp_path / name
    out.write_bytes(b"the user's earlier design")
    rc, _, err = cli("compile", SORTER, "-o", out, "--output-load", "3000")
    assert rc == 1 and "DESIGN CHECKS FAILED" in err
    assert out.read_bytes() == b"the user's earlier design"
    beside = tmp_path / name.replace(".json", ".rejected.json")
    assert f"written to {beside}" in err and f"{out} is unchanged" in err
    rc, _, err = cli("simulate", beside, "--level", "logic")
    assert rc == 0, err


def test_unknown_material_lists_the_known_ones(cli, tmp_path):
    rc, _, err = cli("compile", SORTER, "-o", tmp_path / "x.json", "--material", "wood")
    assert rc == 2 and "'wood'" in err
    assert all(m in err for m in ("aluminium", "steel", "acrylic", "pla"))
    assert not (tmp_path / "x.json").exists()


def test_materials_scale_every_mass_by_their_density(sorter):
    """Same geometry, every body's mass times the density ratio (kg/mm^3: aluminium 2.70e-6,
    steel 7.87e-6, acrylic 1.19e-6, PLA 1.24e-6)."""
    base = sorter.mechanism.body_index()
    assert sorter.mechanism.ctx.density == 2.7e-6  # the default keeps the old density
    for name, rho in (("steel", 7.87e-6), ("acrylic", 1.19e-6), ("pla", 1.24e-6)):
        other = compiled(material=name).mechanism
        assert other.ctx.material == name
        bodies = other.body_index()
        assert set(bodies) == set(base)
        for bid, b in bodies.items():
            assert b.mass == pytest.approx(base[bid].mass * rho / 2.7e-6, rel=1e-12), bid


def test_amplifier_input_resting_short_fails_the_engage_check():
    """The amplifier's input must rest within its engage distance (0.5 mm at stroke 20) of its
    ends. Lengthening the rod into it by 0.7 mm leaves it 0.7 mm short of off in the off states
    (inside the proofs' 5 % = 1 mm rest tolerance): the check fails naming the amplifier; by
    0.3 mm it passes."""
    design = amplifier_with_loads(("or",))
    (c,) = [c for c in design.mechanism.checks if "short of its end" in c.name]
    assert c.passed and c.where == "amplifier amp" and c.value == pytest.approx(0.0, abs=1e-9)
    assert c.limit == pytest.approx(0.5)
    (rod,) = net_rods(design.mechanism.nets["a"])
    for extra, ok in ((0.3, True), (0.7, False)):
        longer = dataclasses.replace(rod, length=rod.length + extra)  # made too long
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(evaluate_module, "net_rods",
                       lambda part, longer=longer: [longer if r.id == rod.id else r
                                                    for r in net_rods(part)])
            run_design_checks(design, LIB)
        (c,) = [c for c in design.mechanism.checks if "short of its end" in c.name]
        assert c.value == pytest.approx(extra, abs=1e-6) and c.passed is ok


def test_a_load_cell_carries_its_own_rod_not_the_whole_net():
    """One input drives three OR gates (each with an input of its own, each an output at the
    default 0.5 N): by the closed-form spring budget each OR input asks 1.3 x 1.3 x (0.5 +
    0.02) + 0.5 + 0.02 N, plus 0.02 N of rod guide friction; the shared net carries three of
    those, but each OR cell only its own rod's pull (static force balance on its input
    slider), so its design load is one share, not the net's demand."""
    from mechc.frontends.boolfile import parse_bool
    from mechc.ir.netlist import CellInst, Netlist
    from mechc.passes.strength import part_loads
    from mechc.pipeline import compile_netlist
    nl = Netlist(["a", "b1", "b2", "b3"])
    cls = LIB.for_type("OR", 2)
    for k in (1, 2, 3):
        nl.add_cell(CellInst(f"c{k}", cls.name, "OR", ("a", f"b{k}"), (f"z{k}",)),
                    pin_names=cls.input_names(2), out_pins=list(cls.outputs))
        nl.set_output(f"z{k}", f"z{k}")
    spec = parse_bool("inputs a b1 b2 b3\noutputs z1 z2 z3\nz1 = a | b1\nz2 = a | b2\n"
                      "z3 = a | b3\n")
    mech = compile_netlist(spec, nl, library=LIB).mechanism
    preload = 1.3 * (0.5 + 0.02)
    share = preload * 1.3 + 0.5 + 0.02 + 0.02
    loads = part_loads(mech)
    assert loads["net a"] == pytest.approx(3 * share, rel=1e-3)
    assert loads["net b1"] == pytest.approx(share, rel=1e-3)
    for k in (1, 2, 3):
        assert loads[f"c{k}"] == pytest.approx(share, rel=1e-3)
        assert loads[f"c{k}"] < loads["net a"] / 2
