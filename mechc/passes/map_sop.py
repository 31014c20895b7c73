"""Technology mapping: minimised equations -> a netlist of library cells (``Equations -> Netlist``).

Each output has candidate structures: its sum of products (OR of AND terms), the inverse of its
complement's sum of products (NOR/NAND root by De Morgan), and, where the function is a parity
of some inputs with a residual, an XOR/XNOR chain. Inverters are absorbed into AND-NOT, OR-NOT,
NOR and NAND cells (001 §2.5, Fig. 14); a NOT cell remains only where nothing can absorb it.
Structures are planned as hash-consed keys, so a candidate's cost counts only cells not already
built for earlier outputs (shared terms are free), and the cheapest is taken per output.
"""

from __future__ import annotations

from dataclasses import dataclass

from mechc.cells.library import Library
from mechc.ir import expr as ex
from mechc.ir.equations import Cover, Equations
from mechc.ir.logic_types import TYPES
from mechc.ir.netlist import CellInst, Netlist
from mechc.passes.map_declared import declared_candidates, declared_expr

Key = tuple  # ("in", name) | ("CONST", value) | (TYPE, (child keys...))


@dataclass
class MapOptions:
    fan_in: int | None = None  # cap on AND/OR/NAND/NOR inputs (default: the library's limit)
    phase: str = "auto"  # "auto": also try complement and XOR forms; "sop": sum of products only
    hazard_free: bool = True  # build covers with consensus terms (outputs dwell; §3)
    prefer: tuple[str, ...] = ()  # cells used wherever they fit, even if not auto_select
    target: str = "conventional"  # "threshold" | "auto": THRESHOLD cells (threshold_map.py)


class Planner:
    def __init__(self, library: Library, fan_in: int | None, prefer: tuple[str, ...] = ()):
        self.lib = library
        self.fan_in = fan_in
        self.prefer = prefer

    # ---- primitive gates --------------------------------------------------------------------
    def limit(self, type_name: str) -> int:
        lib_max = self.lib.max_fan_in(type_name)
        if lib_max == 0:
            raise self.lib.no_cell_error(type_name)
        return min(lib_max, self.fan_in) if self.fan_in else lib_max

    def gate(self, type_name: str, ins: list[Key]) -> Key:
        if TYPES[type_name].commutative:
            ins = sorted(ins, key=repr)
        cap = self.limit(type_name)
        if len(ins) > cap:
            inner = {"AND": "AND", "OR": "OR", "NAND": "AND", "NOR": "OR"}[type_name]
            # fold the surplus into sub-gates of the non-inverting kind
            groups = [ins[i:i + cap] for i in range(0, len(ins), cap)]
            subs = [g[0] if len(g) == 1 else self.gate(inner, g) for g in groups]
            return self.gate(type_name, subs)
        return (type_name, tuple(ins))

    def cost(self, key: Key, seen: set) -> int:
        """Parts of the cells under ``key`` not already in ``seen`` (adds them to ``seen``)."""
        if key[0] == "in" or key in seen:
            return 0
        seen.add(key)
        if key[0] == "CONST":
            return self.costed("CONST", 0).cost(0)
        total = self.costed(key[0], len(key[1])).cost(len(key[1]))
        return total + sum(self.cost(k, seen) for k in key[1])

    def costed(self, type_name: str, n: int):
        """The cell a structure is costed with: the mapper's own choice, so preferred cells
        (--use-cell) replace cells without changing which structure is built."""
        return (self.lib.for_type(type_name, n)
                or self.lib.for_type(type_name, n, self.prefer))

    def cheaper(self, a: Key, b: Key) -> Key:
        return a if self.cost(a, set()) <= self.cost(b, set()) else b

    # ---- AND / OR of literals (absorbing inverters) -------------------------------------------
    def and_(self, P: list[Key], N: list[Key]) -> Key:
        if not P and not N:
            return ("CONST", 1)
        if not N:
            return P[0] if len(P) == 1 else self.gate("AND", P)
        if not P:
            return self.gate("NOT", N) if len(N) == 1 else self.gate("NOR", N)
        base = P[0] if len(P) == 1 else self.gate("AND", P)
        if len(N) == 1:
            return self.gate("AND_NOT", [base, N[0]])
        chain = base
        for k in N:
            chain = self.gate("AND_NOT", [chain, k])
        return self.cheaper(chain, self.gate("AND_NOT", [base, self.gate("OR", N)]))

    def or_(self, P: list[Key], N: list[Key]) -> Key:
        if not P and not N:
            return ("CONST", 0)
        if not N:
            return P[0] if len(P) == 1 else self.gate("OR", P)
        if not P:
            return self.gate("NOT", N) if len(N) == 1 else self.gate("NAND", N)
        base = P[0] if len(P) == 1 else self.gate("OR", P)
        if len(N) == 1:
            return self.gate("OR_NOT", [base, N[0]])
        chain = base
        for k in N:
            chain = self.gate("OR_NOT", [chain, k])
        return self.cheaper(chain, self.gate("OR_NOT", [base, self.gate("AND", N)]))

    # ---- whole covers -----------------------------------------------------------------------
    def sop_parts(self, cover: Cover, inputs: list[str]) -> tuple[list[Key], list[Key]] | Key:
        """Term keys split into plain terms and single negative literals (for OR-NOT)."""
        n = len(inputs)
        P: list[Key] = []
        N: list[Key] = []
        for cube in cover.cubes:
            if cube.mask == 0:
                return ("CONST", 1)
            lits = cube.literal_list(n)
            pos = [("in", inputs[k]) for k, v in lits if v]
            neg = [("in", inputs[k]) for k, v in lits if not v]
            if not pos and len(neg) == 1:
                N.append(neg[0])
            else:
                P.append(self.and_(pos, neg))
        return P, N

    def sop(self, cover: Cover, inputs: list[str], invert: bool = False) -> Key:
        parts = self.sop_parts(cover, inputs)
        if isinstance(parts, tuple) and parts and parts[0] == "CONST":
            return ("CONST", 0 if invert else 1)
        P, N = parts
        if invert:  # ¬(ΣP + ΣN̄) = ΠP̄ · ΠN
            return self.and_(N, P)
        return self.or_(P, N)

    def xor(self, a: Key, b: Key, invert: bool) -> Key:
        return self.gate("XNOR" if invert else "XOR", [a, b])


