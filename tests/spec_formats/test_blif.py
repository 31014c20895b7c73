"""The BLIF front end: networks read as the functions they compute, checked against arithmetic
and against a plain per-vector interpreter of the network written here; errors located."""

from __future__ import annotations

import itertools
import re

import numpy as np
import pytest

from mechc.frontends import Spec, load_spec
from mechc.frontends.blif import parse_blif, table_cover
from mechc.logic.cubes import DC, Cube
from tests.helpers import EXAMPLES


def value(spec: Spec, output: str, bits: tuple[int, ...]) -> int:
    m = int("".join(map(str, bits)), 2)  # input 0 is the most significant bit
    return int(spec.table(output)[m])


def test_full_adder_example_is_arithmetic():
    spec = load_spec(EXAMPLES / "full_adder_net.blif")
    assert spec.inputs == ["a", "b", "cin"] and spec.outputs == ["s", "cout"]
    for a, b, c in itertools.product((0, 1), repeat=3):
        assert value(spec, "s", (a, b, c)) == (a + b + c) % 2
        assert value(spec, "cout", (a, b, c)) == (a + b + c) // 2


def ripple_adder_blif(width: int) -> str:
    """A ripple-carry adder: XOR sums as on-set covers, carries as off-set covers, long
    .names lines continued with '\\'."""
    a = [f"a{i}" for i in range(width)]
    b = [f"b{i}" for i in range(width)]
    lines = [".model ripple", ".inputs " + " ".join(a) + " \\", "  " + " ".join(b) + " cin",
             ".outputs " + " ".join(f"s{i}" for i in range(width)) + f" c{width}"]
    carry = "cin"
    for i in range(width):
        lines += [f".names {a[i]} {b[i]} p{i}", "10 1", "01 1",
                  f".names p{i} {carry} s{i}", "10 1", "01 1",
                  f".names {a[i]} {b[i]} \\", f"   {carry} c{i + 1}  # carry out of bit {i}",
                  "00- 0", "0-0 0", "-00 0"]
        carry = f"c{i + 1}"
    return "\n".join(lines + [".end"]) + "\n"


def test_ripple_adder_is_arithmetic():
    w = 4
    spec = parse_blif(ripple_adder_blif(w), "ripple.blif")
    assert spec.inputs == [f"a{i}" for i in range(w)] + [f"b{i}" for i in range(w)] + ["cin"]
    for a, b, c in itertools.product(range(1 << w), range(1 << w), (0, 1)):
        # a0 is input 0 (most significant bit of the minterm index): bit-reverse by hand
        bits = [a >> i & 1 for i in range(w)] + [b >> i & 1 for i in range(w)] + [c]
        total = a + b + c
        for i in range(w):
            assert value(spec, f"s{i}", tuple(bits)) == total >> i & 1
        assert value(spec, f"c{w}", tuple(bits)) == total >> w


def random_network(rng: np.random.Generator, n: int, nodes: int):
    """A random acyclic network: (inputs, [(fanins, output, cubes, phase)], outputs)."""
    inputs = [f"i{k}" for k in range(n)]
    signals = list(inputs)
    net = []
    for j in range(nodes):
        k = int(rng.integers(0, 4))  # 0 fanins: a constant node
        fanins = [str(s) for s in rng.choice(signals, size=k, replace=True)] if k else []
        cubes = ["".join(rng.choice(list("01-"), size=k)) for _ in range(rng.integers(0, 4))]
        phase = int(rng.integers(0, 2)) if cubes else 1
        net.append((fanins, f"n{j}", cubes, phase))
        signals.append(f"n{j}")
    outputs = [f"n{j}" for j in rng.choice(nodes, size=3, replace=False)]
    return inputs, net, outputs


def network_text(inputs, net, outputs) -> str:
    lines = [".model r", ".inputs " + " ".join(inputs), ".outputs " + " ".join(outputs)]
    for fanins, out, cubes, phase in net:
        lines.append(".names " + " ".join(fanins + [out]))
        lines += [(f"{c} {phase}" if fanins else str(phase)) for c in cubes]
    return "\n".join(lines + [".end"]) + "\n"


def interpret(net, env: dict[str, int], name: str) -> int:
    """BLIF semantics, one vector at a time: a node is 1 iff some cube matches (on-set
    cover), or iff none matches (off-set cover)."""
    for fanins, out, cubes, phase in net:
        if out == name:
            vals = [env[f] if f in env else interpret(net, env, f) for f in fanins]
            hit = any(all(ch == "-" or int(ch) == v for ch, v in zip(c, vals)) for c in cubes)
            return int(hit) if phase == 1 else int(not hit)
    raise KeyError(name)


@pytest.mark.parametrize("seed", range(6))
def test_random_networks_match_an_interpreter(seed):
    rng = np.random.default_rng(seed)
    n = 5
    inputs, net, outputs = random_network(rng, n, 14)
    spec = parse_blif(network_text(inputs, net, outputs), "r.blif")
    assert spec.outputs == outputs
    for m in range(1 << n):
        env = {name: m >> (n - 1 - k) & 1 for k, name in enumerate(inputs)}
        for o in outputs:
            assert spec.table(o)[m] == interpret(net, env, o), (seed, m, o)


@pytest.mark.parametrize("n", [1, 4, 8])
def test_table_cover_is_exact_and_irredundant(n):
    rng = np.random.default_rng(n)
    for _ in range(5):
        table = rng.random(1 << n) < rng.random()
        cubes = table_cover(table, n)
        inside = np.array([[c.contains(Cube.minterm(m, n)) for m in range(1 << n)]
                           for c in cubes], dtype=int).reshape(len(cubes), 1 << n)
        hits = inside.sum(axis=0)
        assert np.array_equal(hits > 0, table)  # exactly the on-set
        for row in inside:  # every cube covers some minterm no other cube covers
            assert ((row == 1) & (hits == 1)).any()


