"""The SAT check of static hazards (``passes/hazard_sat.py``) against the exhaustive ternary
enumeration (``passes/ternary.py``), a second method: on random small netlists of every gate
type the two find exactly the same hazardous changes; and the SAT-driven cure leaves no hazard
(checked by enumeration) and computes the same function (brute force)."""

from __future__ import annotations

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.ir.netlist import CellInst, Netlist
from mechc.logic.cubes import input_matrix
from mechc.passes.hazard_cure import cure_hazards
from mechc.passes.hazard_sat import Implicants, all_hazards, prime_around, sat_hazards
from mechc.passes.map_sop import MapOptions
from mechc.passes.ternary import hazard_transitions

LIB = load_library()
TYPES = [("AND", 2), ("AND", 3), ("OR", 2), ("OR", 3), ("NAND", 2), ("NOR", 2), ("XOR", 2),
         ("XNOR", 2), ("NOT", 1), ("AND_NOT", 2), ("OR_NOT", 2)]


def random_netlist(rng: np.random.Generator, n: int, cells: int, outputs: int) -> Netlist:
    """Random gates over the inputs and earlier nets; the last nets are the outputs."""
    nl = Netlist([f"x{i}" for i in range(n)])
    nets = list(nl.inputs)
    for k in range(cells):
        t, w = TYPES[rng.integers(len(TYPES))]
        ins = list(rng.choice(nets, size=w, replace=False)) if w <= len(nets) else nets[:w]
        cls = LIB.for_type(t, w)
        out = f"n{k}"
        nl.add_cell(CellInst(f"c{k}", cls.name, t, tuple(ins), (out,)),
                    pin_names=cls.input_names(w), out_pins=list(cls.outputs))
        nets.append(out)
    for j in range(outputs):
        nl.set_output(f"y{j}", nets[-1 - j])
    nl.check()
    return nl


def enumerated(nl: Netlist) -> dict[str, set[tuple[int, int]]]:
    """Output -> {(moving input, start)} by the exhaustive ternary simulation."""
    n = len(nl.inputs)
    w = 1 << np.arange(n - 1, -1, -1)
    out: dict[str, set[tuple[int, int]]] = {}
    for o, found in hazard_transitions(nl).items():
        out[o] = {(k, int(s)) for k, vecs in found for s in w @ vecs.astype(np.int64)}
    return out


@pytest.mark.parametrize("seed", range(40))
def test_sat_finds_exactly_the_hazards_enumeration_finds(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    nl = random_netlist(rng, n, int(rng.integers(3, 14)), 2)
    want = enumerated(nl)
    for o in nl.outputs:
        got = {(c.moving, c.start) for c in all_hazards(nl, o)}
        assert got == want.get(o, set()), (seed, o)
    assert set(sat_hazards(nl)) == set(want)


def test_random_netlists_do_have_hazards():
    """The comparison above is not vacuous: many of its netlists have hazards."""
    with_hazards = 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(2, 7))
        if enumerated(random_netlist(rng, n, int(rng.integers(3, 14)), 2)):
            with_hazards += 1
    assert with_hazards >= 10


def test_textbook_carry_hazards_by_sat():
    """co = a.b + ci.(a xor b) has its static-1 hazards where b = ci = 1 (a moving) and
    a = ci = 1 (b moving); starts written (a, b, ci) with the mover at 0."""
    nl = Netlist(["a", "b", "ci"])
    for cid, t, ins, out in (("c1", "AND", ["a", "b"], "g"), ("c2", "XOR", ["a", "b"], "p"),
                             ("c3", "AND", ["ci", "p"], "t"), ("c4", "OR", ["g", "t"], "co")):
        cls = LIB.for_type(t, 2)
        nl.add_cell(CellInst(cid, cls.name, t, tuple(ins), (out,)),
                    pin_names=cls.input_names(2), out_pins=list(cls.outputs))
    nl.set_output("co", "co")
    got = {(c.moving, c.start, c.value) for c in all_hazards(nl, "co")}
    assert got == {(0, 0b011, 1), (1, 0b101, 1)}
    imp = Implicants(nl, "co")
    try:
        cube = prime_around(imp, all_hazards(nl, "co")[0])
    finally:
        imp.close()
    assert len(cube) == 2  # b.ci or a.ci: a prime of the majority


@pytest.mark.parametrize("seed", range(12))
def test_sat_cure_leaves_no_hazard_and_the_same_function(seed):
    # the first random netlist of this seed's stream that has a hazard (one without has
    # nothing to cure, so every case here cures something)
    for k in range(200):
        rng = np.random.default_rng([100 + seed, k])
        n = int(rng.integers(3, 7))
        nl = random_netlist(rng, n, int(rng.integers(5, 14)), 2)
        bad = sorted(enumerated(nl))
        if bad:
            break
    assert bad, "no random netlist with a hazard in 200 draws"
    cured = cure_hazards(nl, bad, LIB, MapOptions(), method="sat")
    assert cured is not None
    assert not hazard_transitions(cured)
    bits = input_matrix(n)
    env = {x: bits[i] for i, x in enumerate(nl.inputs)}
    a, b = nl.evaluate(env), cured.evaluate(env)
    for o in nl.outputs:
        assert np.array_equal(a[nl.outputs[o]], b[cured.outputs[o]])