@dataclass
class Mapped:
    netlist: Netlist
    implemented: dict[str, str]  # output -> expression of the structure built
    # the equations built, when the mapper took ``Equations.alternative`` (fewer parts)
    equations: Equations | None = None


def map_sop(eq: Equations, library: Library, opts: MapOptions | None = None) -> Mapped:
    """Every output onto AND/OR/NOT-family cells (the conventional target). Where the
    equations carry an alternative set of covers (per output, against shared across
    outputs), both are mapped and the one with fewer parts is built: fewer distinct products
    can still cost more parts (smaller cubes have more literals, each complemented one an
    inverting stage)."""
    first = _map_sop(eq, library, opts)
    if eq.alternative is None:
        return first
    other = _map_sop(eq.alternative, library, opts)
    if _parts(other.netlist, library) < _parts(first.netlist, library):
        other.equations = eq.alternative
        return other
    return first


def _parts(nl: Netlist, library: Library) -> int:
    return sum(library[c.cell].cost(len(c.inputs)) for c in nl.cells.values())


def _map_sop(eq: Equations, library: Library, opts: MapOptions | None = None) -> Mapped:
    opts = opts or MapOptions()
    for name in opts.prefer:  # an unknown name is an error, not silently ignored
        library[name]
    pl = Planner(library, opts.fan_in, tuple(opts.prefer))
    built: set = set()
    roots: dict[str, Key] = {}
    for name in eq.outputs:
        cover = eq.hazard_free.get(name, eq.covers[name]) if opts.hazard_free else eq.covers[name]
        cands = [pl.sop(cover, eq.inputs)]
        if opts.phase == "auto":
            comp = eq.complements.get(name)
            if opts.hazard_free:
                comp = eq.hazard_free_complements.get(name, comp)
            if comp is not None:
                cands.append(pl.sop(comp, eq.inputs, invert=True))
            xf = eq.xor_forms.get(name)
            if xf is not None:
                cands.extend(_xor_candidates(pl, xf, eq.inputs))
        # one cell of a type a cell file declares, where the output is exactly that function
        declared = [k for k in declared_candidates(cover, eq.inputs, declared_types(library))
                    if pl.costed(k[0], len(k[1])) is not None]
        cands.extend(declared)
        # the sum of products is the reference; another form must be strictly cheaper (it may
        # resolve don't-cares differently from the minimised equation)
        best = cands[0]
        best_cost = pl.cost(best, set(built))
        for k in cands[1:]:
            c = pl.cost(k, set(built))
            if c < best_cost:
                best, best_cost = k, c
        for k in declared:  # --use-cell: a declared-type cell asked for by name wins
            if any(library[p].type == k[0] for p in opts.prefer):
                best = k
                break
        pl.cost(best, built)
        roots[name] = best
    return Mapped(_materialise(roots, eq, library, tuple(opts.prefer)),
                  {name: ex.to_text(key_expr(k)) for name, k in roots.items()})


