"""The parsed specification: what every front end produces and every proof checks against."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechc.ir import expr as ex
from mechc.ir.network import Network
from mechc.logic.cubes import DC, MAX_TABLE_INPUTS, Cube, cube_table, input_matrix


@dataclass
class OutputSpec:
    """One output: an expression or on-set cubes, don't-care and off-set cubes.

    A minterm in none of the lists takes the value ``rest``: 0 for ``.bool`` and PLA types
    f/fd, DC for fr/fdr (explicit off-set), 1 for r/dr. Precedence: dc over on over off.
    """

    name: str
    expr: ex.Expr | None = None
    on: list[Cube] = field(default_factory=list)
    dc: list[Cube] = field(default_factory=list)
    off: list[Cube] = field(default_factory=list)
    rest: int = 0
    line: int = 0


@dataclass
class Spec:
    path: str
    kind: str  # "bool" | "pla" | "fsm"
    inputs: list[str]
    outputs: list[str]
    functions: dict[str, OutputSpec]
    # safe identifier -> the name as the source file wrote it, where the two differ (PLA
    # names such as ``di<11>``); for display only
    display: dict[str, str] = field(default_factory=dict)
    # a structural network the author gave (BLIF, Verilog) as clean BLIF text, model ``top``,
    # kept for multi-level synthesis; empty for specs given as functions
    structure: str = field(default="", repr=False, compare=False)
    # a spec too wide for a truth table (BLIF, Verilog beyond MAX_TABLE_INPUTS inputs) is
    # valued by its network alone: ``functions`` then holds no cubes, and every value comes
    # from simulating this network (no 2**n table anywhere)
    network: Network | None = field(default=None, repr=False, compare=False)
    _tables: dict[str, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    @property
    def n(self) -> int:
        return len(self.inputs)

    def has_table(self) -> bool:
        return self.n <= MAX_TABLE_INPUTS and self.network is None

    @property
    def by_network(self) -> bool:
        """Whether the spec is valued by its network (no functions, no table)."""
        return self.network is not None

    def table(self, name: str) -> np.ndarray:
        """Truth table (0/1/DC per minterm) of one output; needs n <= MAX_TABLE_INPUTS."""
        if name not in self._tables:
            self._tables[name] = self._build_table(self.functions[name])
        return self._tables[name]

    def _build_table(self, f: OutputSpec) -> np.ndarray:
        n = self.n
        if n > MAX_TABLE_INPUTS or self.network is not None:
            raise ValueError(f"{n} inputs is too many for a truth table")
        if f.expr is not None:
            m = input_matrix(n)
            env = {name: m[k] for k, name in enumerate(self.inputs)}
            on = ex.evaluate(f.expr, env, 1 << n)
        else:
            on = cube_table(f.on, n)
        table = np.full(1 << n, f.rest, dtype=np.int8)
        if f.off:
            table[cube_table(f.off, n)] = 0
        table[on] = 1
        if f.dc:
            table[cube_table(f.dc, n)] = DC
        return table

    def values_at(self, bits: np.ndarray) -> dict[str, np.ndarray]:
        """Spec value (0, 1 or DC) of every output at input vectors given as a boolean
        (n, N) matrix (row k = input k). Uses the network of a network-valued spec, else the
        truth table up to MAX_TABLE_INPUTS inputs and the cubes beyond (any number of inputs)."""
        n = self.n
        if self.network is not None:
            vals = self.network.evaluate({x: bits[k] for k, x in enumerate(self.inputs)})
            return {o: vals[o].astype(np.int8) for o in self.outputs}
        if n <= MAX_TABLE_INPUTS:
            w = (1 << np.arange(n - 1, -1, -1, dtype=np.int64))
            rows = (bits.astype(np.int64) * w[:, None]).sum(axis=0)
            return {o: self.table(o)[rows] for o in self.outputs}
        out = {}
        for o in self.outputs:
            f = self.functions[o]
            if f.expr is not None:
                env = {name: bits[k] for k, name in enumerate(self.inputs)}
                on = ex.evaluate(f.expr, env, bits.shape[1])
            else:
                on = _in_cubes(f.on, bits, n)
            v = np.full(bits.shape[1], f.rest, dtype=np.int8)
            if f.off:
                v[_in_cubes(f.off, bits, n)] = 0
            v[on] = 1
            if f.dc:
                v[_in_cubes(f.dc, bits, n)] = DC
            out[o] = v
        return out

    # ---- JSON echo: enough to re-prove a compiled design against -------------------------
    def to_json(self) -> dict:
        if self.network is not None:  # the network is the spec: its BLIF text is echoed
            return {"source": self.path, "kind": self.kind, "inputs": list(self.inputs),
                    "outputs": list(self.outputs), "functions": {},
                    "network": self.network.to_blif()}
        funcs = {}
        for name in self.outputs:
            f = self.functions[name]
            d: dict = {}
            if f.expr is not None:
                d["expr"] = ex.to_text(f.expr)
            else:
                d["on"] = [c.to_string(self.n) for c in f.on]
            d["dc"] = [c.to_string(self.n) for c in f.dc]
            if f.off:
                d["off"] = [c.to_string(self.n) for c in f.off]
            if f.rest:
                d["rest"] = "dc" if f.rest == DC else 1
            funcs[name] = d
        return {"source": self.path, "kind": self.kind, "inputs": list(self.inputs),
                "outputs": list(self.outputs), "functions": funcs}



def _in_cubes(cubes: list[Cube], bits: np.ndarray, n: int) -> np.ndarray:
    """Which columns of ``bits`` lie in the union of ``cubes`` (works for any n)."""
    hit = np.zeros(bits.shape[1], dtype=bool)
    for c in cubes:
        m = np.ones(bits.shape[1], dtype=bool)
        for k, positive in c.literal_list(n):
            m &= bits[k] if positive else ~bits[k]
        hit |= m
    return hit
