"""Local cures of static hazards (``passes/hazard_cure.py``): the cured network computes the
same function on every vector (brute force), has no static hazard left (ternary simulation,
itself tested on the textbook carry in tests/test_multilevel.py), and each cube it adds lies
inside the function's on-set (or off-set) with the changes it cures inside it."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.ir.netlist import CellInst, Netlist
from mechc.logic.cubes import input_matrix
from mechc.passes.hazard_cure import cover_changes, cure_hazards
from mechc.passes.map_sop import MapOptions
from mechc.passes.ternary import static_hazards

LIB = load_library()


def add(nl: Netlist, cid: str, t: str, ins: list[str], out: str) -> None:
    cls = LIB.for_type(t, len(ins))
    nl.add_cell(CellInst(cid, cls.name, t, tuple(ins), (out,)),
                pin_names=cls.input_names(len(ins)), out_pins=list(cls.outputs))


def table(nl: Netlist) -> dict[str, np.ndarray]:
    bits = input_matrix(len(nl.inputs))
    vals = nl.evaluate({x: bits[i] for i, x in enumerate(nl.inputs)})
    return {o: vals[net] for o, net in nl.outputs.items()}


def textbook_carry() -> Netlist:
    nl = Netlist(["a", "b", "ci"])
    add(nl, "c1", "AND", ["a", "b"], "g")
    add(nl, "c2", "XOR", ["a", "b"], "p")
    add(nl, "c3", "AND", ["ci", "p"], "t")
    add(nl, "c4", "OR", ["g", "t"], "co")
    nl.set_output("co", "co")
    return nl


def test_the_textbook_carry_is_cured_and_still_the_carry():
    nl = textbook_carry()
    assert static_hazards(nl) == {"co": 2}
    cured = cure_hazards(nl, ["co"], LIB, MapOptions())
    assert static_hazards(cured) == {}
    bits = input_matrix(3)
    majority = (bits[0] & bits[1]) | (bits[0] & bits[2]) | (bits[1] & bits[2])
    assert np.array_equal(table(cured)["co"], majority)
    # a moving with b = ci = 1 is held by the cube b.ci, b moving by a.ci: factored
    # ci.(a + b), an AND and an OR, and one more OR adds them to the network's output
    assert len(cured.cells) == len(nl.cells) + 3


def test_cubes_lie_in_the_on_set_and_contain_their_changes():
    rng = np.random.default_rng(3)
    n = 6
    on = rng.random(1 << n) < 0.6
    moves, starts = [], []
    for m in range(1 << n):
        for k in range(n):
            bit = 1 << k
            if not m & bit and on[m] and on[m | bit]:
                moves.append(bit)
                starts.append(m)
    mv, st = np.array(moves, dtype=np.int64), np.array(starts, dtype=np.int64)
    cubes = cover_changes(on, mv, st, n)
    rows = np.arange(1 << n)
    for c in cubes:
        assert on[(rows & c.mask) == c.value].all()
    for bit, m in zip(moves, starts):
        assert any(not c.mask & bit and (m & c.mask) == c.value for c in cubes)


def random_network(rng: np.random.Generator, n: int, cells: int) -> Netlist:
    nl = Netlist([f"x{i}" for i in range(n)])
    nets = list(nl.inputs)
    for k in range(cells):
        t = str(rng.choice(["AND", "OR", "XOR", "NAND", "NOR", "AND_NOT", "OR_NOT"]))
        ins = [str(x) for x in rng.choice(nets, size=2, replace=False)]
        add(nl, f"c{k}", t, ins, f"n{k}")
        nets.append(f"n{k}")
    for j, net in enumerate(nets[-3:]):
        nl.set_output(f"y{j}", net)
    return nl


@pytest.mark.parametrize("seed", range(12))
def test_random_reconvergent_networks_cured(seed):
    rng = np.random.default_rng(seed)
    nl = random_network(rng, 5, 14)
    bad = static_hazards(nl)
    cured = cure_hazards(nl, sorted(bad), LIB, MapOptions())
    assert static_hazards(cured) == {}
    want, got = table(nl), table(cured)
    for o in want:
        assert np.array_equal(want[o], got[o]), o
