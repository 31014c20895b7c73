"""The command line: malformed input never gives a traceback, outputs are never clobbered,
and the logic-level proof catches a wrong design."""

from __future__ import annotations

import json
import re

import pytest

from tests.helpers import EXAMPLES, run_subprocess

GOOD = "inputs A B\noutputs Z\nZ = A & B\n"

# Malformed specs: (file name, content). Each must give exit 2 and one line "file:L:C: error: ..."
MALFORMED = [
    ("empty.bool", b""),
    ("blank.bool", b"\n\n   \n"),
    ("comment_only.bool", b"# nothing here\n"),
    ("junk.bool", bytes(range(256))),
    ("nul.bool", b"inputs A\x00B\n"),
    ("latin1.bool", "inputs \xe9t\u00e9\n".encode("latin-1")),
    ("bad_token.bool", b"inputs A B\noutputs Z\nZ = A @ B\n"),
    ("unbalanced_open.bool", b"inputs A B\noutputs Z\nZ = ((A & B)\n"),
    ("unbalanced_close.bool", b"inputs A B\noutputs Z\nZ = A & B))\n"),
    ("unknown_name.bool", b"inputs A B\noutputs Z\nZ = A & C\n"),
    ("dup_input.bool", b"inputs A B A\noutputs Z\nZ = A\n"),
    ("dup_output_def.bool", b"inputs A\noutputs Z\nZ = A\nZ = ~A\n"),
    ("undefined_output.bool", b"inputs A\noutputs Z W\nZ = A\n"),
    ("huge_minterm.bool", b"inputs A B\noutputs Z\nZ = minterms(" + b"9" * 400 + b")\n"),
    ("minterm_range.bool", b"inputs A B\noutputs Z\nZ = minterms(0, 4)\n"),
    ("on_and_dc.bool", b"inputs A B\noutputs Z\nZ = minterms(1, 2) dontcare(2)\n"),
    ("no_outputs.bool", b"inputs A B\n"),
    ("outputs_first.bool", b"outputs Z\ninputs A\n"),
    ("missing_eq.bool", b"inputs A\noutputs Z\nZ A\n"),
    ("trailing_op.bool", b"inputs A\noutputs Z\nZ = A |"),
    ("double_op.bool", b"inputs A B\noutputs Z\nZ = A & & B\n"),
    ("assign_input.bool", b"inputs A\noutputs Z\nA = 1\n"),
    ("bad_const.bool", b"inputs A\noutputs Z\nZ = 7\n"),
    ("too_many_inputs.bool", ("inputs " + " ".join(f"v{i}" for i in range(40)) + "\n").encode()),
    ("tabs_and_junk.bool", b"inputs\tA\noutputs\tZ\nZ = A \x7f\n"),
    ("minterm_word.bool", b"inputs A\noutputs Z\nZ = minterms(one)\n"),
    ("pla_empty.pla", b""),
    ("pla_width.pla", b".i 3\n.o 1\n11 1\n"),
    ("pla_char.pla", b".i 2\n.o 1\n1z 1\n"),
    ("pla_type.pla", b".i 2\n.o 1\n.type xyz\n"),
    ("pla_junk.pla", b"\x89PNG\r\n\x1a\n\x00\x00"),
    ("pla_onoff.pla", b".i 1\n.o 1\n.type fr\n1 1\n1 0\n"),
    ("pla_ilb.pla", b".i 2\n.o 1\n.ilb a\n"),
    ("unknown_suffix.txt", b"inputs A\n"),
]


