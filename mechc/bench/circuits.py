"""The benchmark circuits: random circuits of a chosen size, with the spec they compute, and
the set the speed benchmark measures (:func:`bench_circuits`: two examples, the sequential
example once it compiles, and two random circuits).

A circuit is grown as a random DAG of library cells (fan-in 2, fan-out at most 3, depth kept
moderate so the force budget stays within an actuator's reach); every net nobody reads becomes
an output; the spec is the circuit's own truth table, so a proof of it is a proof that the
mechanism computes what its netlist says.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mechc.frontends import load_spec
from mechc.frontends.boolfile import parse_bool
from mechc.frontends.fsm import parse_fsm_file
from mechc.ir.design import Design
from mechc.ir.netlist import CellInst, Netlist
from mechc.ir.seqspec import FlowTable
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import Cube, input_matrix
from mechc.passes.assemble import MechOptions
from mechc.pipeline import CompileOptions, compile_spec

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"

TYPES = ["AND", "OR", "NAND", "NOR", "AND_NOT", "OR_NOT", "NOT"]
CELL_OF = {"AND": "and", "OR": "or", "NAND": "nand", "NOR": "nor", "AND_NOT": "and_not",
           "OR_NOT": "or_not", "NOT": "not", "XOR": "xor"}


def adder2_spec() -> Spec:
    """a1 a0 + b1 b0 + cin = s2 s1 s0, as a .bool spec: the 2-bit adder with carry-in of the
    timing and screen benchmarks (its carries go through AMPLIFIERs once compiled)."""
    on: dict[str, list[int]] = {"s2": [], "s1": [], "s0": []}
    for row in range(32):
        total = ((row >> 3) & 3) + ((row >> 1) & 3) + (row & 1)
        for bit, o in ((2, "s2"), (1, "s1"), (0, "s0")):
            if (total >> bit) & 1:
                on[o].append(row)
    text = "inputs a1 a0 b1 b0 cin\noutputs s2 s1 s0\n" + "".join(
        f"{o} = minterms({', '.join(map(str, v))})\n" for o, v in on.items())
    return parse_bool(text, "<adder2>")


def random_netlist(n_cells: int, n_inputs: int = 6, seed: int = 0, max_depth: int = 5,
                   max_fanout: int = 3) -> Netlist:
    rng = np.random.default_rng(seed)
    inputs = [f"x{i}" for i in range(n_inputs)]
    nl = Netlist(inputs)
    depth = {x: 0 for x in inputs}
    fanout = {x: 0 for x in inputs}
    nets = list(inputs)
    for c in range(1, n_cells + 1):
        t = TYPES[int(rng.integers(len(TYPES)))]
        k = 1 if t == "NOT" else 2
        pool = [x for x in nets if fanout[x] < max_fanout and depth[x] < max_depth]
        # prefer nets nobody reads yet, so every cell ends up in some output's cone
        unread = [x for x in pool if fanout[x] == 0]
        ins: list[str] = []
        while len(ins) < k:
            src = unread if unread and rng.random() < 0.7 else pool
            cand = [x for x in src if x not in ins]
            if not cand:
                cand = [x for x in pool if x not in ins]
            pick = cand[int(rng.integers(len(cand)))]
            ins.append(pick)
            if pick in unread:
                unread.remove(pick)
        out = f"n{c}"
        nl.add_cell(CellInst(f"c{c}", CELL_OF[t], t, tuple(ins), (out,)))
        for x in ins:
            fanout[x] += 1
        depth[out] = 1 + max(depth[x] for x in ins)
        fanout[out] = 0
        nets.append(out)
    outs = [x for x in nets if fanout[x] == 0 and x not in inputs]
    for i, net in enumerate(outs):
        nl.set_output(f"z{i}", net)
    nl.check()
    return nl


def spec_of(nl: Netlist, name: str = "random") -> Spec:
    n = len(nl.inputs)
    m = input_matrix(n)
    nets = nl.evaluate({x: m[k] for k, x in enumerate(nl.inputs)})
    funcs = {}
    for o, net in nl.outputs.items():
        on = np.flatnonzero(nets[net])
        funcs[o] = OutputSpec(o, on=[Cube.minterm(int(x), n) for x in on])
    return Spec(name, "bool", list(nl.inputs), list(nl.outputs), funcs)


def random_compiled(target_cells: int, seed: int = 0, options=None):
    """A design compiled by mechc from a random spec, grown until it has about
    ``target_cells`` cells (±25 %): hazard-free, as every compiled design is."""
    rng = np.random.default_rng(seed)
    n_in, n_out = 4, 1
    best = None
    for _ in range(40):
        n = 1 << n_in
        funcs = {}
        for j in range(n_out):
            t = rng.random(n)
            on = np.flatnonzero(t < 0.4)
            dc = np.flatnonzero((t >= 0.4) & (t < 0.5))
            funcs[f"z{j}"] = OutputSpec(f"z{j}", on=[Cube.minterm(int(x), n_in) for x in on],
                                        dc=[Cube.minterm(int(x), n_in) for x in dc])
        spec = Spec(f"random{target_cells}", "bool", [f"x{i}" for i in range(n_in)],
                    list(funcs), funcs)
        d = compile_spec(spec, options)
        cells = len(d.netlist.cells)
        if best is None or abs(cells - target_cells) < abs(len(best.netlist.cells)
                                                             - target_cells):
            best = d
        if abs(cells - target_cells) <= 0.25 * target_cells:
            return d
        if cells < target_cells:
            if n_out < 4:
                n_out += 1
            else:
                n_in, n_out = n_in + 1, 1
        else:
            n_out = max(1, n_out - 1)
    return best


@dataclass
class Circuit:
    """One benchmark circuit and how much of it the dynamic level runs."""

    name: str
    design: Design
    max_cases: int | None = None  # dynamic changes run (None: the proof's own plan)
    note: str = ""
    sequential: bool = False  # proved by mechc.proofs.seq_logic / seqmech, never pruned


def bench_circuits(quick: bool, say: Callable[[str], None]) -> list[Circuit]:
    """The circuits the speed benchmark measures; ``say`` reports the ones skipped."""
    out = [Circuit("sorter", compile_spec(load_spec(EXAMPLES / "sorter.bool"))),
           Circuit("full_adder", compile_spec(load_spec(EXAMPLES / "full_adder.bool")))]
    fsm = EXAMPLES / "speedctl.fsm"
    if fsm.exists():
        try:
            d = compile_spec(parse_fsm_file(fsm))
            out.append(Circuit("speedctl", d, sequential=True))
        except Exception as e:  # another issue's front end: measure it only once it compiles
            say(f"note: {fsm.name} does not compile yet ({type(e).__name__}: {e}); skipped")
    else:
        say("note: examples/speedctl.fsm does not exist yet; skipped")
    for cells, cases in ((30, None), (100, 6 if quick else 24)):
        d = random_compiled(cells, seed=cells)
        note = ""
        if not d.stats["design_checks"]["passed"]:  # measure the physics, not the force budget
            d = random_compiled(cells, seed=cells,
                                options=CompileOptions(mech=MechOptions(actuator_force=1e4)))
            note = "actuators rated 1e4 N (the 100 N default fails the force check)"
        out.append(Circuit(f"random{cells}", d, cases, note))
    return out


def random_flow_table(rng: np.random.Generator, rows: int, inputs: int = 2, outputs: int = 1,
                      p_entry: float = 0.8, p_dc_output: float = 0.0) -> FlowTable:
    """A random valid primitive flow table (benchmarks and property tests): each row stable
    in one column (every column used while rows last), each single-input change from it
    specified with probability ``p_entry`` towards a random row stable in the new column
    (else ``-``), each output bit unspecified with probability ``p_dc_output`` (at 0 no extra
    random numbers are drawn, so seeds give the tables they always gave)."""
    ncol = 1 << inputs
    cols = [i ^ (i >> 1) for i in range(ncol)]  # Gray order, as tables are written
    home = [r % ncol if r < ncol else int(rng.integers(ncol)) for r in range(rows)]
    home = [int(h) for h in rng.permutation(home)] if rows <= ncol else home
    by_col: dict[int, list[int]] = {}
    for r, k in enumerate(home):
        by_col.setdefault(k, []).append(r)
    nxt: list[list[int | None]] = []
    for r in range(rows):
        line: list[int | None] = [None] * ncol
        line[home[r]] = r
        for b in range(inputs):
            k2 = cols.index(cols[home[r]] ^ (1 << b))
            if by_col.get(k2) and rng.random() < p_entry:
                line[k2] = int(rng.choice(by_col[k2]))
        nxt.append(line)
    out: list[list[int | None]] = [[int(v) for v in rng.integers(0, 2, size=outputs)]
                                   for _ in range(rows)]
    if p_dc_output > 0:
        out = [[None if rng.random() < p_dc_output else v for v in line] for line in out]
    names = [f"s{r + 1}" for r in range(rows)]
    return FlowTable([f"x{i + 1}" for i in range(inputs)], [f"z{j + 1}" for j in range(outputs)],
                     cols, names, nxt, out, 0, None, [0] * rows)
