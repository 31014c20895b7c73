"""Held-out robustness: odd specs and odd command lines that no example covers.

Each case is one a user can type: a flow table of one state, outputs all unspecified,
unreachable rows, KISS2 with ``-`` cubes and ``*`` next states, spec files with CRLF line
ends, a byte-order mark or tabs, and every design-reading command given a file that is not a
design. The rule checked is the project's: a spec compile accepts passes its own proofs
(here: ``mechc simulate`` at the default dynamic level), bad input exits 2 with one error line
naming the file, never a traceback, and nothing the user had is overwritten on failure.
The random held-out sweep is ``benchmarks/fsm_heldout.py``; two of its tables run here
(marked slow).
"""

from __future__ import annotations

import gzip
import json
import sys
from pathlib import Path

import pytest

from mechc.frontends import load_spec

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

# ---- sequential: odd flow tables, compile then the default (dynamic) proof --------------------

ODD_TABLES = {
    "single_state.fsm": "inputs x\noutputs z\ncolumns 0 1\nflow\n1: (1) (1) | 1\n",
    "all_outputs_unspecified.fsm": (
        "inputs x1 x2\noutputs z1 z2\ncolumns 00 01 11 10\nflow\n1: (1) 3 - 2 | - -\n"
        "2: 4 - 5 (2) | - -\n3: 1 (3) - - | - -\n4: (4) 3 - 2 | - -\n5: - - (5) 6 | - -\n"
        "6: 1 - - (6) | - -\n"),
    "unreachable_rows.fsm": (
        "inputs x\noutputs z\ncolumns 0 1\nflow\na: (a) b | 0\nb: a (b) | 1\nc: (c) d | 1\n"
        "d: c (d) | 0\n"),
    "dash_and_star.kiss2": (
        ".i 2\n.o 1\n.s 3\n.r a\n-0 a a 0\n01 a b 0\n11 b b 1\n01 b b 1\n00 b c -\n"
        "-0 c c 1\n11 c * -\n.e\n"),
}


@pytest.mark.parametrize("name", sorted(ODD_TABLES))
def test_odd_flow_tables_compile_and_pass_the_dynamic_proof(cli, tmp_path, name):
    src = tmp_path / name
    src.write_text(ODD_TABLES[name])
    out = tmp_path / "d.json"
    code, _, err = cli("compile", "-q", src, "-o", out)
    assert code == 0, err
    code, stdout, err = cli("simulate", out, "--jobs", "1")  # default level: dynamic
    assert code == 0, stdout + err
    assert "PASSED: level dynamic" in stdout


def test_a_state_with_no_stable_column_is_refused_at_its_row(cli, tmp_path):
    src = tmp_path / "nostable.fsm"
    src.write_text("inputs x\noutputs z\ncolumns 0 1\nflow\na: (a) b | 0\nb: a c | 1\n"
                   "c: a (c) | 1\n")
    code, _, err = cli("compile", src)
    assert code == 2
    assert f"{src}:6:1: error: state b is missing from its own row" in err
    assert "Traceback" not in err and not (tmp_path / "nostable.json").exists()


# ---- every front end: CRLF, a byte-order mark and tabs read as the plain file ------------------

PLAIN = {
    ".bool": "inputs a b c\noutputs z w\nz = a & ~b | c\nw = a\n",
    ".pla": ".i 3\n.o 2\n.ilb a b c\n.ob z w\n10- 11\n--1 10\n1-- 01\n.e\n",
    ".blif": (".model m\n.inputs a b c\n.outputs z w\n.names a b c z\n10- 1\n--1 1\n"
              ".names a w\n1 1\n.end\n"),
    ".fsm": (EXAMPLES / "speedctl.fsm").read_text(),
    ".kiss2": ".i 1\n.o 1\n.s 2\n0 s0 s0 0\n1 s0 s1 0\n1 s1 s1 1\n0 s1 s0 1\n.e\n",
}
VARIANTS = {
    "crlf": lambda t: t.replace("\n", "\r\n").encode(),
    "bom": lambda t: b"\xef\xbb\xbf" + t.encode(),
    "tabs": lambda t: t.replace(" ", "\t").encode(),
}


