"""What compile hands out and says: the compact design file (re-read by the library, checked
by two schema validators that must agree), the quiet and short summaries, the stages of a long
compile, the proofs it runs before writing, and the flow-table rows merged."""

from __future__ import annotations

import copy
import gzip
import io
import json
import re
import time

import jsonschema
import numpy as np
import pytest

import mechc.cli.compile as compile_cmd
from mechc.backends.design_json import (
    check_numbers,
    design_from_json,
    design_to_json,
    dumps,
    dumps_design,
    fast_validator,
    has_bad_number,
    load_design_json,
    schema,
)
from mechc.cells.library import load_library
from mechc.cli.common import StageProgress
from mechc.errors import UsageError
from mechc.frontends import load_spec
from mechc.pipeline import compile_spec
from mechc.proofs import prove
from mechc.proofs.report import sampled_text
from mechc.ui import Progress
from tests.helpers import EXAMPLES


@pytest.fixture(scope="module")
def sorter_obj() -> dict:
    return design_to_json(compile_spec(load_spec(EXAMPLES / "sorter.bool")))


def test_compact_layout_holds_the_same_design_and_is_smaller(sorter_obj):
    text = dumps_design(sorter_obj)
    assert json.loads(text) == sorter_obj  # re-read by the json library: the same document
    assert len(text) < len(dumps(sorter_obj)) / 1.5
    lines = text.splitlines()
    # one line per cell record, and the top-level keys each on their own line
    assert sum(1 for ln in lines if ln.lstrip().startswith('{"id":"c')) == len(sorter_obj["cells"])
    assert lines[1] == '  "format": "mechc",'
    assert dumps_design(sorter_obj) == text  # deterministic


def test_an_indented_design_of_before_still_loads(sorter_obj, tmp_path):
    old = tmp_path / "old.json"
    old.write_text(json.dumps(sorter_obj, indent=2))
    new = tmp_path / "new.json"
    new.write_text(dumps_design(sorter_obj))
    a = design_from_json(load_design_json(old), str(old))
    b = design_from_json(load_design_json(new), str(new))
    assert a.netlist.to_text() == b.netlist.to_text()
    lib = load_library()
    assert prove(a, a.spec, lib, "kinematic").passed and prove(b, b.spec, lib, "kinematic").passed


def _mutations(obj: dict, rng: np.random.Generator, n: int):
    """``n`` copies of ``obj`` each with one value somewhere replaced by a value of another
    type or a key dropped (many are still valid: an extra stats key, say)."""
    paths = []

    def walk(o, path):
        paths.append(path)
        if isinstance(o, dict):
            for k, v in o.items():
                walk(v, (*path, k))
        elif isinstance(o, list):
            for i, v in enumerate(o[:3]):
                walk(v, (*path, i))

    walk(obj, ())
    swaps = ["x", -1, 1.5, None, True, [], {}, {"kind": "nope"}, [1, 2]]
    for _ in range(n):
        path = paths[int(rng.integers(1, len(paths)))]
        m = copy.deepcopy(obj)
        parent = m
        for k in path[:-1]:
            parent = parent[k]
        if isinstance(parent, dict) and rng.random() < 0.3:
            del parent[path[-1]]
        else:
            parent[path[-1]] = swaps[int(rng.integers(len(swaps)))]
        yield path, m


def test_the_fast_validator_agrees_with_jsonschema(sorter_obj):
    """jsonschema-rs decides what loads; jsonschema (the reference) must reach the same verdict
    on every mutated design, valid or not."""
    ref = jsonschema.Draft202012Validator(schema())
    assert fast_validator().is_valid(sorter_obj) and ref.is_valid(sorter_obj)
    rejected = 0
    for path, m in _mutations(sorter_obj, np.random.default_rng(7), 300):
        fast, slow = fast_validator().is_valid(m), ref.is_valid(m)
        assert fast == slow, path
        rejected += not slow
    assert rejected > 150  # the mutations mostly break the schema: the comparison has teeth


def test_a_bad_file_is_refused_with_its_place(sorter_obj, tmp_path):
    bad = copy.deepcopy(sorter_obj)
    bad["cells"][2]["geometry"]["bodies"][0]["mass_kg"] = "heavy"
    p = tmp_path / "bad.json"
    p.write_text(dumps_design(bad))
    with pytest.raises(UsageError, match=r"bad.json: not a valid mechc design at "
                       r"cells/2/geometry/bodies/0/mass_kg: 'heavy' is not of type 'number'"):
        load_design_json(p)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf"), 1e300, 1.5e9,
                                   -12345678901, np.float64("nan")])
def test_every_number_out_of_range_is_found_with_its_place(sorter_obj, value):
    bad = copy.deepcopy(sorter_obj)
    bad["cells"][1]["geometry"]["bodies"][0]["outline"][0][2][1] = value
    assert has_bad_number(bad)
    with pytest.raises(UsageError, match=r"x.json: not a valid mechc design at "
                       r"cells/1/geometry/bodies/0/outline/0/2/1: .* is not a finite number"):
        check_numbers(bad, "x.json")
    assert not has_bad_number(sorter_obj)  # True and False are no numbers out of range either
    check_numbers(sorter_obj, "x.json")