def _xor_candidates(pl: Planner, xf, inputs: list[str]) -> list[Key]:
    out = []
    for residual in xf.residual_keys(pl, inputs):
        acc, inv = residual
        for v in xf.vars:
            acc = ("in", v) if acc is None else pl.xor(acc, ("in", v), False)
        if acc is None:
            continue
        if inv:  # fold the final inversion into the last XOR (XNOR) or a NOT
            if acc[0] == "XOR":
                acc = ("XNOR", acc[1])
            elif acc[0] == "XNOR":
                acc = ("XOR", acc[1])
            else:
                acc = pl.gate("NOT", [acc])
        out.append(acc)
    return out


def key_expr(key: Key) -> ex.Expr:
    """The Boolean expression a planned structure computes (for the JSON 'implemented')."""
    if key[0] == "in":
        return ex.Var(key[1])
    if key[0] == "CONST":
        return ex.Const(bool(key[1]))
    a = [key_expr(k) for k in key[1]]
    t = key[0]
    if t == "NOT":
        return ex.Not(a[0])
    if t in ("AND", "NAND"):
        e = ex.And(tuple(a))
    elif t in ("OR", "NOR"):
        e = ex.Or(tuple(a))
    elif t in ("XOR", "XNOR"):
        e = ex.Xor(tuple(a))
    elif t == "AND_NOT":
        e = ex.And((a[0], ex.Not(a[1])))
    elif t == "OR_NOT":
        e = ex.Or((a[0], ex.Not(a[1])))
    elif TYPES.get(t) is not None and TYPES[t].table is not None:
        return declared_expr(t, a)
    else:
        raise ValueError(t)
    return ex.Not(e) if t in ("NAND", "NOR", "XNOR") else e


def _materialise(roots: dict[str, Key], eq: Equations, library: Library,
                 prefer: tuple[str, ...] = ()) -> Netlist:
    nl = Netlist(eq.inputs)
    names: dict[Key, str] = {("in", n): n for n in eq.inputs}
    counter = {"cell": 0, "net": 0}
    # outputs driven by a cell give their name to that net (first output wins)
    out_net_name: dict[Key, str] = {}
    taken = set(eq.inputs) | set(roots)
    for name, key in roots.items():
        if key[0] != "in" and key not in out_net_name:
            out_net_name[key] = name

    def build(key: Key) -> str:
        if key in names:
            return names[key]
        if key[0] == "CONST":
            ins: list[str] = []
            type_name, params = "CONST", {"value": key[1]}
        else:
            ins = [build(k) for k in key[1]]
            type_name, params = key[0], {}
        cell_cls = library.for_type(type_name, len(ins), prefer)
        counter["cell"] += 1
        if key in out_net_name:
            net = out_net_name[key]
        else:
            while True:  # an output or input may already be called n7
                counter["net"] += 1
                net = f"n{counter['net']}"
                if net not in taken:
                    break
        cid = f"c{counter['cell']}"
        nl.add_cell(CellInst(cid, cell_cls.name, type_name, tuple(ins), (net,), params),
                    pin_names=cell_cls.input_names(len(ins)), out_pins=list(cell_cls.outputs))
        names[key] = net
        return net

    for name, key in roots.items():
        nl.set_output(name, build(key))
    nl.check()
    return nl


def declared_types(library: Library) -> list[str]:
    """The logic types the library's cells declare (not built in), sorted."""
    return sorted({c.type for c in library.cells.values()
                   if TYPES.get(c.type) is not None and TYPES[c.type].table is not None})
