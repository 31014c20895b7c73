"""The Verilog front end (through Yosys): functions read as written, vector bits named A0..,
structure kept for multi-level synthesis, and every bad file a ``file:line:col`` error with
exit 2 (no traceback)."""

from __future__ import annotations

import itertools

import pytest

from mechc.errors import SpecError
from mechc.frontends import load_spec
from mechc.frontends.verilog import parse_verilog
from tests.helpers import EXAMPLES


def value(spec, output: str, env: dict[str, int]) -> int:
    m = int("".join(str(env[x]) for x in spec.inputs), 2)  # input 0 is the MSB
    return int(spec.table(output)[m])


def test_mux_and_vector_ports():
    text = ("module top(input [1:0] d, input s, output y, output [1:0] n);\n"
            "  assign y = s ? d[1] : d[0];\n"
            "  assign n = ~d;\n"
            "endmodule\n")
    spec = parse_verilog(text, "mux.v")
    assert spec.inputs == ["d0", "d1", "s"]
    assert spec.outputs == ["y", "n0", "n1"]
    assert spec.display["d1"] == "d[1]" and "s" not in spec.display
    assert ".model top" in spec.structure
    for d0, d1, s in itertools.product((0, 1), repeat=3):
        env = {"d0": d0, "d1": d1, "s": s}
        assert value(spec, "y", env) == (d1 if s else d0)
        assert value(spec, "n0", env) == 1 - d0
        assert value(spec, "n1", env) == 1 - d1


def test_adder_example_is_arithmetic():
    spec = load_spec(EXAMPLES / "multilevel" / "adder4.v")
    for a, b, ci in itertools.product(range(16), range(16), (0, 1)):
        env = {f"A{i}": a >> i & 1 for i in range(4)} | {f"B{i}": b >> i & 1 for i in range(4)}
        env["CI"] = ci
        total = a + b + ci
        for i in range(4):
            assert value(spec, f"S{i}", env) == total >> i & 1
        assert value(spec, "CO", env) == total >> 4


BAD = [
    # (source, line, col, words the message must contain)
    ("module m(input a, output y);\n  assign y = a &;\nendmodule\n", 2, 17, "syntax error"),
    ("module m(input a, output y);\n  assign y = a & q;\nendmodule\n", 2, 18, "q"),
    ("module m(input a, input clk, output reg y);\n  always @(posedge clk) y <= a;\n"
     "endmodule\n", 2, 3, "sequential"),
    ("module m(input a, output y);\n  assign y = a;\nendmodul\n", 3, 1, "syntax error"),
    ("module m(input a, output y);\n  wire w;\n  assign y = a & w;\nendmodule\n", 2, 8,
     "no driver"),
]


@pytest.mark.parametrize("text,line,col,words", BAD)
def test_bad_verilog_is_located(text, line, col, words):
    with pytest.raises(SpecError) as e:
        parse_verilog(text, "bad.v")
    assert (e.value.path, e.value.line, e.value.col) == ("bad.v", line, col), str(e.value)
    assert words in e.value.message


def test_cli_bad_verilog_exit_2(cli, tmp_path):
    p = tmp_path / "bad.v"
    p.write_text(BAD[0][0])
    code, out, err = cli("compile", p, "-o", tmp_path / "bad.json")
    assert code == 2
    assert f"{p}:2:17: error: syntax error" in err
    assert "Traceback" not in err and not (tmp_path / "bad.json").exists()