def test_quiet_prints_only_the_file_line_and_the_verdict(cli, tmp_path):
    out = tmp_path / "s.json"
    code, stdout, err = cli("compile", EXAMPLES / "sorter.bool", "-o", out, "--quiet",
                            "--levels", "2")  # the two-level design this test pins
    assert code == 0, err
    lines = stdout.splitlines()
    assert lines[0].startswith(f"{EXAMPLES / 'sorter.bool'} -> {out}: 6 cells")
    assert [ln.split(":")[0].strip() for ln in lines[1:]] == [
        "design checks", "logic proof", "kinematic proof"]
    assert err == ""
    code, loud, _ = cli("compile", EXAMPLES / "sorter.bool", "-o", out)
    assert "Z = " in loud and "cells used" in loud and "Z = " not in stdout


def test_a_design_of_many_outputs_leaves_its_equations_out(cli, tmp_path):
    n = 22
    spec = tmp_path / "wide.bool"
    spec.write_text("inputs a b c\noutputs " + " ".join(f"z{i}" for i in range(n)) + "\n"
                    + "".join(f"z{i} = minterms({i % 8}, {(i * 3 + 1) % 8})\n" for i in range(n)))
    out = tmp_path / "w.json"
    code, stdout, err = cli("compile", spec, "-o", out)
    assert code in (0, 1), err
    assert f"equations of {n} output(s) not shown" in stdout and "--equations" in stdout
    assert "z0 = " not in stdout
    code, stdout, err = cli("compile", spec, "-o", out, "--equations")
    assert all(f"z{i} = " in stdout for i in range(n))


def test_long_stages_are_named_with_their_seconds():
    s = io.StringIO()
    st = StageProgress("compile", delay=0.05, stream=s)
    st.start("quick")
    st.end("quick", 0.001)
    st.start("slow")
    time.sleep(0.3)  # the stage outlives the delay: it is named while it runs
    st.end("slow", 0.3)
    st.close()
    assert s.getvalue().splitlines() == ["compile: slow ...", "compile: slow 0.3 s"]
    assert st.summary().startswith("compile stages (s): quick 0.00, slow 0.30; total")
    quiet = io.StringIO()
    st = StageProgress("compile", delay=0.05, stream=quiet, enabled=False)
    st.start("slow")
    time.sleep(0.2)
    st.end("slow", 0.2)
    assert quiet.getvalue() == ""


def test_progress_goes_on_when_a_job_finds_more_work():
    """A screened proof's first round reaches 9/9, then its fallback adds 85 changes: off a
    terminal (CI logs) the count must go on printing, not wait for a decile already passed."""
    s = io.StringIO()
    bar = Progress(9, "proof", delay=0.0, stream=s)
    for done in range(1, 10):
        bar.update(done)
    bar.retotal(94)
    for done in range(10, 95):
        bar.update(done)
    lines = s.getvalue().splitlines()
    after = [ln for ln in lines if "/94" in ln]
    assert lines[-1].startswith("proof: 94/94 (100%)")
    assert len(after) >= 10 and after[0].startswith("proof: 10/94")
    bar.retotal(94)  # the same total again: no line until the next decile
    bar.update(94)
    assert s.getvalue().splitlines() == lines


def test_a_design_its_proof_rejects_is_not_written(cli, tmp_path, monkeypatch):
    """The design read back from the text compile is about to write has one AND turned into
    an OR: the logic proof fails, nothing is written and an existing file stays."""
    real = compile_cmd.design_from_json

    def corrupted(obj, where, mechanism=True):
        obj = copy.deepcopy(obj)
        next(c for c in obj["cells"] if c["type"] == "AND")["type"] = "OR"
        return real(obj, where, mechanism)

    monkeypatch.setattr(compile_cmd, "design_from_json", corrupted)
    out = tmp_path / "s.json"
    out.write_text("mine")
    code, stdout, err = cli("compile", EXAMPLES / "sorter.bool", "-o", out)
    assert code == 1
    assert "PROOF FAILED: logic proof: FAILED" in err and "NOT written" in err
    assert out.read_text() == "mine"
    code, _, err = cli("compile", EXAMPLES / "sorter.bool", "-o", out, "--no-prove")
    assert code == 0 and json.loads(out.read_text())["format"] == "mechc"


def test_the_kinematic_proof_tells_its_progress():
    d = compile_spec(load_spec(EXAMPLES / "full_adder.bool"))
    seen = []
    rep = prove(d, d.spec, load_library(), "kinematic", progress=lambda a, b: seen.append((a, b)))
    assert rep.passed and seen
    total = seen[-1][1]
    assert seen[-1][0] == total == 2 ** 3 + 3 * 2 ** 2 * 21  # every state, then every change
    assert all(a <= b for (a, _), (b, _) in zip(seen, seen[1:]))


