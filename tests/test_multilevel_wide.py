"""Designs too wide for a truth table (more than 20 inputs), from BLIF and Verilog: the spec is
valued by its network alone (checked against integer arithmetic, an independent reference),
compiled multi-level with no minimise, proved by the SAT miter against that network (an
injected error is caught and confirmed), and proved kinematically on sampled and
coverage-directed changes, with the count reported."""

from __future__ import annotations

import json
from functools import cache

import numpy as np
import pytest

from mechc.backends.design_json import design_from_json, design_to_json, dumps_design
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.blif import parse_blif
from mechc.frontends.spec_json import spec_from_json
from mechc.frontends.verilog import parse_verilog
from mechc.passes.map_sop import MapOptions
from mechc.passes.minimise import MinimiseOptions
from mechc.passes.multilevel import map_multilevel_hazard_free
from mechc.pipeline import CompileOptions, compile_spec
from mechc.proofs import ProofSettings, prove
from mechc.proofs.logic import prove_logic
from mechc.proofs.sat_equiv import check_equivalence
from tests.helpers import EXAMPLES

WIDE = EXAMPLES / "multilevel"


def adder_blif(bits: int, carry_in: bool = True) -> str:
    """A ripple adder as BLIF, written here (not the example file): full adders, each sum an
    XOR cover, each carry the majority cover."""
    ins = [f"A{i}" for i in range(bits)] + [f"B{i}" for i in range(bits)]
    ins += ["CI"] if carry_in else []
    lines = [".model add", ".inputs " + " ".join(ins),
             ".outputs " + " ".join([f"S{i}" for i in range(bits)] + ["CO"])]
    c = "CI" if carry_in else ""
    for i in range(bits):
        co = "CO" if i == bits - 1 else f"c{i + 1}"
        if c:
            lines += [f".names A{i} B{i} {c} S{i}", "100 1", "010 1", "001 1", "111 1",
                      f".names A{i} B{i} {c} {co}", "11- 1", "1-1 1", "-11 1"]
        else:
            lines += [f".names A{i} B{i} S{i}", "10 1", "01 1", f".names A{i} B{i} {co}", "11 1"]
        c = co
    return "\n".join(lines + [".end"]) + "\n"


def adder_reference(bits: np.ndarray, names: list[str], width: int) -> dict[str, np.ndarray]:
    """S and CO of A + B + CI by integer arithmetic on each column of ``bits``."""
    col = {nm: bits[k].astype(np.int64) for k, nm in enumerate(names)}
    a = sum(col[f"A{i}"] << i for i in range(width))
    b = sum(col[f"B{i}"] << i for i in range(width))
    t = a + b + col.get("CI", 0)
    out = {f"S{i}": (t >> i) & 1 for i in range(width)}
    out["CO"] = (t >> width) & 1
    return out


def random_bits(n: int, count: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).integers(0, 2, size=(n, count)).astype(bool)


@pytest.mark.parametrize("width, carry_in", [(12, False), (12, True), (16, True)])
def test_wide_blif_is_valued_by_its_network(width, carry_in):
    spec = parse_blif(adder_blif(width, carry_in), "add.blif")
    assert spec.n == 2 * width + carry_in > 20
    assert spec.network is not None and not spec.has_table()
    bits = random_bits(spec.n, 4096, width)
    got = spec.values_at(bits)
    want = adder_reference(bits, spec.inputs, width)
    for o in spec.outputs:
        assert np.array_equal(got[o], want[o]), o
    with pytest.raises(ValueError):
        spec.table("CO")  # no 2**n table is built for a wide spec


def test_wide_verilog_is_valued_by_its_network():
    spec = load_spec(WIDE / "adder16.v")
    assert spec.n == 33 and spec.network is not None
    bits = random_bits(spec.n, 4096, 1)
    got = spec.values_at(bits)
    want = adder_reference(bits, spec.inputs, 16)
    for o in spec.outputs:
        assert np.array_equal(got[o], want[o]), o
    assert spec.display["A3"] == "A[3]"


def test_wide_behavioural_verilog_compares_as_integers():
    """``a > b`` and ``a == b`` on 12-bit ports (24 inputs), elaborated by Yosys and valued by
    its gate network, against Python's integer comparison."""
    text = ("module cmp(input [11:0] a, input [11:0] b, output gt, output eq);\n"
            "  assign gt = a > b;\n  assign eq = a == b;\nendmodule\n")
    spec = parse_verilog(text, "cmp.v")
    assert spec.n == 24 and spec.network is not None
    bits = random_bits(24, 4096, 7)
    bits[12:, :1024] = bits[:12, :1024]  # a == b on a quarter of the vectors
    col = {nm: bits[k].astype(np.int64) for k, nm in enumerate(spec.inputs)}
    a = sum(col[f"a{i}"] << i for i in range(12))
    b = sum(col[f"b{i}"] << i for i in range(12))
    got = spec.values_at(bits)
    assert np.array_equal(got["gt"], (a > b).astype(np.int8))
    assert np.array_equal(got["eq"], (a == b).astype(np.int8))
    assert got["eq"].sum() >= 1024


def test_the_network_echo_reads_back_to_the_same_function():
    spec = load_spec(WIDE / "adder16.blif")
    echo = spec.to_json()
    assert echo["functions"] == {} and echo["network"].startswith(".model top")
    back = spec_from_json(json.loads(json.dumps(echo)))
    bits = random_bits(spec.n, 2048, 2)
    a, b = spec.values_at(bits), back.values_at(bits)
    assert all(np.array_equal(a[o], b[o]) for o in spec.outputs)


