"""The SAT miter (mechc.proofs.sat_equiv) against brute force: on random small specs and
netlists both methods give the same verdict per output, every SAT counterexample is a vector
brute force also finds failing, a netlist broken on purpose is caught with a valid
counterexample, and a 24- and a 40-input adder are proved in seconds."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mechc.cells.library import load_library
from mechc.frontends.boolfile import parse_expression_text
from mechc.ir import expr as ex
from mechc.ir.logic_types import evaluate_type, table_rows
from mechc.ir.netlist import CellInst, Netlist
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import DC, Cube, input_matrix
from mechc.passes.map import map_equations
from mechc.passes.minimise import minimise
from mechc.proofs.logic import choose_method, prove_logic
from mechc.proofs.sat_equiv import Cnf, check_equivalence, encode_netlist

TYPES2 = ["AND", "OR", "NAND", "NOR", "AND_NOT", "OR_NOT", "XOR", "XNOR"]


def rand_expr(rng: np.random.Generator, names: list[str], depth: int) -> ex.Expr:
    if depth == 0 or rng.random() < 0.25:
        return ex.Var(names[rng.integers(len(names))])
    kind = rng.integers(4)
    if kind == 0:
        return ex.Not(rand_expr(rng, names, depth - 1))
    args = tuple(rand_expr(rng, names, depth - 1) for _ in range(int(rng.integers(2, 4))))
    return (ex.And, ex.Or, ex.Xor)[kind - 1](args)


def rand_cubes(rng: np.random.Generator, n: int, k: int) -> list[Cube]:
    out = []
    for _ in range(k):
        mask = int(rng.integers(1, 1 << n))
        out.append(Cube(mask, int(rng.integers(0, 1 << n)) & mask))
    return out


def rand_spec(rng: np.random.Generator, n: int, m: int) -> Spec:
    names = [f"x{i}" for i in range(n)]
    funcs = {}
    for j in range(m):
        o = f"f{j}"
        if rng.random() < 0.5:
            funcs[o] = OutputSpec(o, expr=rand_expr(rng, names, 4),
                                  dc=rand_cubes(rng, n, int(rng.integers(0, 2))))
        else:
            funcs[o] = OutputSpec(o, on=rand_cubes(rng, n, int(rng.integers(1, 6))),
                                  dc=rand_cubes(rng, n, int(rng.integers(0, 3))),
                                  off=rand_cubes(rng, n, int(rng.integers(0, 3))),
                                  rest=int(rng.choice([0, 1, DC])))
    return Spec("rand", "bool", names, list(funcs), funcs)


def rand_netlist(rng: np.random.Generator, names: list[str], outputs: list[str]) -> Netlist:
    """Random cells of every encodable kind: two-input types, wide AND/OR beyond the table
    limit, THRESHOLD, CONNECTOR, CONST."""
    nl = Netlist(names)
    nets = list(names)
    for i in range(int(rng.integers(3, 12))):
        pick = rng.integers(6)

        def some(k: int) -> tuple[str, ...]:
            return tuple(nets[j] for j in rng.integers(0, len(nets), size=k))
        if pick <= 1:
            cell = CellInst(f"c{i}", "x", str(rng.choice(TYPES2)), some(2), (f"n{i}",))
        elif pick == 2:
            t = str(rng.choice(["AND", "OR", "NAND", "NOR"]))
            cell = CellInst(f"c{i}", "x", t, some(int(rng.integers(3, 12))), (f"n{i}",))
        elif pick == 3:
            k = int(rng.integers(1, 4))
            cell = CellInst(f"c{i}", "x", "THRESHOLD", some(k), (f"n{i}",),
                            {"weights": [int(w) for w in rng.integers(-2, 3, size=k)],
                             "thresholds": [0.5, 1.5][: int(rng.integers(1, 3))],
                             "below": int(rng.integers(2))})
        elif pick == 4:
            cell = CellInst(f"c{i}", "x", "CONNECTOR", some(1), (f"n{i}",),
                            {"logic": str(rng.choice(["identity", "invert"]))})
        else:
            cell = CellInst(f"c{i}", "x", "CONST", (), (f"n{i}",), {"value": int(rng.integers(2))})
        nl.add_cell(cell)
        nets.append(f"n{i}")
    for o in outputs:
        nl.set_output(o, nets[int(rng.integers(len(names), len(nets)))])
    return nl


def brute_failing(nl: Netlist, spec: Spec) -> dict[str, set[int]]:
    """Per output, every vector (input 0 the MSB) where the netlist differs from a cared value."""
    m = input_matrix(spec.n)
    got = nl.evaluate({name: m[k] for k, name in enumerate(spec.inputs)})
    out = {}
    for o in spec.outputs:
        want = spec.table(o)
        bad = (want != DC) & (got[nl.outputs[o]] != (want == 1))
        out[o] = set(np.flatnonzero(bad).tolist())
    return out


def test_cell_clauses_agree_with_the_cell_functions():
    """Each cell's CNF, solved with the inputs fixed, gives evaluate_type's value on every row
    (table encoding up to 8 inputs, the structural one beyond)."""
    from pysat.solvers import Solver

    for t, k in [(t, 2) for t in TYPES2] + [("AND", 10), ("NOR", 9), ("OR", 11), ("NAND", 12),
                                            ("NOT", 1), ("AND", 5)]:
        names = [f"i{j}" for j in range(k)]
        nl = Netlist(names, None)
        nl.add_cell(CellInst("c", "x", t, tuple(names), ("z",)))
        cnf = Cnf()
        ins = {nm: cnf.new() for nm in names}
        y = encode_netlist(nl, cnf, ins)["z"]
        want = evaluate_type(t, table_rows(k), {}, 1 << k)
        with Solver(name="cadical195", bootstrap_with=cnf.clauses) as s:
            for row in range(0, 1 << k, max(1, (1 << k) // 64)):
                fix = [ins[nm] if (row >> (k - 1 - j)) & 1 else -ins[nm]
                       for j, nm in enumerate(names)]
                assert s.solve(assumptions=fix + [y]) == bool(want[row]), (t, k, row)
                assert s.solve(assumptions=fix + [-y]) == (not want[row]), (t, k, row)


@pytest.mark.parametrize("seed", range(6))
def test_sat_agrees_with_brute_force_on_random_specs_and_netlists(seed):
    rng = np.random.default_rng(seed)
    agreed_bad = agreed_good = 0
    for _ in range(40):
        spec = rand_spec(rng, int(rng.integers(2, 8)), int(rng.integers(1, 4)))
        nl = rand_netlist(rng, spec.inputs, spec.outputs)
        brute = brute_failing(nl, spec)
        eq = check_equivalence(nl, spec)
        for o in spec.outputs:
            assert bool(eq.counterexamples[o]) == bool(brute[o]), (seed, o)
            assert set(eq.counterexamples[o]) <= brute[o]
            # up to 5 distinct counterexamples, as many as there are failing vectors
            assert len(set(eq.counterexamples[o])) == min(5, len(brute[o]))
            agreed_bad += bool(brute[o])
            agreed_good += not brute[o]
    assert agreed_bad > 20 and agreed_good > 5  # both verdicts were exercised


@pytest.mark.parametrize("seed", range(4))
def test_compiled_designs_are_proved_and_broken_ones_caught(seed):
    """A random spec compiled by minimise and map: SAT proves it; one cell's type flipped or
    one input rewired: SAT and brute force agree, and SAT's counterexamples fail by both."""
    rng = np.random.default_rng(100 + seed)
    lib = load_library(())
    caught = 0
    for _ in range(8):
        spec = rand_spec(rng, int(rng.integers(3, 7)), int(rng.integers(1, 3)))
        nl = map_equations(minimise(spec), lib).netlist
        assert check_equivalence(nl, spec).equivalent
        assert prove_logic(nl, spec, method="sat")["passed"]
        cells = [c for c in nl.cells.values() if c.type in TYPES2 or c.type in ("AND", "OR")]
        if not cells:
            continue
        victim = cells[int(rng.integers(len(cells)))]
        swap = {"AND": "OR", "OR": "AND", "NAND": "NOR", "NOR": "NAND", "AND_NOT": "OR_NOT",
                "OR_NOT": "AND_NOT", "XOR": "XNOR", "XNOR": "XOR"}[victim.type]
        bad = Netlist(nl.inputs)
        for c in nl.topo_cells():
            bad.add_cell(CellInst(c.id, c.cell, swap if c is victim else c.type, c.inputs,
                                  c.outputs, c.params))
        for o, net in nl.outputs.items():
            bad.set_output(o, net)
        brute = brute_failing(bad, spec)
        rep = prove_logic(bad, spec, method="sat")
        assert rep["passed"] == (not any(brute.values()))
        for f in rep["failures"]:
            vec = sum(v << (spec.n - 1 - k) for k, v in enumerate(f["inputs"].values()))
            assert vec in brute[f["output"]]
            caught += 1
    assert caught > 0