def test_table_cover_of_an_or_of_products_has_one_cube_per_product():
    # x0·x1 + x2·x3 + x4·x5: three primes, each essential, so any irredundant cover is them
    n = 6
    m = np.arange(1 << n)
    bit = [(m >> (n - 1 - k)) & 1 for k in range(n)]
    table = (bit[0] & bit[1]) | (bit[2] & bit[3]) | (bit[4] & bit[5])
    assert sorted(c.to_string(n) for c in table_cover(table.astype(bool), n)) == \
        ["----11", "--11--", "11----"]


def test_constants_comments_continuations_unused_signals():
    text = """\
# no .model line: allowed
.inputs a   # first input line
.inputs b c
.outputs one zero nand buf
.names one
1
.names zero
.names a b \\
  nand
11 0
.names c buf
1 1
.names a dangling   # drives nothing that is listed
0 1
.end
"""
    spec = parse_blif(text, "c.blif")
    assert spec.inputs == ["a", "b", "c"]
    for a, b, c in itertools.product((0, 1), repeat=3):
        assert value(spec, "one", (a, b, c)) == 1
        assert value(spec, "zero", (a, b, c)) == 0
        assert value(spec, "nand", (a, b, c)) == 1 - (a & b)
        assert value(spec, "buf", (a, b, c)) == c
    assert all(DC not in spec.table(o) for o in spec.outputs)  # BLIF covers are complete


# (content, line:col, message fragment); each must exit 2 with one located line
HEAD = ".model m\n.inputs a b\n.outputs z\n"
ERRORS = [
    (HEAD + ".names a w z\n11 1\n.names z w\n1 1\n", "4:12", "combinational cycle: z -> w -> z"),
    (HEAD + ".names a q z\n11 1\n", "4:10", "signal 'q' is used but never defined"),
    (HEAD + ".latch a z re clk 0\n", "4:1", "'.latch' is not supported"),
    (HEAD + "  .subckt add x=a y=z\n", "4:3", "'.subckt' is not supported"),
    (HEAD + ".gate inv A=a O=z\n", "4:1", "'.gate' is not supported"),
    (HEAD + ".names a z\n1 1\n.exdc\n.names a z\n1 1\n", "6:1", "'.exdc' is not supported"),
    (HEAD + ".names a b z\n11 1\n00 0\n", "6:4", "a '.names' cover is all on-set (1) or all"),
    (HEAD + ".names a b z\n1 1\n", "5:1", "cube '1' has 1 character(s); expected 2"),
    (HEAD + ".names a b z\n1x 1\n", "5:2", "bad cube character 'x'"),
    (HEAD + ".names a b z\n11 2\n", "5:4", "expected output value 0 or 1"),
    (HEAD + ".names a z\n1 1\n.names b z\n1 1\n", "6:10", "'z' is driven twice"),
    (HEAD + ".names b a\n1 1\n", "4:10", "which is a primary input"),
    (".model m\n.inputs a b\n.outputs z a\n.names a z\n1 1\n", "3:12",
     "output 'a' is also a primary input"),
    (".model m\n.inputs a\n.outputs z y\n.names a z\n1 1\n", "3:12", "output 'y' is never"),
    (HEAD + ".names a z\n1 1\n.end\n.model n\n", "7:1", "a second '.model'"),
    (HEAD + "11 1\n", "4:1", "a cover line outside '.names'"),
    (HEAD + ".names a z\n1 1\n.wire_load_slope 0.2\n", "6:1", "unknown keyword"),
    (".model m\n.inputs a b[0]\n", "2:11", "not usable as a primary input name"),
    ("", "1:1", "no '.inputs'"),
]


@pytest.mark.parametrize("content, where, fragment", ERRORS, ids=[e[2][:30] for e in ERRORS])
def test_errors_are_located_exit_2(cli, tmp_path, content, where, fragment):
    spec = tmp_path / "n.blif"
    spec.write_text(content)
    code, _, err = cli("compile", spec, "-o", tmp_path / "n.json")
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"{spec}:{where}: error: "), lines[0]
    assert fragment in lines[0], lines[0]
    assert not (tmp_path / "n.json").exists()


def test_blif_design_proves_against_the_bool_full_adder(cli, tmp_path):
    design = tmp_path / "fa.json"
    code, _, err = cli("compile", EXAMPLES / "full_adder_net.blif", "-o", design)
    assert code == 0, err
    code, out, _ = cli("simulate", design, "--level", "logic", "--spec",
                       EXAMPLES / "full_adder.bool")
    assert code == 0 and "PASSED" in out
    code, out, _ = cli("simulate", EXAMPLES / "full_adder_net.blif", "--level", "kinematic")
    assert code == 0 and "PASSED: level kinematic" in out


def test_documented_example_is_the_full_adder():
    doc = (EXAMPLES.parent / "docs" / "spec-formats.md").read_text()
    block = re.search(r"## `\.blif`.*?```\n(.*?)```", doc, re.S)
    assert block, "BLIF example missing from docs/spec-formats.md"
    spec = parse_blif(block.group(1), "doc.blif")
    for a, b, c in itertools.product((0, 1), repeat=3):
        assert value(spec, "s", (a, b, c)) == (a + b + c) % 2
        assert value(spec, "cout", (a, b, c)) == (a + b + c) // 2