def test_a_sampled_proof_says_sampled_n_of_m(cli, tmp_path):
    assert sampled_text(8, {"exhaustive": True}) == "8 cases"
    names = [f"a{i}" for i in range(11)]
    spec = tmp_path / "w.bool"
    spec.write_text(f"inputs {' '.join(names)}\noutputs z\nz = a0 & a1 | a10\n")
    code, stdout, err = cli("compile", spec, "-o", tmp_path / "w.json")
    assert code == 0, err
    # 512 random states and changes, led by the changes that switch every cell (and their
    # start states)
    design = json.loads((tmp_path / "w.json").read_text())
    cells = len(design["cells"])
    m = re.search(r"kinematic proof: proved, sampled (\d+) of 2048 cases, proven on (\d+) of "
                  r"11264 single-input changes, sampled, (\d+) of them chosen to switch every "
                  rf"cell: {cells} of {cells} cells switched \(not exhaustive\)", stdout)
    assert m, stdout
    directed = int(m.group(3))
    assert 1 <= directed <= cells and int(m.group(1)) == int(m.group(2)) == 512 + directed
    code, stdout, _ = cli("simulate", tmp_path / "w.json", "--level", "kinematic")
    assert f"sampled {512 + directed} of 2048 cases" in stdout


def test_merged_flow_table_rows_are_named(cli, tmp_path):
    """Four KISS2 states of one output value, chained by their transitions, are one row."""
    spec = tmp_path / "chain.kiss2"
    spec.write_text(".i 1\n.o 1\n.r a\n0 a a 0\n1 a b -\n1 b b 0\n0 b c -\n0 c c 0\n"
                    "1 c d -\n1 d d 0\n0 d a -\n.e\n")
    code, stdout, err = cli("compile", spec, "-o", tmp_path / "c.json")
    assert code == 0, err
    assert "flow table: 4 states -> 1 row (merged: a+b+c+d)" in stdout
    code, stdout, err = cli("compile", EXAMPLES / "toggle.kiss2", "-o", tmp_path / "t.json")
    assert code == 0, err
    assert "flow table" not in stdout  # nothing merged, nothing said


def test_a_gzip_design_is_the_same_text_and_reads_back(cli, tmp_path):
    gz, plain = tmp_path / "s.json.gz", tmp_path / "s.json"
    for out in (gz, plain):
        code, _, err = cli("compile", EXAMPLES / "sorter.bool", "-o", out, "--quiet")
        assert code == 0, err
    assert gzip.decompress(gz.read_bytes()) == plain.read_bytes()  # read back by gzip itself
    assert gz.stat().st_size < plain.stat().st_size / 3
    code, _, _ = cli("compile", EXAMPLES / "sorter.bool", "-o", tmp_path / "t.json.gz", "-q")
    assert (tmp_path / "t.json.gz").read_bytes() == gz.read_bytes()  # reproducible bytes
    for level in ("logic", "kinematic"):
        code, out, err = cli("simulate", gz, "--level", level)
        assert code == 0 and "PASSED" in out, err
    code, _, err = cli("draw", gz, "-o", tmp_path / "s.svg")
    assert code == 0, err
    broken = tmp_path / "broken.json.gz"
    broken.write_bytes(gz.read_bytes()[:200])
    code, _, err = cli("simulate", broken, "--level", "logic")
    assert code == 2 and "broken.json.gz: cannot read design: a damaged gzip file" in err


def test_what_compile_writes_simulate_and_draw_accept_across_option_values(cli, tmp_path):
    """A seeded draw of compile's design options, extreme values included: every design compile
    writes (whatever its exit status) is taken by `simulate --level logic` and by `draw`; a
    refusal is exit 2 and leaves no file. So no written design is ever refused for its content."""
    rng = np.random.default_rng(16)
    written = 0
    for i in range(8):
        out = tmp_path / f"d{i}.json"
        opts = ["--stroke", f"{rng.choice([2.0, 8.0, 20.0, 60.0, 300.0]):g}",
                "--actuator-force", f"{rng.choice([0.5, 5.0, 50.0, 5e3]):g}",
                "--output-load", f"{rng.choice([0.0, 0.2, 2.0, 200.0, 1e6]):g}",
                "--clearance", f"{rng.choice([0.0, 0.5, 1.0, 5.0]):g}",
                "--material", str(rng.choice(["aluminium", "steel", "acrylic"]))]
        spec = EXAMPLES / str(rng.choice(["sorter.bool", "majority.pla", "toggle.fsm"]))
        code, _, err = cli("compile", spec, "-o", out, "--no-prove", *opts)
        if not out.exists():
            assert code == 2 and "Traceback" not in err, (opts, err)
            continue
        written += 1
        code, _, err = cli("simulate", out, "--level", "logic")
        assert code == 0, (opts, err)
        code, _, err = cli("draw", out, "-o", tmp_path / f"d{i}.svg")
        assert code == 0, (opts, err)
    assert written >= 3  # the draw reaches designs, not only refusals