def adder_netlist(bits: int) -> tuple[Netlist, Spec]:
    """A ripple-carry adder built cell by cell (XOR, AND, OR) and its spec written as .bool
    expressions: each sum bit as the XOR of a, b and the carry expression, the carry as the
    majority of the bit before."""
    names = [f"a{i}" for i in range(bits)] + [f"b{i}" for i in range(bits)]
    nl = Netlist(names)
    carry = None
    for i in range(bits):
        a, b = f"a{i}", f"b{i}"
        nl.add_cell(CellInst(f"x{i}", "x", "XOR", (a, b), (f"p{i}",)))
        nl.add_cell(CellInst(f"g{i}", "x", "AND", (a, b), (f"g{i}",)))
        if carry is None:
            sum_net, carry = f"p{i}", f"g{i}"
        else:
            nl.add_cell(CellInst(f"s{i}", "x", "XOR", (f"p{i}", carry), (f"s{i}",)))
            nl.add_cell(CellInst(f"t{i}", "x", "AND", (f"p{i}", carry), (f"t{i}",)))
            nl.add_cell(CellInst(f"c{i}", "x", "OR", (f"g{i}", f"t{i}"), (f"c{i}",)))
            sum_net, carry = f"s{i}", f"c{i}"
        nl.set_output(f"s{i}", sum_net)
    nl.set_output("cout", carry)
    texts = {}
    c = "0"
    for i in range(bits):
        texts[f"s{i}"] = f"a{i} ^ b{i} ^ ({c})"
        c = f"a{i} & b{i} | (a{i} | b{i}) & ({c})"
    texts["cout"] = c
    funcs = {o: OutputSpec(o, expr=parse_expression_text(t, names, "adder.bool"))
             for o, t in texts.items()}
    return nl, Spec("adder.bool", "bool", names, list(funcs), funcs)


