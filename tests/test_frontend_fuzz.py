"""Bad input never gives a traceback: a seeded fuzz of the front ends and the CLI, and one test
per class of bug the fuzz found (each asserts the exact place and message).

The rule under test (docs/spec-formats.md, ``mechc --help``): bad input exits 2 with one message
naming the file (and line:column for a text spec) and what was expected; exit 3 ("internal
error") on user input is a bug; an existing output file is never truncated or overwritten by a
run that fails.
"""

from __future__ import annotations

import contextlib
import errno
import io
import json
import os
import random
import re
from pathlib import Path

import pytest

from mechc.cli.main import main
from mechc.errors import SpecError
from mechc.frontends.boolfile import parse_bool
from mechc.frontends.fsm import parse_fsm
from mechc.frontends.pla import parse_pla
from tests.helpers import EXAMPLES

SENTINEL = b"precious\n"

#: Insertions the fuzz draws from: operators of this and other notations, digits (also non-ASCII
#: ones), keywords of the three formats, control and unicode characters, huge tokens.
TOKENS = ["=", "+", "'", "~", "(", ")", ":", "-", "|", "&", "^", ",", "[", "]", "0", "1", "2",
          "9", "99999999999999999999", "é", "λ", "\u200b", "\t", "\r", "\n", "\r\n", "\0", " ",
          "#", ".", ".i", ".o", ".e", ".type", ".ilb", "inputs", "outputs", "memory", "set",
          "reset", "initial", "columns", "flow", "assign", "secondary", "startup", "minterms",
          "dontcare", "A", "x1", "Z", "\ufeff", "\x7f", "(1)", "-1", "\u2028", "\x0b", "²", "٣",
          "１", "\u00a0", "0" * 300, "A" * 300]
#: Whole lines the fuzz inserts or substitutes (statements of the formats, right and wrong).
LINES = ["memory y set A reset ~A initial 1", "startup 01", "assign 1=01 2=10",
         "secondary y1 y2", "initial 1 00", "columns 00 01", "columns 0 1", "flow",
         "1: (1) 2 | 0", "7: - - - - | 1 1", ".type fr", ".type r", ".ilb a b", ".ob m n",
         ".i 2", ".o 2", ".e", "111 1", "1-? 1", "000 0", "Z = minterms(1,2) dontcare(3)",
         "Z = minterms()", "Z = 1", "inputs A B", "outputs Z", "inputs", "outputs",
         "memory y", "memory y set A reset", "memory Z set A reset B", "Z = A & B &", "Z = (A"]


def mutate(text: str, rng: random.Random, rounds: int = 1) -> str:
    """``text`` with ``rounds`` random edits: lines deleted, duplicated, swapped, replaced;
    characters and tokens inserted or deleted; truncation; other line endings."""
    for _ in range(rounds):
        lines = text.split("\n")
        op = rng.randrange(11)
        i = rng.randrange(len(lines))
        pos = rng.randrange(len(text) + 1)
        if op == 0:
            del lines[i]
        elif op == 1:
            lines.insert(i, lines[i])
        elif op == 2:
            j = rng.randrange(len(lines))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == 3:
            lines[i] = rng.choice(LINES)
        elif op == 4:
            lines.insert(i, rng.choice(LINES))
        if op <= 4:
            text = "\n".join(lines)
        elif op == 5:
            text = text[:pos] + text[pos + rng.randrange(1, 4):]
        elif op in (6, 7):
            text = text[:pos] + rng.choice(TOKENS) + text[pos:]
        elif op == 8:
            text = text[:pos] + " " + rng.choice(TOKENS) + " " + text[pos:]
        elif op == 9:
            text = text[:pos]
        else:
            text = text.replace("\n", rng.choice(["\r\n", "\r"]))
    return text