@pytest.mark.parametrize("name, content", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_malformed_spec_exit_2_one_line_no_traceback(cli, tmp_path, name, content):
    spec = tmp_path / name
    spec.write_bytes(content)
    out = tmp_path / "out.json"
    out.write_text("precious\n")
    code, stdout, err = cli("compile", spec, "-o", out)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert re.match(rf"^{re.escape(str(spec))}:\d+:\d+: error: \S", lines[0]), lines[0]
    assert "Traceback" not in err
    assert out.read_text() == "precious\n"  # the existing output is untouched


def test_malformed_via_real_entry_point(tmp_path):
    spec = tmp_path / "x.bool"
    spec.write_bytes(bytes(range(256)) * 4)
    r = run_subprocess("compile", spec, "-o", tmp_path / "y.json")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert re.search(r"x\.bool:1:1: error: binary data", r.stderr)
    assert not (tmp_path / "y.json").exists()


def test_missing_file(cli, tmp_path):
    code, _, err = cli("compile", tmp_path / "nope.bool")
    assert code == 2 and "file not found" in err


def test_output_into_missing_directory(cli, tmp_path):
    spec = tmp_path / "a.bool"
    spec.write_text(GOOD)
    code, _, err = cli("compile", spec, "-o", tmp_path / "no" / "dir" / "a.json")
    assert code == 2 and "does not exist" in err


def test_argparse_errors_exit_2(tmp_path):
    r = run_subprocess("compile")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    r = run_subprocess("compile", "x.bool", "--fan-in", "1")
    assert r.returncode == 2 and "at least 2" in r.stderr


def test_help_for_every_command():
    for args in (["--help"], ["compile", "--help"], ["simulate", "--help"], ["cells", "--help"]):
        r = run_subprocess(*args)
        assert r.returncode == 0 and "usage: mechc" in r.stdout
    assert "mechc 0." in run_subprocess("--version").stdout


def mutate(spec_text: str, minterm: int) -> str:
    """The sorter spec with one care minterm flipped (on <-> off)."""
    lines = spec_text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith("Z = minterms("):
            on = [int(x) for x in line.split("minterms(")[1].split(")")[0].split(",")]
            on = sorted(set(on) ^ {minterm})
            lines[i] = f"Z = minterms({', '.join(map(str, on))}) dontcare(4, 7, 8, 11)"
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("minterm", [0, 3, 6, 13])  # off->on and on->off flips
def test_simulate_against_mutated_spec_fails(cli, tmp_path, minterm):
    design = tmp_path / "s.json"
    assert cli("compile", EXAMPLES / "sorter.bool", "-o", design)[0] == 0
    mutated = tmp_path / "mutated.bool"
    mutated.write_text(mutate((EXAMPLES / "sorter.bool").read_text(), minterm))
    report = tmp_path / "r.json"
    code, out, _ = cli("simulate", design, "--level", "logic", "--spec", mutated, "--report",
                       report)
    assert code == 1 and "FAILED" in out
    r = json.loads(report.read_text())
    assert r["passed"] is False and r["level"] == "logic" and r["cases"] == 16
    assert len(r["failures"]) == 1
    f = r["failures"][0]
    row = sum(f["inputs"][k] << (3 - i) for i, k in enumerate("ABCD"))
    assert row == minterm


def test_simulate_passes_on_own_spec_and_on_spec_file(cli, tmp_path):
    design = tmp_path / "s.json"
    cli("compile", EXAMPLES / "sevenseg.bool", "-o", design)
    report = tmp_path / "r.json"
    code, out, _ = cli("simulate", design, "--level", "logic", "--report", report)
    assert code == 0 and "PASSED" in out
    r = json.loads(report.read_text())
    assert r["passed"] is True and r["failures"] == [] and r["cases"] == 16
    code, out, _ = cli("simulate", EXAMPLES / "sorter.bool", "--level", "logic")
    assert code == 0


def test_a_solver_failure_names_the_run_that_tells_it_from_the_mechanism(cli, tmp_path):
    """One solver iteration per step breaks the full adder's joints: the proof runs the first
    failing changes again at twice the iterations and says how many passed there; the changes
    beyond that cap keep the hint (twice the iterations, half the step, from the settings the
    report used); a passing proof says nothing of it."""
    report = tmp_path / "r.json"
    code, out, _ = cli("simulate", EXAMPLES / "full_adder.bool", "--level", "dynamic",
                       "--iterations", "1", "--report", report)
    r = json.loads(report.read_text())
    assert code == 1 and {"solver", "settle"} & set(r["failure_kinds"])
    rc = r["recheck"]
    assert f"re-run at 2 iterations: {rc['passed_finer']} of {rc['changes']} failing" in out
    hint = next(x for x in out.splitlines() if "can be the solver's" in x)
    assert "were not re-run" in hint
    assert "--iterations 2 " in hint and f"--dt {r['settings']['dt_s'] / 2:g};" in hint
    code, out, _ = cli("simulate", EXAMPLES / "full_adder.bool", "--level", "dynamic")
    assert code == 0 and "can be the solver's" not in out and "re-run at" not in out


def test_simulate_rejects_mismatched_interface(cli, tmp_path):
    design = tmp_path / "s.json"
    cli("compile", EXAMPLES / "sorter.bool", "-o", design)
    other = tmp_path / "o.bool"
    other.write_text("inputs A B C\noutputs Z\nZ = A\n")
    code, _, err = cli("simulate", design, "--spec", other)
    assert code == 2 and "differ" in err


def test_simulate_rejects_corrupt_design(cli, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "mechc", "version": 1, "inputs": [}')
    code, _, err = cli("simulate", bad)
    assert code == 2 and re.search(r"bad\.json:1:\d+: error: invalid JSON", err)
    design = tmp_path / "s.json"
    cli("compile", EXAMPLES / "sorter.bool", "-o", design)
    d = json.loads(design.read_text())
    del d["cells"][0]["type"]
    bad.write_text(json.dumps(d))
    code, _, err = cli("simulate", bad)
    assert code == 2 and "not a valid mechc design" in err


def test_cells_lists_the_library(cli):
    code, out, _ = cli("cells")
    assert code == 0
    for t in ["AND", "OR", "NOT", "NAND", "NOR", "AND_NOT", "OR_NOT", "XOR", "XNOR"]:
        assert re.search(rf"\b{t}\b", out)
    code, out, _ = cli("cells", "--json")
    items = json.loads(out)
    assert {i["type"] for i in items} >= {"AND", "OR", "NOT"}


def test_user_cell_directory_is_picked_up_without_compiler_edits(cli, tmp_path):
    (tmp_path / "my_and.py").write_text(
        "from mechc.stdlib.and_gate import AndGate\n\n\nclass CheapAnd(AndGate):\n"
        "    name = 'cheap_and'\n    max_inputs = 2\n    description = 'test cell'\n\n"
        "    @classmethod\n    def cost(cls, n):\n        return 1\n")
    code, out, _ = cli("cells", "--cells", tmp_path)
    assert code == 0 and "cheap_and" in out
    design = tmp_path / "d.json"
    spec = tmp_path / "s.bool"
    spec.write_text("inputs a b\noutputs z\nz = a & b\n")
    code, out, _ = cli("compile", spec, "-o", design, "--cells", tmp_path)
    assert code == 0
    assert json.loads(design.read_text())["cells"][0]["cell"] == "cheap_and"
    # the summary says which cell was used, and that it stands in for the standard one
    assert "cells used: AND cheap_and" in out
    assert f"user cell cheap_and ({tmp_path / 'my_and.py'}) for AND, instead of the standard " \
        "and" in out


def test_user_cell_without_mechanism_is_a_clear_error(cli, tmp_path):
    (tmp_path / "bare.py").write_text(
        "from mechc.cells.cell import Cell\n\n\nclass Bare(Cell):\n    name = 'bare_and'\n"
        "    type = 'AND'\n    description = 'no geometry'\n\n    @classmethod\n"
        "    def cost(cls, n):\n        return 0\n")
    spec = tmp_path / "s.bool"
    spec.write_text("inputs a b\noutputs z\nz = a & b\n")
    code, _, err = cli("compile", spec, "-o", tmp_path / "d.json", "--cells", tmp_path)
    assert code == 2 and "has no mechanism" in err and "Traceback" not in err
    assert "'bare_and'" in err and "bare.py" in err and not (tmp_path / "d.json").exists()


def test_broken_user_cell_reports_file_and_line(cli, tmp_path):
    (tmp_path / "broken.py").write_text("x = 1\nraise RuntimeError('boom')\n")
    code, out, err = cli("cells", "--cells", tmp_path)
    # the other cells are still listed; the broken file is a warning with its line
    assert code == 0 and "xor" in out
    assert "broken.py:2:" in err and "boom" in err and "Traceback" not in err


def test_output_to_a_device_is_written_not_replaced(cli, tmp_path):
    import os
    import stat

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    import threading

    got = []
    t = threading.Thread(target=lambda: got.append(open(fifo).read()))
    t.start()
    code, _, err = cli("compile", EXAMPLES / "sorter.bool", "-o", fifo)
    t.join(10)
    assert code == 0, err
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)  # still a pipe, not replaced by a file
    assert '"format": "mechc"' in got[0]


def test_compile_never_writes_a_design_simulate_refuses(cli, tmp_path):
    """An absurd output load makes numbers no reader accepts: compile refuses (exit 2), names
    the options, writes nothing, and leaves an existing file as it was."""
    out = tmp_path / "s.json"
    out.write_text("keep me")
    rc, _, err = cli("compile", EXAMPLES / "sorter.bool", "-o", out, "--output-load", "1e8")
    assert rc == 2
    # refused before compiling: more than one bar of the plate carries at yield (strength)
    assert "refusing to compile" in err and "--output-load 1e+08 N" in err
    assert out.read_text() == "keep me"


def test_unreadable_spec_paths_have_no_line_and_column(cli, tmp_path):
    rc, _, err = cli("compile", tmp_path)
    assert rc == 2 and f"{tmp_path}: is a directory, expected a spec file" in err
    rc, _, err = cli("compile", tmp_path / "missing.bool")
    assert rc == 2 and f"{tmp_path / 'missing.bool'}: file not found" in err
    assert ":1:1:" not in err


def test_a_spec_compiled_in_memory_is_built_as_compile_builds_it(tmp_path):
    """simulate, view, draw and export compile a spec given instead of a design as `mechc
    compile` does: Verilog multi-level. (They once took the default from simulate's `--spec
    OTHER`, absent, and built a Verilog file two-level: cmp8.v, 95 cells compiled, 1909
    with 671 amplifiers when proved.)"""
    from mechc.cli.common import compile_path
    from mechc.cli.main import build_parser

    spec = str(EXAMPLES / "multilevel" / "adder4.v")
    parser = build_parser()
    built = {}
    for argv in (["compile", spec, "-o", str(tmp_path / "a.json")], ["simulate", spec],
                 ["view", spec], ["draw", spec], ["export", spec, "-o", str(tmp_path / "a.dxf")]):
        args = parser.parse_args(argv)
        d = compile_path(spec, args, mechanism=False)
        built[argv[0]] = (d.stats.get("levels", {}).get("chosen", "2"), len(d.netlist.cells))
    assert built["compile"][0] == "multi"
    assert set(built.values()) == {built["compile"]}, built
