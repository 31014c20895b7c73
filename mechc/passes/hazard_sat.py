"""Static hazards of a combinational netlist by SAT, for designs too wide to enumerate.

The ternary check (:mod:`mechc.passes.ternary`) simulates every input vector and every
single-input change: 2**n * n of them. Here the same question is put to a SAT solver, once per
input ``k`` (:class:`MovingInput`), with no enumeration. The outputs' cones are written over
variables ``x`` for the other inputs (the start of the change, input ``k`` at 0):

- a binary copy at ``x``, and a second one with input ``k`` at 1;
- a dual-rail (ternary) copy, each net a pair (can be 0, can be 1): input ``k`` can be both
  (X), every other input is its binary value, and each cell's pair is exact for its ternary
  extension (a row of its table is possible where every input can take that row's value), the
  rule :func:`mechc.ir.ternary.evaluate3` simulates.

Only the fan-out of input ``k`` differs between the copies; outside it the second end and the
dual-rail copy reuse the first copy's literals, so the solver never has to rediscover that two
copies of a carry chain agree (written with a free one-hot choice of the moving input instead,
the 32-bit adder's check did not finish in minutes). A model of "output X in the dual-rail
copy, equal in both binary copies" is a static hazard of that output on a change of ``k``;
none, for every ``k``, is a proof over all 2**n * n changes that the output has no static
hazard. The cure (:mod:`mechc.passes.hazard_cure`) asks for hazards one at a time and excludes
those the cubes chosen so far already hold (:meth:`MovingInput.exclude_cube`), so it never
lists them all.
"""

from __future__ import annotations

from dataclasses import dataclass

from mechc.ir.cnf import TABLE_MAX_INPUTS, Cnf, NotEncodable, cell_table, encode_netlist
from mechc.ir.netlist import CellInst, Netlist

#: The solver python-sat runs (CaDiCaL, incremental with assumptions, as the logic proof's).
SOLVER = "cadical195"


@dataclass(frozen=True)
class Change:
    """One single-input change of an output: input ``moving`` rises from ``start`` (an integer,
    input 0 the most significant bit, the moving input 0); ``value`` is the output at both
    ends."""

    output: str
    moving: int
    start: int
    value: int


def cone_cells(nl: Netlist, *nets: str) -> list[CellInst]:
    """The cells the ``nets`` depend on, in the netlist's topological order."""
    need: set[str] = set()
    todo = list(nets)
    while todo:
        x = todo.pop()
        drv = nl.driver.get(x)
        if drv is None or drv[0] not in nl.cells or drv[0] in need:
            continue
        need.add(drv[0])
        todo.extend(nl.cells[drv[0]].inputs)
    return [c for c in nl.topo_cells() if c.id in need]


def encode_ternary(cells: list[CellInst], cnf: Cnf,
                   inputs: dict[str, tuple[int, int]]) -> dict[str, tuple[int, int]]:
    """Every net of ``cells`` as a dual-rail pair of literals (can be 0, can be 1)."""
    nets = dict(inputs)
    cache: dict = {}
    for cell in cells:
        ins = [nets[n] for n in cell.inputs]
        lo, hi = [a for a, _ in ins], [b for _, b in ins]
        t = cell.type
        if t in ("AND", "NAND"):
            out = (cnf.or_(lo), cnf.and_(hi))
        elif t in ("OR", "NOR"):
            out = (cnf.and_(lo), cnf.or_(hi))
        elif t == "NOT":
            out = (ins[0][1], ins[0][0])
        elif t == "AMPLIFIER":
            out = ins[0]
        elif len(ins) <= TABLE_MAX_INPUTS:
            values = cell_table(cell, cache)
            k = len(ins)
            if k == 0:
                out = (-cnf.true, cnf.true) if values[0] else (cnf.true, -cnf.true)
            else:
                rows = {0: [], 1: []}
                for r, v in enumerate(values):
                    rows[int(v)].append(cnf.and_([hi[i] if (r >> (k - 1 - i)) & 1 else lo[i]
                                                  for i in range(k)]))
                out = (cnf.or_(rows[0]), cnf.or_(rows[1]))
        else:
            raise NotEncodable(f"cell {cell.id} ({t}, {len(ins)} inputs) has no CNF form "
                               f"beyond {TABLE_MAX_INPUTS} inputs")
        if t in ("NAND", "NOR"):
            out = (out[1], out[0])
        for net in cell.outputs:
            nets[net] = out
    return nets


def fanout_cells(cells: list[CellInst], net: str) -> list[CellInst]:
    """The cells of ``cells`` (topologically ordered) that ``net`` reaches."""
    reached = {net}
    out = []
    for c in cells:
        if any(i in reached for i in c.inputs):
            out.append(c)
            reached.update(c.outputs)
    return out