def run(*args) -> tuple[int, str, str]:
    """``mechc ARGS`` in-process: (exit status, stdout, stderr). Nothing may escape main()."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return code, out.getvalue(), err.getvalue()


def assert_user_error(code: int, err: str, path: Path, located: bool) -> None:
    """Exit 2, no traceback, one message line naming ``path`` (with :line:col if located)."""
    assert "Traceback" not in err and "internal error" not in err, err
    assert code == 2, err
    first = err.strip().splitlines()[0]
    if located:
        assert re.match(rf"^{re.escape(str(path))}:\d+:\d+: error: \S", first), first
    else:
        assert str(path) in first, first


def text_sources() -> list[Path]:
    return sorted(p for p in EXAMPLES.iterdir() if p.suffix in (".bool", ".pla", ".fsm"))


# ---- the bounded fuzz ------------------------------------------------------------------------
PARSERS = {".bool": parse_bool, ".pla": parse_pla, ".fsm": parse_fsm}


def test_parsers_fuzz_locate_every_error_inside_the_text():
    """1,500 mutated specs straight into the parsers: each parses or raises a SpecError whose
    line and column exist in the text (column up to one past the end of its line)."""
    rng = random.Random(20240611)
    sources = [(p.suffix, p.read_text()) for p in text_sources()]
    outcomes = {"parsed": 0, "error": 0}
    for k in range(1500):
        suffix, text = sources[k % len(sources)]
        bad = mutate(text, rng, rounds=rng.choice([1, 1, 2, 4]))
        where = f"case{k}{suffix}"
        try:
            PARSERS[suffix](bad, where)
            outcomes["parsed"] += 1
        except SpecError as e:
            outcomes["error"] += 1
            assert e.path == where
            # lines as the lexer counts them (only "\n" ends a line; PLA splits the same way)
            lines = bad.split("\n")
            assert 1 <= e.line <= len(lines), (bad, str(e))
            assert 1 <= e.col <= len(lines[e.line - 1]) + 1, (bad, str(e))
            assert len(str(e)) < 400, str(e)  # a huge token is not echoed whole
    assert outcomes["parsed"] > 100 and outcomes["error"] > 500, outcomes  # both paths ran


def test_cli_fuzz_no_traceback_and_output_untouched(tmp_path):
    """160 mutated specs through the CLI: exit 0/1 (the mutation was valid) or exit 2 with a
    located message; never exit 3; an existing output file survives every failing compile.
    Sources whose compile is cheap; sequential specs stop at the logic proof (no mechanism)."""
    rng = random.Random(7)
    cheap = ["sorter.bool", "full_adder.bool", "fv157.bool", "majority.pla",
             "gated_latch.fsm", "speedctl_sr.fsm", "sequence_detector.fsm"]
    sources = [(EXAMPLES / n).read_text() for n in cheap]
    out = tmp_path / "out.json"
    seen = {0: 0, 1: 0, 2: 0}
    for k in range(160):
        name = cheap[k % len(cheap)]
        text = mutate(sources[k % len(cheap)], rng, rounds=rng.choice([1, 2]))
        spec = tmp_path / f"m{k}{Path(name).suffix}"
        spec.write_bytes(text.encode("utf-8", "surrogatepass"))
        if spec.suffix == ".fsm":
            code, _, err = run("simulate", spec, "--level", "logic")
        else:
            out.write_bytes(SENTINEL)
            code, _, err = run("compile", spec, "-o", out, "--time-limit", "2")
            if code == 2:
                assert out.read_bytes() == SENTINEL, spec
        assert code in seen, (code, err)
        seen[code] += 1
        if code == 2:
            assert_user_error(code, err, spec, located=True)
    assert seen[2] > 40 and seen[0] > 20, seen


def test_cli_fuzz_design_json(tmp_path, sorter_design):
    """Mutated compiled designs (fields deleted, wrong types, NaN, negative, huge, swapped
    names) into simulate (logic, kinematic) and draw: exit 0/1, or 2 naming the file."""
    rng = random.Random(3)
    base = json.loads(sorter_design.read_text())
    leaves = list(_paths(base))
    for k in range(45):
        d = json.loads(json.dumps(base))
        path = rng.choice(leaves)
        parent = d
        for key in path[:-1]:
            parent = parent[key]
        old = parent[path[-1]]
        op = rng.randrange(4)
        if op == 0:
            del parent[path[-1]]
        elif op == 1 and isinstance(old, (int, float)) and not isinstance(old, bool):
            parent[path[-1]] = rng.choice([-old, -abs(old) - 1, 0, float("nan"), 1e300, 1e-300])
        elif op == 2 and isinstance(old, str):
            parent[path[-1]] = rng.choice(["A", "ground", "c1", "", "x.y"])
        else:
            parent[path[-1]] = rng.choice([None, "x", -1, [], {}, True, [1.0]])
        f = tmp_path / f"j{k}.json"
        f.write_text(json.dumps(d))
        args = [("simulate", f, "--level", "logic"), ("simulate", f, "--level", "kinematic"),
                ("draw", f, "-o", tmp_path / "x.svg")][k % 3]
        code, _, err = run(*args)
        assert code in (0, 1, 2), (path, err)
        if code == 2:
            assert_user_error(code, err, f, located=False)


def _paths(o, prefix=()):
    if isinstance(o, dict):
        for k, v in o.items():
            yield (*prefix, k)
            yield from _paths(v, (*prefix, k))
    elif isinstance(o, list):
        for i, v in enumerate(o):
            yield (*prefix, i)
            yield from _paths(v, (*prefix, i))


def _compiled(tmp_path_factory, spec: str) -> Path:
    """An example compiled once per module (the design the JSON mutations start from)."""
    p = tmp_path_factory.mktemp("design") / (Path(spec).stem + ".json")
    code, _, err = run("compile", EXAMPLES / spec, "-o", p)
    assert code == 0, err
    return p


@pytest.fixture(scope="module")
def sorter_design(tmp_path_factory) -> Path:
    return _compiled(tmp_path_factory, "sorter.bool")


# ---- one test per bug class --------------------------------------------------------------------
def nest(depth: int) -> str:
    return "(" * depth + "A" + ")" * depth


@pytest.mark.parametrize("depth", [65, 5000])
def test_deep_nesting_is_a_located_error_not_a_recursion_error(tmp_path, depth):
    # was: exit 3, RecursionError, from 5000 nested parentheses
    spec = tmp_path / "deep.bool"
    spec.write_text(f"inputs A\noutputs Z\nZ = {nest(depth)}\n")
    code, _, err = run("compile", spec, "-o", tmp_path / "o.json")
    assert_user_error(code, err, spec, located=True)
    # the 65th '(' is the first too deep: 'Z = ' takes columns 1-4, '(' k sits at 4 + k
    assert err.startswith(f"{spec}:3:69: error: expression nested more than 64 levels deep")


def test_deep_nesting_limit_counts_not_and_parentheses_in_fsm():
    ok = "inputs A\noutputs Z\nmemory y set A reset " + "~" * 63 + "(A)\nZ = y\n"
    assert parse_fsm(ok, "t.fsm").memories[0].name == "y"  # 64 levels: accepted
    with pytest.raises(SpecError) as e:
        parse_fsm(ok.replace("~(A)", "~~(A)"), "t.fsm")
    # 'memory y set A reset ' is 21 characters, then 64 '~': the '(' is at column 21 + 65
    assert (e.value.line, e.value.col) == (3, 86)
    assert "nested more than 64 levels" in e.value.message


def test_deep_nesting_at_the_limit_compiles(tmp_path):
    spec = tmp_path / "deep.bool"
    spec.write_text(f"inputs A B\noutputs Z\nZ = {nest(64)} & " + "~" * 64 + "B\n")
    code, out, err = run("compile", spec, "-o", tmp_path / "o.json")
    assert code == 0, err
    assert "Z = A & B" in out  # 64 '~' in front of B cancel


@pytest.mark.parametrize("text, col, kw", [(".i ²\n.o 1\n", 4, ".i"),   # isdigit() yet int() fails
                                           (".i 1\n.o ٣\n", 4, ".o")])  # read as 3 by int()
def test_pla_counts_take_ascii_digits_only(tmp_path, text, col, kw):
    # was: exit 3 (ValueError from int('²')); '٣' was silently read as 3
    spec = tmp_path / "u.pla"
    spec.write_text(text)
    code, _, err = run("compile", spec, "-o", tmp_path / "o.json")
    assert_user_error(code, err, spec, located=True)
    line = 1 if kw == ".i" else 2
    assert err.strip() == f"{spec}:{line}:{col}: error: expected one whole number after '{kw}'"


@pytest.mark.parametrize("token, kind", [("A" * 5000, "name"), ("1" * 5000, "number")])
def test_huge_token_is_refused_and_not_echoed(tmp_path, token, kind):
    # was: the 5000-character token printed whole inside the message
    spec = tmp_path / "t.bool"
    spec.write_text(f"inputs A B\noutputs Z\nZ = A & B {token}\n")
    code, _, err = run("compile", spec, "-o", tmp_path / "o.json")
    assert_user_error(code, err, spec, located=True)
    assert err.strip() == (f"{spec}:3:11: error: {kind} '{token[:40]}'... has 5000 characters; "
                           "expected at most 100")


@pytest.mark.parametrize("ch, col, hint", [("+", 7, "'|' for OR"), ("*", 7, "'&' for AND"),
                                           ("!", 5, "'~' for NOT")])
def test_foreign_operator_says_what_to_write(ch, col, hint):
    text = f"inputs A B\noutputs Z\nZ = A {ch} B\n" if ch != "!" else \
        "inputs A B\noutputs Z\nZ = !A & B\n"
    with pytest.raises(SpecError) as e:
        parse_bool(text, "t.bool")
    assert (e.value.line, e.value.col) == (3, col)
    assert e.value.message == (f"unexpected character {ch!r}: expected a name, a number or one "
                               f"of ~ & ^ | ( ) = , : - [ ] (write {hint})")


def test_old_mac_line_endings_count_as_lines(tmp_path):
    # was: a file with CR-only line endings read as one line ('expected end of line' at 1:12)
    spec = tmp_path / "cr.bool"
    spec.write_bytes(b"inputs A B\routputs Z\rZ = A & Q\r")
    code, _, err = run("compile", spec, "-o", tmp_path / "o.json")
    assert code == 2 and err.strip() == f"{spec}:3:9: error: unknown name 'Q' (inputs are: A B)"


def test_utf16_files_are_read(tmp_path, sorter_design):
    # was: 'binary data (NUL byte)' for a UTF-16 spec (Windows PowerShell's default encoding)
    good = tmp_path / "maj.pla"
    good.write_bytes((EXAMPLES / "majority.pla").read_text().encode("utf-16"))
    code, out, err = run("compile", good, "-o", tmp_path / "o.json")
    assert code == 0, err
    bad = tmp_path / "bad.bool"
    bad.write_bytes("inputs A B\noutputs Z\nZ = A é B\n".encode("utf-16"))
    code, _, err = run("compile", bad, "-o", tmp_path / "o.json")
    assert code == 2 and err.strip().startswith(f"{bad}:3:7: error: unexpected character 'é'")
    design = tmp_path / "d16.json"
    design.write_bytes(sorter_design.read_text().encode("utf-16"))
    assert run("simulate", design, "--level", "logic")[0] == 0


def test_pla_on_off_clash_points_at_the_output_column():
    # was: the column of the first output character plus the output's index, which is off by
    # the spaces between output characters
    text = ".i 2\n.o 2\n.type fr\n11 ~ 1\n1- ~ 0\n"
    with pytest.raises(SpecError) as e:
        parse_pla(text, "t.pla")
    line4 = text.split("\n")[3]
    assert (e.value.line, e.value.col) == (4, line4.rindex("1") + 1)  # f1's '1' on line 4
    assert e.value.message == ("output 'f1': this on-set term meets the off-set term of line 5 "
                               "(at input 11)")


@pytest.mark.parametrize("option", ["--tolerance", "--dt", "--move-time", "--accuracy",
                                    "--time-limit", "--stroke", "--actuator-force",
                                    "--output-load"])
@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_non_finite_option_values_are_refused(capsys, option, value):
    # was: --dt nan / --move-time nan|inf exit 3 (int(nan) in the solver), --output-load inf a
    # ZeroDivisionError, and 'nan' passed every '<= 0' check
    with pytest.raises(SystemExit) as e:
        main(["simulate", str(EXAMPLES / "sorter.bool"), f"{option}={value}"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"argument {option}: expected a finite number, got '{value}'" in err
    assert "Traceback" not in err


def test_spec_with_other_inputs_is_refused_at_every_level(tmp_path, sorter_design):
    # was: exit 3 (KeyError 'A') at the kinematic level against a sequential spec
    for level in ("logic", "kinematic", "dynamic"):
        code, _, err = run("simulate", sorter_design, "--level", level,
                           "--spec", EXAMPLES / "toggle.fsm")
        assert_user_error(code, err, sorter_design, located=False)
        assert "design inputs (A B C D) differ from the spec's (T)" in err


def test_report_never_overwrites_the_design(tmp_path, sorter_design):
    # was: 'simulate d.json --report d.json' replaced the design by the proof report
    design = tmp_path / "d.json"
    design.write_bytes(sorter_design.read_bytes())
    before = design.read_bytes()
    code, out, err = run("simulate", design, "--level", "logic", "--report", design)
    assert code == 2 and out == ""
    assert "refusing to overwrite the design" in err and str(design) in err
    assert design.read_bytes() == before


def test_output_onto_the_spec_is_refused_however_spelled(tmp_path):
    # a hard link was not caught (Path.resolve() does not see through it)
    spec = tmp_path / "s.bool"
    spec.write_bytes((EXAMPLES / "sorter.bool").read_bytes())
    before = spec.read_bytes()
    (tmp_path / "sym.json").symlink_to(spec)
    os.link(spec, tmp_path / "hard.json")
    for out in (spec, tmp_path / "." / "s.bool", tmp_path / "sym.json", tmp_path / "hard.json"):
        code, _, err = run("compile", spec, "-o", out)
        assert code == 2 and f"refusing to overwrite the spec '{spec}' with the output" in err
        assert spec.read_bytes() == before


def test_report_path_is_checked_before_the_proof(tmp_path, sorter_design):
    # was: a dynamic proof ran to the end, then the report could not be written
    code, out, err = run("simulate", sorter_design, "--report", tmp_path / "no" / "r.json")
    assert code == 2 and out == ""  # no proof output: it never started
    assert f"{tmp_path / 'no' / 'r.json'}: directory '{tmp_path / 'no'}' does not exist" in err


def test_failed_write_is_exit_2_and_leaves_the_old_file(tmp_path, monkeypatch):
    # was: exit 3 (OSError) on a full disk or an unwritable file system
    out = tmp_path / "o.json"
    out.write_bytes(SENTINEL)

    def full(*_a, **_k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr("mechc.backends.design_json.os.replace", full)
    code, _, err = run("compile", EXAMPLES / "sorter.bool", "-o", out)
    assert_user_error(code, err, out, located=False)
    assert f"{out}: cannot write: {os.strerror(errno.ENOSPC)}" in err
    assert out.read_bytes() == SENTINEL
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.json"]  # no temporary file left


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="/dev/full is Linux-only")
def test_write_to_a_full_device_is_exit_2():
    code, _, err = run("compile", EXAMPLES / "sorter.bool", "-o", "/dev/full")
    assert_user_error(code, err, Path("/dev/full"), located=False)
    assert "cannot write" in err


def _edited(sorter_design: Path, tmp_path: Path, edit) -> Path:
    d = json.loads(sorter_design.read_text())
    edit(d)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(d))
    return p


def _first_spring(d: dict) -> dict:
    return next(c["geometry"]["springs"][0] for c in d["cells"] if c["geometry"]["springs"])


@pytest.mark.parametrize("case, edit, where, what", [
    # NaN slipped through the schema (every comparison with NaN is false); draw then did int(nan)
    ("nan", lambda d: d["cells"][0]["geometry"]["bodies"][0]["outline"][0][0].__setitem__(
        0, float("nan")), "cells/0/geometry/bodies/0/outline/0/0/0",
     "nan is not a finite number of magnitude at most 1e+09"),
    ("huge", lambda d: d["cells"][0]["geometry"]["bodies"][0]["outline"][0][0].__setitem__(
        1, 1e308), "cells/0/geometry/bodies/0/outline/0/0/1",
     "1e+308 is not a finite number of magnitude at most 1e+09"),
    # a joint naming a body that does not exist: was KeyError deep in the kinematics
    ("joint ref", lambda d: d["cells"][0]["geometry"]["joints"][0].__setitem__("a", "AND bar"),
     "cells/0/geometry/joints/0/a", "'AND bar' is not a body of this design (nor 'ground')"),
    # a profile point with one coordinate: was IndexError while reading the geometry
    ("profile", lambda d: d["cells"][0]["geometry"]["joints"][0].__setitem__(
        "profile", [[1.0, 2.0], [3.0]]), "cells/0/geometry/joints/0/profile",
     "expected a list of [x, y] points"),
    # the mechanism order names a cell that has no geometry: was KeyError in draw
    ("order", lambda d: d["mechanism"]["order"].__setitem__(0, "zz"), "mechanism/order",
     "expected each cell with geometry once: 'zz' is not one or is listed twice"),
    ("rest length", lambda d: _first_spring(d).__setitem__("rest_length_mm", -20.0), None,
     "-20.0: a length cannot be negative"),
])
def test_corrupt_design_geometry_is_a_clear_error(tmp_path, sorter_design, case, edit, where,
                                                  what):
    bad = _edited(sorter_design, tmp_path, edit)
    for args in (("simulate", bad, "--level", "logic"), ("draw", bad, "-o", tmp_path / "x.svg")):
        code, _, err = run(*args)
        assert_user_error(code, err, bad, located=False)
        assert f"{bad}: not a valid mechc design at " in err
        if where:
            assert f"at {where}: {what}" in err
        else:
            assert what in err
    assert not (tmp_path / "x.svg").exists()


def test_layout_with_unknown_field_is_a_clear_error(tmp_path, sorter_design):
    # was: exit 3 (TypeError from Place(**place)) - the schema allows extra keys in a place
    bad = _edited(sorter_design, tmp_path,
                  lambda d: d["cells"][0]["place"].__setitem__("z", 1.0))
    code, _, err = run("simulate", bad, "--level", "logic")
    assert_user_error(code, err, bad, located=False)
    assert f"{bad}: inconsistent layout: " in err


def test_deeply_nested_json_is_a_clear_error(tmp_path):
    # json.loads raises RecursionError on 100,000 nested brackets
    bad = tmp_path / "deep.json"
    bad.write_text("[" * 100_000 + "]" * 100_000)
    code, _, err = run("simulate", bad, "--level", "logic")
    assert_user_error(code, err, bad, located=False)
    assert "nested too deeply" in err


def test_design_path_that_is_a_directory(tmp_path):
    d = tmp_path / "d.json"
    d.mkdir()
    code, _, err = run("simulate", d, "--level", "logic")
    assert_user_error(code, err, d, located=False)
    assert f"{d}: is a directory, expected a design file (.json)" in err


# ---- sequential designs with broken geometry (found by the fuzz, fixed outside the parsers) ----
@pytest.fixture(scope="module")
def toggle_design(tmp_path_factory) -> Path:
    return _compiled(tmp_path_factory, "toggle.fsm")


def _rewire_rod(d: dict) -> None:
    """Hang a rod of a cell on a body of another cell: the cell's bodies lose their driver."""
    cell = next(c for c in d["cells"] if c["type"] != "MEMORY" and any(
        j["kind"] == "rod" for j in c["geometry"]["joints"]))
    other = next(b["id"] for c in d["cells"] if c["id"] != cell["id"]
                 for b in c["geometry"]["bodies"])
    next(j for j in cell["geometry"]["joints"] if j["kind"] == "rod")["b"] = other


def _drop_memory_contact(d: dict) -> None:
    mem = next(c for c in d["cells"] if c["type"] == "MEMORY")
    joints = mem["geometry"]["joints"]
    joints.remove(next(j for j in joints if j["kind"] == "contact"))


@pytest.mark.parametrize("edit", [_rewire_rod, _drop_memory_contact])
def test_broken_sequential_geometry_is_bad_input_not_an_internal_error(tmp_path, toggle_design,
                                                                       edit):
    d = json.loads(toggle_design.read_text())
    edit(d)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d))
    code, _, err = run("simulate", bad, "--level", "kinematic")
    assert code == 2, err
    assert "bad.json" in err and "not a determinate mechanism" in err