def _spec_json(path: Path) -> dict:
    d = load_spec(path).to_json()
    d.pop("source")
    return d


@pytest.mark.parametrize("variant", sorted(VARIANTS))
@pytest.mark.parametrize("suffix", sorted(PLAIN))
def test_line_ends_bom_and_tabs_read_as_the_plain_spec(tmp_path, suffix, variant):
    if variant == "tabs" and suffix == ".pla":
        pytest.skip("a PLA row's cube and outputs are split by blanks, tabs included: "
                    "covered by the .bool/.blif/.fsm/.kiss2 cases")
    plain = tmp_path / f"plain{suffix}"
    plain.write_text(PLAIN[suffix])
    odd = tmp_path / f"{variant}{suffix}"
    odd.write_bytes(VARIANTS[variant](PLAIN[suffix]))
    assert _spec_json(odd) == _spec_json(plain)


def test_crlf_bool_compiles_and_proves(cli, tmp_path):
    src = tmp_path / "crlf.bool"
    src.write_bytes(VARIANTS["crlf"](PLAIN[".bool"]))
    assert cli("compile", "-q", src, "-o", tmp_path / "c.json")[0] == 0
    code, stdout, err = cli("simulate", tmp_path / "c.json", "--level", "kinematic")
    assert code == 0, stdout + err


# ---- bad specs: exit 2, file:line:col, the old output kept -------------------------------------

BAD_SPECS = {
    "empty.bool": (b"", "empty.bool:1:1: error: empty specification"),
    "unicode.bool": ("inputs α b\noutputs z\nz = α\n".encode(),
                     "unicode.bool:1:8: error: unexpected character 'α'"),
    "bad_byte.bool": (b"inputs a b\noutputs z\nz = a & \xff\n",
                      "bad_byte.bool:3:9: error: invalid UTF-8 byte 0xff"),
    "output_is_input.bool": (b"inputs a b\noutputs a\na = b\n",
                             "output_is_input.bool:2:9: error: duplicate name 'a'"),
    "long_name.bool": (f"inputs {'x' * 300} b\noutputs z\nz = b\n".encode(),
                       "long_name.bool:1:8: error: name 'x"),
    "zero_inputs.pla": (b".i 0\n.o 1\n 1\n.e\n", "zero_inputs.pla:1:1: error: '.i' must be"),
    "short_row.pla": (b".i 2\n.o 1\n1 1\n.e\n", "short_row.pla:3:1: error: product term"),
    "cycle.blif": (b".model m\n.inputs a\n.outputs z\n.names a z z\n11 1\n.end\n",
                   "cycle.blif:4:12: error: combinational cycle"),
    "empty.blif": (b"", "empty.blif:1:1: error:"),
    "unstable.kiss2": (b".i 1\n.o 1\n0 a b 0\n0 b a 1\n1 a a 0\n1 b b 1\n.e\n",
                       "unstable.kiss2:3:5: error: row a oscillates in column 0"),
}


@pytest.mark.parametrize("name", sorted(BAD_SPECS))
def test_bad_specs_exit_2_at_file_line_col_and_keep_the_old_output(cli, tmp_path, name):
    data, want = BAD_SPECS[name]
    src = tmp_path / name
    src.write_bytes(data)
    out = tmp_path / "existing.json"
    out.write_text("the user's old file\n")
    code, _, err = cli("compile", src, "-o", out)
    assert code == 2
    assert want in err.replace(str(tmp_path) + "/", "")
    assert "Traceback" not in err
    assert out.read_text() == "the user's old file\n"