def test_sat_miter_against_a_network_spec_finds_a_wrong_network():
    """Two networks that differ in one carry (bit 5's majority without its term B5.c5) are
    not equivalent, and the counterexample the solver gives is confirmed by evaluation."""
    text = adder_blif(11)
    right = parse_blif(text, "right.blif")
    wrong = parse_blif(text.replace("-11 1\n.names A6", ".names A6", 1), "wrong.blif")
    assert wrong.n == 23 and wrong.outputs == right.outputs
    # a netlist equal to the right network: the one compiled from it
    lib = load_library()
    nl = map_multilevel_hazard_free(right.structure, right.inputs, right.outputs, lib,
                                    MapOptions(), MinimiseOptions(), None).netlist
    assert check_equivalence(nl, right).equivalent
    rep = prove_logic(nl, wrong)
    assert not rep.passed
    assert rep.coverage["method"] == "sat"
    f = rep.failures[0]
    v = np.array([[f["inputs"][x]] for x in wrong.inputs], dtype=bool)
    assert int(wrong.values_at(v)[f["output"]][0]) == f["expected"] != f["got"]


def test_levels_2_on_a_wide_spec_is_refused_naming_the_file(cli, tmp_path):
    spec = tmp_path / "wide.blif"
    spec.write_text(adder_blif(11))
    code, _, err = cli("compile", spec, "--levels", "2", "-o", tmp_path / "w.json")
    assert code == 2
    assert err.strip().startswith(f"mechc: error: {spec}: 23 inputs"), err
    assert "--levels 2" in err and "Traceback" not in err
    assert not (tmp_path / "w.json").exists()


@cache
def compiled(fmt: str) -> dict:
    spec = load_spec(WIDE / f"adder16.{fmt}")
    design = compile_spec(spec, CompileOptions(levels="multi"))
    return json.loads(dumps_design(design_to_json(design)))


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["v", "blif"])
def test_adder16_compiles_and_proves(fmt):
    obj = compiled(fmt)
    assert obj["stats"]["minimisation"]["skipped"]
    assert obj["stats"]["design_checks"]["passed"]
    design = design_from_json(obj, f"adder16.{fmt}.json")
    assert design.spec.network is not None and design.spec.n == 33
    lib = load_library()
    logic = prove(design, design.spec, lib, "logic", ProofSettings())
    assert logic.passed and logic.coverage["method"] == "sat" and logic.coverage["complete"]
    kin = prove(design, design.spec, lib, "kinematic", ProofSettings())
    assert kin.passed, kin.failures[:3]
    assert kin.cases > 0 and not kin.coverage.get("exhaustive", False)
    # the netlist is the adder: evaluated on random vectors against integer arithmetic
    bits = random_bits(33, 2048, 5)
    env = {x: bits[k] for k, x in enumerate(design.netlist.inputs)}
    nets = design.netlist.evaluate(env)
    want = adder_reference(bits, design.netlist.inputs, 16)
    for o, net in design.netlist.outputs.items():
        assert np.array_equal(nets[net], want[o].astype(bool)), o


@pytest.mark.slow
def test_an_injected_error_in_a_wide_design_file_is_caught_by_sat():
    obj = json.loads(json.dumps(compiled("blif")))
    ors = [c for c in obj["cells"] if c["type"] == "OR" and len(c["inputs"]) == 2]
    assert ors
    victim = ors[len(ors) // 2]
    victim["type"] = "AND"  # its own library cell's function changes: the logic is wrong
    victim["cell"] = next(c["cell"] for c in obj["cells"]
                          if c["type"] == "AND" and len(c["inputs"]) == 2)
    design = design_from_json(obj, "broken.json", mechanism=False)
    rep = prove(design, design.spec, load_library(), "logic", ProofSettings())
    assert not rep.passed and rep.coverage["method"] == "sat"
    f = rep.failures[0]
    v = np.array([[f["inputs"][x]] for x in design.spec.inputs], dtype=bool)
    assert int(design.spec.values_at(v)[f["output"]][0]) == f["expected"] != f["got"]


def test_a_hazard_no_candidate_can_cure_stops_the_compile_exit_1(cli, tmp_path, monkeypatch):
    """Never a design with an unreported hazard: where the cure fails on every candidate of a
    wide spec (no two-level fallback exists), the compile says which outputs, exit 1."""
    import mechc.passes.multilevel as ml

    monkeypatch.setattr(ml, "static_hazards", lambda nl, *a, **k: {"CO": 1})
    monkeypatch.setattr(ml, "cure_hazards", lambda *a, **k: None)
    spec = tmp_path / "wide.blif"
    spec.write_text(adder_blif(11))
    code, _, err = cli("compile", spec, "-o", tmp_path / "w.json")
    assert code == 1, err
    assert "no hazard-free network" in err and "CO" in err and "Traceback" not in err
    assert not (tmp_path / "w.json").exists()


def test_the_dynamic_proofs_plan_of_a_wide_design_is_a_walk_not_a_tour():
    """33 inputs: the plan is a seeded random walk of single-input changes (the Gray tour of
    2^33 vectors was once built before that choice, and the process ran out of memory)."""
    from mechc.proofs.dynamic import plan

    walk = plan(33, 16, 0)
    assert len(walk) == 64
    prev = 0
    for v in walk:
        assert 0 <= v < 1 << 33 and bin(v ^ prev).count("1") == 1  # one input at a time
        prev = v