@pytest.mark.parametrize("bits", [12, 20])
def test_wide_adder_proved_by_sat_in_seconds_and_a_broken_one_caught(bits):
    nl, spec = adder_netlist(bits)
    assert spec.n == 2 * bits and choose_method(nl, spec) == "sat"
    t0 = time.perf_counter()
    rep = prove_logic(nl, spec)  # auto: SAT, the only complete method at this width
    assert time.perf_counter() - t0 < 10
    assert rep["passed"] and rep["method"] == "sat" and rep["complete"]
    assert rep["cases"] == 1 << spec.n
    # the carry of bit 5 computed with AND instead of OR
    bad = Netlist(nl.inputs)
    for c in nl.topo_cells():
        bad.add_cell(CellInst(c.id, c.cell, "AND" if c.id == "c5" else c.type, c.inputs,
                              c.outputs, c.params))
    for o, net in nl.outputs.items():
        bad.set_output(o, net)
    rep = prove_logic(bad, spec)
    assert not rep["passed"] and rep["failure_count"] > 0
    for f in rep["failures"]:  # each counterexample checked by integer arithmetic
        v = f["inputs"]
        a = sum(v[f"a{i}"] << i for i in range(bits))
        b = sum(v[f"b{i}"] << i for i in range(bits))
        total = a + b
        o = f["output"]
        want = (total >> bits) & 1 if o == "cout" else (total >> int(o[1:])) & 1
        assert f["expected"] == want and f["got"] != want
        # AND for OR differs only where bit 5 carries out (generated or propagated)
        assert v["a5"] == 1 or v["b5"] == 1