# ---- the command line: files that are not what a command reads --------------------------------


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """A good design, a proof report and a trace written by simulate, a truncated .json.gz, a
    truncated .json, a directory named like a design, a missing file."""
    from mechc.cli.main import main

    d = tmp_path_factory.mktemp("cli")
    spec = d / "and.bool"
    spec.write_text("inputs a b\noutputs z\nz = a & b\n")
    good = d / "good.json"
    assert main(["compile", "-q", str(spec), "-o", str(good)]) == 0
    assert main(["simulate", str(good), "--level", "logic", "--report", str(d / "rep.json")]) == 0
    assert main(["simulate", str(good), "--level", "kinematic", "--trace",
                 str(d / "trace.json")]) == 0
    gz = gzip.compress(good.read_bytes())
    (d / "good.json.gz").write_bytes(gz)
    (d / "trunc.json.gz").write_bytes(gz[: len(gz) // 2])
    (d / "trunc.json").write_bytes(good.read_bytes()[:500])
    (d / "dir.json").mkdir()
    return {"spec": spec, "good": good, "good_gz": d / "good.json.gz", "report": d / "rep.json",
            "trace": d / "trace.json", "trunc_gz": d / "trunc.json.gz",
            "trunc": d / "trunc.json", "dir": d / "dir.json", "missing": d / "missing.json"}


BAD_DESIGNS = {
    "missing": "file not found",
    "dir": "is a directory",
    "report": "not a mechc design",
    "trace": "not a mechc design",
    "trunc_gz": "a damaged gzip file",
    "trunc": "invalid JSON",
}
COMMANDS = {
    "simulate": ["--level", "logic"],
    "draw": [],
    "export": ["--format", "bom"],
    "view": [],
    "tolerance": ["--samples", "2"],
}


@pytest.mark.parametrize("kind", sorted(BAD_DESIGNS))
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_design_reader_refuses_what_is_not_a_design(cli, files, tmp_path, command, kind):
    out = tmp_path / "out.x"
    extra = [] if command in ("simulate", "tolerance") else ["-o", out]
    code, stdout, err = cli(command, files[kind], *COMMANDS[command], *extra)
    assert code == 2, stdout + err
    assert BAD_DESIGNS[kind] in err and str(files[kind].name) in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_tolerance_reads_a_gzip_design_as_the_others_do(cli, files):
    """It refused every .json.gz ("expected a compiled design (.json)") though compile writes
    them and simulate, draw, export and view read them."""
    code, stdout, err = cli("tolerance", files["good_gz"], "--samples", "4", "--seed", "1")
    assert code in (0, 1), stdout + err  # a verdict on the design, not a refusal of the file
    assert "samples" in stdout or "yield" in stdout


@pytest.mark.parametrize("kind, want", [
    ("good", "is a compiled design, not a spec"),
    ("good_gz", "is a compiled design, not a spec"),
    ("report", "is a compiled design, not a spec"),
    ("dir", "is a directory, expected a spec file"),
])
def test_compile_says_what_is_wrong_with_the_spec_before_the_output(cli, files, kind, want):
    """Without -o the output defaults to SPEC.json: given a design (or a directory named
    x.json) compile said "refusing to overwrite the spec", hiding that it was no spec."""
    before = files["good"].read_bytes()
    code, _, err = cli("compile", files[kind])
    assert code == 2 and want in err and "Traceback" not in err
    assert files["good"].read_bytes() == before


@pytest.mark.parametrize("out", ["/nonexistent-dir/x.json", "{dir}", "{spec}/x.json"])
def test_compile_to_an_unwritable_output_is_refused_before_any_work(cli, files, out):
    target = out.format(dir=files["dir"], spec=files["spec"])
    code, _, err = cli("compile", files["spec"], "-o", target)
    assert code == 2 and "error" in err and "Traceback" not in err


# ---- the random held-out sweep, two tables (the benchmark runs the rest) -----------------------


@pytest.mark.slow
def test_heldout_sweep_two_random_tables_through_the_command_line(tmp_path, capsys):
    """Seeds 7002 and 7003 of ``benchmarks/fsm_heldout.py`` (7 rows, 2 inputs): compile then
    simulate at the default dynamic level, in fresh processes, as a user runs them."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        import fsm_heldout
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    code = fsm_heldout.main(["--seeds", "7002", "7003", "--dir", str(tmp_path)])
    text = capsys.readouterr().out
    assert code == 0, text
    assert "accepted: 2" in text and "accepted_passing: 2" in text
    assert json.loads((tmp_path / "t7002.json").read_text())["format"] == "mechc"
