"""Cells users write: new logic types declared in the cell file, broken cell files, the source
of every cell recorded in the design, and each user cell proven alone at compile."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.errors import UsageError
from mechc.frontends.boolfile import parse_bool
from mechc.ir.logic_types import evaluate_type, table_from_function, table_from_truth
from mechc.ir.netlist import CellInst, Netlist
from mechc.pipeline import compile_netlist
from mechc.proofs import prove
from tests.helpers import EXAMPLES

MAJ_CELL = '''"""Majority of three: the threshold generator with weights 1, 1, 1 and threshold 2."""
from mechc.cells.cell import Cell
from mechc.stdlib.threshold import ThresholdCell

PARAMS = {"weights": [1, 1, 1], "thresholds": [2]}


class Maj3(Cell):
    name = "maj3"
    type = "MAJ"
    %s
    min_inputs = max_inputs = 3
    description = "majority of three"

    @classmethod
    def cost(cls, n_inputs):
        return ThresholdCell.cost(n_inputs)

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        return ThresholdCell.synthesise(cid, ctx, n_inputs, PARAMS, demand)

    @classmethod
    def kinematics(cls, part, fixed, size, extra=None):
        return ThresholdCell.kinematics(part, fixed, size, extra)
'''

#: A cell that claims XOR and is built as an OR bar (wrong on purpose).
FAKE_XOR = '''from mechc.cells.builder import Builder
from mechc.cells.cell import Cell


class FakeXor(Cell):
    name = "fake_xor"
    type = "XOR"

    @classmethod
    def cost(cls, n_inputs):
        return 1

    @classmethod
    def synthesise(cls, cid, ctx, n_inputs, params, demand):
        b = Builder(cid, ctx)
        S, p = ctx.stroke, ctx.pitch
        pins = cls.input_names(n_inputs)
        sigs = [b.input_slider(pin, 0.0, -i * p, 1.5 * S) for i, pin in enumerate(pins)]
        bar, loads = b.or_bar("bar", sigs, 1.5 * S + ctx.bar / 2, demand)
        b.output(bar, "Z", reach=bar.x + S)
        return b.finish(dict(zip(pins, loads)))
'''

#: The same as a correct cell: the standard XOR under another name (the control).
GOOD_XOR = '''from mechc.stdlib.xor_gate import XorGate


class MyXor(XorGate):
    name = "my_xor"

    @classmethod
    def cost(cls, n_inputs):
        return 1
'''

MAJ_BLIF = """.model maj
.inputs a b c
.outputs m
.names a b c m
11- 1
1-1 1
-11 1
.end
"""


def maj_dir(tmp_path, declare='function = "A&B | A&C | B&C"', name="cells"):
    d = tmp_path / name
    d.mkdir()
    (d / "maj3.py").write_text(MAJ_CELL % declare)
    return d


def test_truth_and_function_declare_the_same_table():
    by_fn = table_from_function("A&B | A&C | B&C", ["A", "B", "C"], "<test>")
    by_truth = table_from_truth("0001 0111", 3)
    # row r: inputs spell r in binary, first pin most significant; majority by counting bits
    brute = tuple(int(bin(r).count("1") >= 2) for r in range(8))
    assert by_fn == by_truth == brute
    with pytest.raises(ValueError, match="8"):
        table_from_truth("0001", 3)


@pytest.mark.parametrize("declare", ['function = "A&B | A&C | B&C"', 'truth = "00010111"'])
def test_maj_cell_in_a_hand_netlist_passes_logic_and_kinematic_proofs(tmp_path, declare):
    lib = load_library([str(maj_dir(tmp_path, declare))])
    assert not lib.broken and lib["maj3"].type == "MAJ"
    nl = Netlist(["a", "b", "c"])
    nl.add_cell(CellInst("c1", "maj3", "MAJ", ("a", "b", "c"), ("z",)))
    nl.set_output("z", "z")
    spec = parse_bool("inputs a b c\noutputs z\nz = a & b | a & c | b & c\n")
    d = compile_netlist(spec, nl, library=lib)
    assert d.stats["design_checks"]["passed"], d.stats["design_checks"]["failed"]
    for level in ("logic", "kinematic"):
        r = prove(d, spec, lib, level)
        assert r.passed, r.failures
    # the logic level really uses the declared table: against OR of three it must fail
    wrong = parse_bool("inputs a b c\noutputs z\nz = a | b | c\n")
    r = prove(d, wrong, lib, "logic")
    assert not r.passed and r.failure_count == 3  # 100, 010, 001
    x = [np.array([0, 1, 1, 0], bool), np.array([0, 1, 0, 1], bool), np.array([1, 0, 1, 1], bool)]
    assert evaluate_type("MAJ", x, {}, 4).tolist() == [False, True, True, True]


def test_maj_cell_from_blif_is_mapped_and_simulates_without_cells(cli, tmp_path):
    cells = maj_dir(tmp_path)
    blif = tmp_path / "maj.blif"
    blif.write_text(MAJ_BLIF)
    design = tmp_path / "maj.json"
    rc, out, err = cli("compile", blif, "--cells", cells, "-o", design)
    assert rc == 0, err
    d = json.loads(design.read_text())
    assert [(c["cell"], c["type"]) for c in d["cells"]] == [("maj3", "MAJ")]
    src = d["cell_sources"]["maj3"]
    assert src["library"] == "user" and src["path"] == str((cells / "maj3.py").resolve())
    import hashlib
    assert src["sha256"] == hashlib.sha256((cells / "maj3.py").read_bytes()).hexdigest()
    # the passing proof of the cell alone is among the design checks
    assert any("maj3" in c["where"] and "computes its type MAJ" in c["name"] and c["passed"]
               for c in d["mechanism"]["checks"])
    for level in ("logic", "kinematic"):
        rc, out, err = cli("simulate", design, "--level", level)  # no --cells
        assert rc == 0 and "PASSED" in out, err


def test_unknown_type_without_declaration_is_named(tmp_path):
    d = maj_dir(tmp_path, declare="")
    lib = load_library([str(d)])
    assert "maj3" not in lib.cells
    msg = lib.broken[str(d / "maj3.py")]
    assert msg.startswith(f"{d / 'maj3.py'}:8:") and "unknown logic type 'MAJ'" in msg
    assert "function =" in msg


def test_declaration_contradicting_a_builtin_type_is_refused(tmp_path):
    d = tmp_path / "c"
    d.mkdir()
    (d / "x.py").write_text(GOOD_XOR + '    function = "A | B"\n')
    lib = load_library([str(d)])
    assert "my_xor" not in lib.cells
    assert "inputs 11" in lib.broken[str(d / "x.py")]


def test_broken_cell_file_does_not_stop_an_unrelated_compile(cli, tmp_path):
    cells = maj_dir(tmp_path)
    (cells / "broken.py").write_text("from mechc.cells.cell import Cell\n\n\n"
                                     "class X(Cell):\n    name = 'x'\n    def oops(:\n")
    design = tmp_path / "sorter.json"
    rc, out, err = cli("compile", EXAMPLES / "sorter.bool", "--cells", cells, "-o", design)
    assert rc == 0 and design.exists()
    assert err.count(f"{cells / 'broken.py'}:6:") == 1 and "SyntaxError" in err
    # the good cell of the same directory is loaded; a design needing a missing cell says where
    lib = load_library([str(cells)])
    assert "maj3" in lib.cells
    with pytest.raises(UsageError, match="broken.py:6"):
        lib["x"]


def test_a_wrong_cell_fails_compile_naming_it(cli, tmp_path):
    spec = tmp_path / "x.bool"
    spec.write_text("inputs a b\noutputs z\nz = a ^ b\n")
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "fake_xor.py").write_text(FAKE_XOR)
    out_json = tmp_path / "x.json"
    rc, out, err = cli("compile", spec, "--cells", bad, "-o", out_json)
    # the design's own kinematic proof finds z wrong at a=1 b=1: the design is not handed out
    assert rc == 1 and not out_json.exists()
    assert "fake_xor" in err and "inputs A=1 B=1" in err and "computes its type XOR" in err
    assert "PROOF FAILED: kinematic proof" in err and "a=1 b=1" in err and "NOT written" in err
    # --no-prove writes it for inspection (the cell's own check still fails compile)
    rc, out, err = cli("compile", spec, "--cells", bad, "-o", out_json, "--no-prove")
    assert rc == 1 and out_json.exists() and "PROOF FAILED" not in err
    # control: a correct user XOR passes the same proof
    good = tmp_path / "good"
    good.mkdir()
    (good / "my_xor.py").write_text(GOOD_XOR)
    rc, out, err = cli("compile", spec, "--cells", good, "-o", tmp_path / "y.json")
    assert rc == 0, err
    assert "cells used: XOR my_xor" in out


def test_a_changed_or_missing_cell_file_is_detected(cli, tmp_path):
    cells = maj_dir(tmp_path)
    pla = tmp_path / "majority.pla"
    shutil.copy(EXAMPLES / "majority.pla", pla)
    design = tmp_path / "m.json"
    assert cli("compile", pla, "--cells", cells, "-o", design)[0] == 0
    f = cells / "maj3.py"
    f.write_text(f.read_text() + "# edited\n")
    rc, _, err = cli("simulate", design, "--level", "logic")
    assert rc == 2 and f"{f.resolve()} changed since the design was compiled" in err
    rc, out, err = cli("simulate", design, "--level", "logic", "--cells", cells)
    assert rc == 0 and "differs, and is used as --cells asks" in err
    f.unlink()
    rc, _, err = cli("simulate", design, "--level", "logic")
    assert rc == 2 and f"compiled from {f.resolve()}, which no longer exists" in err


def test_documented_maj_cell_is_chosen_by_cost_for_majority(cli, tmp_path):
    """docs/write-a-cell.md's MAJ example, run as printed: one MAJ cell of 15 parts against 17
    for three ANDs and an OR, proven without --cells at the kinematic level."""
    import re

    from tests.test_docs import DOC

    code = re.search(r"```python\n(# my_cells/maj3.py\n.*?)```", DOC.read_text(), re.S)
    cells = tmp_path / "my_cells"
    cells.mkdir()
    (cells / "maj3.py").write_text(code.group(1))
    design, plain = tmp_path / "m.json", tmp_path / "p.json"
    rc, out, err = cli("compile", EXAMPLES / "majority.pla", "--cells", cells, "-o", design)
    assert rc == 0, err
    d = json.loads(design.read_text())
    assert [c["type"] for c in d["cells"]] == ["MAJ"] and d["stats"]["parts"] == 15
    # the doc's 17: the two-level design (auto may now find a multi-level one of fewer)
    assert cli("compile", EXAMPLES / "majority.pla", "-o", plain, "--levels", "2")[0] == 0
    assert json.loads(plain.read_text())["stats"]["parts"] == 17
    rc, out, err = cli("simulate", design, "--level", "kinematic")
    assert rc == 0 and "PASSED" in out, err


def test_a_broken_file_in_the_standard_library_does_not_stop_commands(cli, tmp_path,
                                                                      monkeypatch):
    """A copy of stdlib/ with one broken file added: compiling an unrelated spec still works and
    the file is named once; a design that needs a missing cell names it (exit 2)."""
    import mechc.cells.library as library

    root = EXAMPLES.parent
    pkg = tmp_path / "std_copy"
    shutil.copytree(root / "stdlib", pkg)
    (pkg / "zz_broken.py").write_text("import math\n\nmath.no_such_function()\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(library, "STDLIB", "std_copy")
    monkeypatch.setattr(library, "_CACHE", {})
    design = tmp_path / "s.json"
    rc, out, err = cli("compile", EXAMPLES / "sorter.bool", "-o", design)
    assert rc == 0 and design.exists()
    assert err.count("zz_broken.py:3:") == 1 and "AttributeError" in err
    d = json.loads(design.read_text())
    d["cells"][0]["cell"] = "no_such_cell"
    d["cell_sources"] = {"no_such_cell": {"library": "standard"}}
    design.write_text(json.dumps(d))
    rc, _, err = cli("simulate", design, "--level", "kinematic")  # moves the cells' geometry
    assert rc == 2 and "unknown library cell 'no_such_cell'" in err and "zz_broken.py:3" in err