class MovingInput:
    """The static hazards of some outputs of ``nl`` on the changes of one input ``k``, found one
    at a time by a SAT solver. Outside the moving input's fan-out the two ends and the
    dual-rail copy share the binary copy's literals (they are equal there), so each copy adds
    only that fan-out: the solver never has to rediscover that two copies of a carry chain
    agree."""

    def __init__(self, nl: Netlist, k: int, outputs: list[str]):
        # python-sat's solvers are compiled extensions: loaded when a check needs them
        from pysat.solvers import Solver

        self.n = n = len(nl.inputs)
        self.k = k
        names = list(nl.inputs)
        nets = {o: nl.outputs[o] for o in outputs}
        cells = cone_cells(nl, *nets.values())
        moved = fanout_cells(cells, names[k])
        cnf = Cnf()
        self.x = x = [cnf.new() if i != k else -cnf.true for i in range(n)]
        a = encode_netlist(nl, cnf, dict(zip(names, x)), cells)
        b = encode_netlist(nl, cnf, {**a, names[k]: cnf.true}, moved)
        t0 = {net: (-lit, lit) for net, lit in a.items()}
        t0[names[k]] = (cnf.true, cnf.true)
        tern = encode_ternary(moved, cnf, t0)
        reach = {names[k]} | {net for c in moved for net in c.outputs}
        self.a = {o: a[net] for o, net in nets.items()}
        self.hazards = {o: cnf.and_([*tern[net], -cnf.xor2(a[net], b[net])])
                        for o, net in nets.items() if net in reach}
        self.top = cnf.top
        self.solver = Solver(name=SOLVER, bootstrap_with=cnf.clauses)

    def next(self, output: str | list[str] | None = None) -> Change | None:
        """A static hazard of ``output`` (of any of a list, default: of any output) not yet
        excluded, or None: none of them has one on this input's changes."""
        outs = ([output] if isinstance(output, str) else
                list(self.hazards) if output is None else list(output))
        outs = [o for o in outs if o in self.hazards]
        if not outs:
            return None
        if len(outs) == 1:
            goal = self.hazards[outs[0]]
        else:  # a fresh literal that implies one of their hazards, assumed for this call
            self.top += 1
            goal = self.top
            self.solver.add_clause([-goal] + [self.hazards[o] for o in outs])
        if not self.solver.solve(assumptions=[goal]):
            return None
        model = set(lit for lit in self.solver.get_model() if lit > 0)
        start = sum(1 << (self.n - 1 - i) for i in range(self.n)
                    if i != self.k and self.x[i] in model)
        o = next(o for o in outs if self.hazards[o] in model)
        return Change(o, self.k, start, int(self.a[o] in model))

    def exclude(self, ch: Change) -> None:
        """Ask for other changes than ``ch`` from now on."""
        self.solver.add_clause([-self.x[i] if (ch.start >> (self.n - 1 - i)) & 1 else self.x[i]
                                for i in range(self.n) if i != self.k])

    def exclude_cube(self, cube: list[tuple[int, int]]) -> None:
        """Ask only for changes outside ``cube`` (literals (input, value)); a cube with a literal
        of the moving input holds none of its changes."""
        if all(i != self.k for i, _ in cube):
            self.solver.add_clause([-self.x[i] if v else self.x[i] for i, v in cube])

    def close(self) -> None:
        self.solver.delete()


def _outputs(nl: Netlist, outputs: list[str] | None) -> list[str]:
    """The named outputs (default all) that a cell drives (an input passed through has no
    hazard)."""
    return [o for o in (outputs if outputs is not None else list(nl.outputs))
            if nl.outputs[o] not in nl.inputs]


def sat_hazards(nl: Netlist, outputs: list[str] | None = None) -> dict[str, Change]:
    """Output -> one static hazard (a witness), for every output that has any (SAT: a proof
    over every vector and single-input change that the others have none)."""
    found: dict[str, Change] = {}
    outs = _outputs(nl, outputs)
    for k in range(len(nl.inputs)):
        todo = [o for o in outs if o not in found]
        if not todo:
            break
        f = MovingInput(nl, k, todo)
        try:
            while (ch := f.next(todo)) is not None:  # one call proves "none" for them all
                found[ch.output] = ch
                todo.remove(ch.output)
        finally:
            f.close()
    return found


def all_hazards(nl: Netlist, output: str, limit: int = 1 << 20) -> list[Change]:
    """Every static hazard of one output (up to ``limit``), each a distinct change: what the
    enumeration finds, by SAT (the tests compare the two)."""
    out: list[Change] = []
    for k in range(len(nl.inputs)):
        f = MovingInput(nl, k, _outputs(nl, [output]))
        try:
            while len(out) < limit and (ch := f.next(output)) is not None:
                out.append(ch)
                f.exclude(ch)
        finally:
            f.close()
    return out


class Implicants:
    """Whether a cube is an implicant of one output of ``nl`` (or of its complement), by SAT on
    the output's cone."""

    def __init__(self, nl: Netlist, output: str):
        from pysat.solvers import Solver  # compiled extension, loaded on use

        self.n = len(nl.inputs)
        cnf = Cnf()
        self.x = [cnf.new() for _ in range(self.n)]
        net = nl.outputs[output]
        self.y = encode_netlist(nl, cnf, dict(zip(nl.inputs, self.x)), cone_cells(nl, net))[net]
        self.solver = Solver(name=SOLVER, bootstrap_with=cnf.clauses)

    def holds(self, cube: list[tuple[int, int]], value: int) -> bool:
        """Whether the output is ``value`` at every point of ``cube``."""
        lits = [self.x[i] if v else -self.x[i] for i, v in cube]
        return not self.solver.solve(assumptions=lits + [-self.y if value else self.y])

    def close(self) -> None:
        self.solver.delete()


def prime_around(imp: Implicants, ch: Change) -> list[tuple[int, int]]:
    """A prime implicant of the output (of its complement for a static-0 change) containing
    both ends of ``ch`` with the moving input free: the change's start without the moving
    input, then each literal dropped in turn while the cube stays an implicant."""
    n = imp.n
    cube = [(i, (ch.start >> (n - 1 - i)) & 1) for i in range(n) if i != ch.moving]
    for lit in list(cube):
        trial = [c for c in cube if c != lit]
        if imp.holds(trial, ch.value):
            cube = trial
    return cube
