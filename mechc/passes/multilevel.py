"""Multi-level synthesis: a logic network -> ABC's multi-level optimisation and technology
mapping onto mechc's own cells, costed in parts (``network BLIF -> Netlist``).

The two-level path builds every output as a sum of products, which for an adder, an ALU or a
comparator means wide sums of many products and huge fan-out on every input. Here the network
(a structural BLIF or Verilog as its author wrote it, or the minimised sums of products) goes
through Yosys to ABC, which restructures it (AIG rewriting, choice nodes) and maps it by area
to a Liberty library generated from mechc's cell library: one Liberty cell per logic type and
fan-in the mapper may use, its area the mechc cell's part count (``Cell.cost``). ABC is run
with a few area-oriented scripts and the mapping with the fewest parts is kept. Each mapped
cell becomes a ``CellInst`` of the same library cell, so the back half of the compiler (place,
assemble with its force budget and amplifiers, checks, proofs) is the same as for two levels.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace

from mechc.cells.library import Library
from mechc.errors import DesignError, MechcError
from mechc.ir.equations import Equations
from mechc.ir.netlist import CellInst, Netlist
from mechc.ir.spec import OutputSpec, Spec
from mechc.logic.cubes import Cube
from mechc.logic.yosys import run_yosys
from mechc.passes.factor import factored_netlist
from mechc.passes.hazard_cure import MAX_SAT_CUBES, cure_hazards
from mechc.passes.map import map_equations
from mechc.passes.map_sop import MapOptions
from mechc.passes.minimise import MinimiseOptions, minimise
from mechc.passes.ternary import static_hazards

#: Logic type -> its Liberty function over pins A, B, C, D (n: the fan-in).
_FUNCTIONS = {
    "AND": lambda n: "&".join("ABCD"[:n]),
    "OR": lambda n: "|".join("ABCD"[:n]),
    "NAND": lambda n: "!(" + "&".join("ABCD"[:n]) + ")",
    "NOR": lambda n: "!(" + "|".join("ABCD"[:n]) + ")",
    "XOR": lambda n: "^".join("ABCD"[:n]),
    "XNOR": lambda n: "!(" + "^".join("ABCD"[:n]) + ")",
    "AND_NOT": lambda n: "A&!B",
    "OR_NOT": lambda n: "A|!B",
    "NOT": lambda n: "!A",
}
#: ABC's cut-based mapper matches gates of at most this many inputs well.
MAX_LIBERTY_FAN_IN = 4
#: A buffer is never worth a part (a net is simply shared); its area keeps ABC from using it.
_BUFFER = "BUF"

#: Area-oriented ABC scripts tried; the mapping with the fewest mechc parts is kept.
# ABC's resyn2 spelt out: its short aliases (b, rw, rf, resyn2) are not defined in a script
_RESYN2 = ("balance;rewrite;refactor;balance;rewrite;rewrite,-z;balance;refactor,-z;"
           "rewrite,-z;balance")
SCRIPTS = (
    "+strash;dch,-f;map,-a;topo",
    f"+strash;{_RESYN2};dch,-f;map,-a;topo",
    f"+strash;{_RESYN2};{_RESYN2};dch,-f;amap;topo",
    "+strash;&get,-n;&dch,-f;&nf,-a,-R,1000;&put",
)


@dataclass
class MultiLevel:
    """The mapped network, with what chose it."""

    netlist: Netlist
    implemented: dict[str, str]
    parts: int  # of the mapped cells (before any amplifier)
    script: str  # the ABC script whose mapping was kept
    tried: dict[str, int] = field(default_factory=dict)  # script -> parts
    two_level_outputs: list[str] = field(default_factory=list)  # rebuilt for a hazard
    cured_outputs: list[str] = field(default_factory=list)  # hazards cured by cubes


def liberty(library: Library, fan_in: int | None = None) -> tuple[str, dict[str, tuple]]:
    """A Liberty library of the cells the mapper may use: text, and Liberty cell name ->
    (logic type, fan-in, mechc cell name)."""
    cells: dict[str, tuple] = {}
    lines = ["library(mechc) {"]
    for t, fn in _FUNCTIONS.items():
        n_max = 1 if t == "NOT" else (2 if t in ("AND_NOT", "OR_NOT") else
                                      min(library.max_fan_in(t), MAX_LIBERTY_FAN_IN,
                                          fan_in or MAX_LIBERTY_FAN_IN))
        for n in range(1 if t == "NOT" else 2, n_max + 1):
            cls = library.for_type(t, n)
            if cls is None:
                continue
            name = f"{t}{n}"
            cells[name] = (t, n, cls.name)
            pins = " ".join(f"pin({p}) {{ direction: input; }}" for p in "ABCD"[:n])
            lines.append(f"  cell({name}) {{ area: {cls.cost(n)}; {pins} "
                         f"pin(Y) {{ direction: output; function: \"{fn(n)}\"; }} }}")
    lines.append(f"  cell({_BUFFER}) {{ area: 1000; pin(A) {{ direction: input; }} "
                 "pin(Y) { direction: output; function: \"A\"; } }")
    lines.append("}")
    return "\n".join(lines) + "\n", cells


def equations_blif(eq: Equations) -> str:
    """The minimised sums of products as a BLIF network (one ``.names`` per output), the
    start of multi-level synthesis for a spec given as functions (.bool, .pla)."""
    n = len(eq.inputs)
    lines = [".model top", ".inputs " + " ".join(eq.inputs),
             ".outputs " + " ".join(eq.outputs)]
    for o in eq.outputs:
        lines.append(".names " + " ".join(eq.inputs + [o]))
        lines += [f"{c.to_string(n)} 1" for c in eq.covers[o].cubes]
    return "\n".join(lines + [".end"]) + "\n"


def map_multilevel(blif: str, inputs: list[str], outputs: list[str], library: Library,
                   fan_in: int | None = None) -> MultiLevel:
    """Optimise and map the BLIF network (model ``top``) onto the library; the cheapest of
    :data:`SCRIPTS` in parts."""
    lib_text, cells = liberty(library, fan_in)
    script = ["read_blif input.blif", "hierarchy -top top", "flatten",
              "synth -flatten -top top", "design -save base"]
    for k, s in enumerate(SCRIPTS):
        script += ["design -load base", f"abc -liberty mech.lib -script {s}",
                   "opt_clean -purge", f"write_json mapped{k}.json"]
    want = [f"mapped{k}.json" for k in range(len(SCRIPTS))]
    res = run_yosys("\n".join(script) + "\n", {"input.blif": blif, "mech.lib": lib_text}, want)
    if res.returncode != 0 or not res.files:
        tail = " ".join(ln for ln in res.log.splitlines() if "ERROR" in ln)[:400]
        raise MechcError(f"multi-level synthesis failed in Yosys (exit {res.returncode}): "
                         f"{tail or res.log[-400:]}")
    best: MultiLevel | None = None
    tried: dict[str, int] = {}
    for k, s in enumerate(SCRIPTS):
        text = res.files.get(f"mapped{k}.json")
        if text is None:
            continue
        nl = netlist_from_json(json.loads(text), inputs, outputs, cells, library)
        parts = sum(library[c.cell].cost(len(c.inputs)) for c in nl.cells.values())
        tried[s] = parts
        if best is None or parts < best.parts:
            best = MultiLevel(nl, {}, parts, s)
    assert best is not None
    best.tried = tried
    depth = best.netlist.depth()
    for o, net in best.netlist.outputs.items():
        drv = best.netlist.driver[net][0]
        best.implemented[o] = (f"multi-level network, depth {depth.get(drv, 0)}"
                               if drv in best.netlist.cells else net)
    return best


#: Cut sizes tried for the hazard-free composition (each node a function of at most K nets).
LUT_SIZES = (3, 4, 6)


def map_multilevel_hazard_free(blif: str, inputs: list[str], outputs: list[str],
                               library: Library, map_opts: MapOptions,
                               min_opts: MinimiseOptions, two_level: Netlist | None,
                               fan_in: int | None = None,
                               eq: Equations | None = None) -> MultiLevel:
    """Multi-level logic a mechanism can move without glitches: the candidates are ABC's area
    mapping onto the cells (:func:`map_multilevel`) and ABC's K-input cut decomposition with
    every node built by mechc's own two-level minimiser and mapper (a hazard-free cover of a
    function of at most K nets); each is checked for static hazards (ternary simulation of every
    change, or SAT from :data:`~mechc.passes.ternary.SAT_MIN_INPUTS` inputs), and every output
    that still has one is cured by cubes (:mod:`hazard_cure`) or built hazard-free: from the
    two-level netlist, or
    from the algebraically factored hazard-free covers (``eq`` given; :mod:`factor`), whichever
    has fewer parts; the factored covers are also a candidate of their own. The candidate with
    the fewest parts is kept. A spec too wide for a table comes with neither ``eq`` nor
    ``two_level``: its candidates are ABC's and the cut networks, cured by SAT; where none can
    be made hazard-free that is a :class:`DesignError` naming the outputs (exit 1)."""
    cands: list[MultiLevel] = []
    if eq is not None:
        fac = factored_netlist(eq, library, map_opts)
        if not static_hazards(fac):  # algebraic factoring keeps hazard freedom: checked
            cands.append(MultiLevel(fac, {}, _parts(fac, library),
                                    "hazard-free covers, factored by mechc"))
            if two_level is None or _parts(fac, library) < _parts(two_level, library):
                two_level = fac
    cands.append(map_multilevel(blif, inputs, outputs, library, fan_in))
    script = ["read_blif input.blif", "hierarchy -top top", "flatten",
              "synth -flatten -top top", "design -save base"]
    for k in LUT_SIZES:
        script += ["design -load base", f"abc -lut {k}", "opt_clean -purge",
                   f"write_json lut{k}.json"]
    res = run_yosys("\n".join(script) + "\n", {"input.blif": blif},
                    [f"lut{k}.json" for k in LUT_SIZES])
    cache: dict = {}
    for k in LUT_SIZES:
        text = res.files.get(f"lut{k}.json")
        if text is None:
            continue
        nl = compose_luts(json.loads(text), inputs, outputs, library, map_opts, min_opts, cache)
        cands.append(MultiLevel(nl, {}, _parts(nl, library), f"abc -lut {k}, nodes by mechc"))
    best: MultiLevel | None = None
    tried: dict[str, int] = {}
    uncured: set[str] = set()
    for c in cands:
        bad = static_hazards(c.netlist)
        if bad:
            uncured |= set(bad)
            fixes = []  # (netlist, cured locally)
            if two_level is not None:
                fixes.append((with_two_level(c.netlist, two_level, sorted(bad)), False))
            cured = cure_hazards(c.netlist, sorted(bad), library, map_opts)
            if cured is not None and not static_hazards(cured):
                fixes.append((cured, True))
            if not fixes:
                continue
            c.netlist, local = min(fixes, key=lambda f: _parts(f[0], library))
            c.parts = _parts(c.netlist, library)
            if local:
                c.cured_outputs = sorted(bad)
            else:
                c.two_level_outputs = sorted(bad)
        tried[c.script] = c.parts
        if best is None or c.parts < best.parts:
            best = c
    if best is None:  # never a design with a hazard unreported: exit 1, saying which
        raise DesignError("multi-level synthesis found no hazard-free network: the static "
                          "hazards of " + ", ".join(sorted(uncured)) + " could not be cured "
                          f"in any of {len(cands)} candidates (a cure by cubes needs at most "
                          f"{MAX_SAT_CUBES} cubes an output)")
    best.tried = tried
    _describe(best)
    return best


def _parts(nl: Netlist, library: Library) -> int:
    return sum(library[c.cell].cost(len(c.inputs)) for c in nl.cells.values())


def _describe(ml: MultiLevel) -> None:
    depth = ml.netlist.depth()
    ml.implemented = {}
    for o, net in ml.netlist.outputs.items():
        drv = ml.netlist.driver[net][0]
        how = ("hazard-free cone (the multi-level one had a static hazard)"
               if o in ml.two_level_outputs else
               "multi-level network, its static hazards cured by cubes"
               if o in ml.cured_outputs else "multi-level network")
        ml.implemented[o] = (f"{how}, depth {depth.get(drv, 0)}"
                             if drv in ml.netlist.cells else net)


def _output_bits(mod: dict, outputs: list[str], driver: dict) -> tuple[dict, dict]:
    """Yosys' bit of each output, and bit -> the output that names its net (the first output
    on a bit some cell drives)."""
    out_bits = {o: mod["ports"][o]["bits"][0] for o in outputs}
    named: dict = {}
    for o, b in out_bits.items():
        if b in driver and b not in named:
            named[b] = o
    return out_bits, named


def _namer(taken: set[str]):
    """A source of fresh net names n1, n2, ... that skips the names in ``taken``."""
    counter = [0]

    def fresh() -> str:
        while True:
            counter[0] += 1
            net = f"n{counter[0]}"
            if net not in taken:
                return net
    return fresh


def compose_luts(doc: dict, inputs: list[str], outputs: list[str], library: Library,
                 map_opts: MapOptions, min_opts: MinimiseOptions, cache: dict) -> Netlist:
    """ABC's cut network (``$lut`` cells) -> a netlist in which each node is its function's
    minimised hazard-free cover, mapped by the two-level mapper (cached by truth table)."""
    mod = doc["modules"]["top"]
    net_of: dict = {}
    for name in inputs:
        for b in mod["ports"][name]["bits"]:
            net_of[b] = name
    driver = {c["connections"]["Y"][0]: c for c in mod["cells"].values()}
    for c in mod["cells"].values():
        if c["type"] != "$lut":
            raise MechcError(f"Yosys left a {c['type']} cell in its cut network")
    out_bits, named = _output_bits(mod, outputs, driver)
    cells: list[CellInst] = []
    counter = {"cell": 0}
    fresh = _namer(set(inputs) | set(outputs))

    def node(table: str, ins: list[str], net_name) -> str:
        k = len(ins)
        if table not in cache:
            cache[table] = _node_netlist(table, k, library, map_opts, min_opts)
        sub = cache[table]
        rename = {f"x{i}": ins[i] for i in range(k)}
        out_net = sub.outputs["y"]
        if out_net in rename:
            return rename[out_net]
        for c in sub.topo_cells():
            for net in c.outputs:
                rename[net] = (net_name() if net == out_net else fresh())
            counter["cell"] += 1
            cells.append(CellInst(f"c{counter['cell']}", c.cell, c.type,
                                  tuple(rename[n] for n in c.inputs),
                                  tuple(rename[n] for n in c.outputs), dict(c.params)))
        return rename[out_net]

    def build(bit) -> str:
        stack = [bit]
        while stack:
            b = stack[-1]
            if b in net_of:
                stack.pop()
                continue
            if b in ("0", "1"):
                net_of[b] = node("1" if b == "1" else "0", [], fresh)
                stack.pop()
                continue
            c = driver.get(b)
            if c is None:
                raise MechcError(f"Yosys left net bit {b} undriven")
            ins = c["connections"]["A"]
            todo = [i for i in ins if i not in net_of]
            if todo:
                stack.extend(todo)
                continue
            stack.pop()
            table = str(c["parameters"]["LUT"])
            width = len(ins)
            table = table.zfill(1 << width)[-(1 << width):]
            net_of[b] = node(table, [net_of[i] for i in ins],
                             (lambda b=b: named[b]) if b in named else fresh)
        return net_of[bit]

    outs = {o: build(b) for o, b in out_bits.items()}
    nl = Netlist(inputs)
    for c in cells:
        cls = library[c.cell]
        nl.add_cell(c, pin_names=cls.input_names(len(c.inputs)), out_pins=list(cls.outputs))
    for o, net in outs.items():
        nl.set_output(o, net)
    nl.check()
    return nl


def _node_netlist(table: str, k: int, library: Library, map_opts: MapOptions,
                  min_opts: MinimiseOptions) -> Netlist:
    """One cut node (Yosys' LUT parameter: bit j is the output for input value j, input 0
    the least significant) minimised and mapped over inputs x0..x(k-1)."""
    names = [f"x{i}" for i in range(k)]
    on = []
    for j in range(1 << k):
        if table[len(table) - 1 - j] == "1":
            value = sum(1 << (k - 1 - i) for i in range(k) if j >> i & 1)
            on.append(Cube((1 << k) - 1, value))
    spec = Spec("<node>", "pla", names, ["y"], {"y": OutputSpec("y", on=on)})
    eq = minimise(spec, min_opts)
    opts = replace(map_opts, target="conventional")
    return map_equations(eq, library, opts).netlist


def with_two_level(ml: Netlist, two: Netlist, outputs: list[str]) -> Netlist:
    """``ml`` with the named outputs built by their cones of the two-level netlist instead
    (its cells renamed apart); cells no output needs any more are dropped."""
    keep_outputs = {o: net for o, net in ml.outputs.items() if o not in outputs}
    live = _cone(ml, keep_outputs.values())
    two_live = _cone(two, [two.outputs[o] for o in outputs])
    taken = set(ml.inputs) | set(ml.driver) | set(ml.outputs)
    rename = {x: x for x in two.inputs}
    cells = [ml.cells[c] for c in ml.cells if c in live]
    k = len(ml.cells)
    for c in two.topo_cells():
        if c.id not in two_live:
            continue
        for net in c.outputs:
            name = net if net in outputs and net not in taken else f"t_{net}"
            while name in taken:
                name = "t_" + name
            taken.add(name)
            rename[net] = name
        k += 1
        cells.append(CellInst(f"c{k}", c.cell, c.type, tuple(rename[n] for n in c.inputs),
                              tuple(rename[n] for n in c.outputs), dict(c.params)))
    nl = Netlist(ml.inputs)
    for c in cells:
        nl.add_cell(c)
    for o in ml.outputs:
        nl.set_output(o, keep_outputs[o] if o in keep_outputs else rename[two.outputs[o]])
    nl.check()
    return nl


def _cone(nl: Netlist, nets) -> set[str]:
    """Cells some of ``nets`` depend on."""
    seen: set[str] = set()
    todo = [nl.driver[n][0] for n in nets]
    while todo:
        cid = todo.pop()
        if cid in seen or cid not in nl.cells:
            continue
        seen.add(cid)
        todo.extend(nl.driver[n][0] for n in nl.cells[cid].inputs)
    return seen


def netlist_from_json(doc: dict, inputs: list[str], outputs: list[str],
                      cells: dict[str, tuple], library: Library) -> Netlist:
    """Yosys' JSON of the mapped module -> a mechc netlist (cells numbered in topological
    order; an output driven by a cell gives its name to that net)."""
    mod = doc["modules"]["top"]
    net_of: dict = {}  # Yosys bit -> mechc net name
    for name in inputs:
        for b in mod["ports"][name]["bits"]:
            net_of[b] = name
    driver: dict = {}  # bit -> yosys cell name
    for cname, c in mod["cells"].items():
        if c["type"] not in cells and c["type"] != _BUFFER:
            raise MechcError(f"Yosys mapped to an unknown cell {c['type']}")
        driver[c["connections"]["Y"][0]] = cname
    out_bits, named = _output_bits(mod, outputs, driver)
    nl = Netlist(inputs)
    counter = {"cell": 0}
    fresh = _namer(set(inputs) | set(outputs))

    def add(cid: str, type_name: str, ins: tuple[str, ...], net: str, params: dict) -> None:
        cls = library.for_type(type_name, len(ins))
        nl.add_cell(CellInst(cid, cls.name, type_name, ins, (net,), params),
                    pin_names=cls.input_names(len(ins)), out_pins=list(cls.outputs))

    def const(value: int) -> str:
        key = f"const{value}"
        if key not in net_of:
            counter["cell"] += 1
            net = fresh()
            add(f"c{counter['cell']}", "CONST", (), net, {"value": value})
            net_of[key] = net
        return net_of[key]

    def build(bit) -> str:  # iterative depth-first: chains may be long
        stack = [bit]
        while stack:
            b = stack[-1]
            if b in net_of:
                stack.pop()
                continue
            if b in ("0", "1"):
                net_of[b] = const(int(b))
                stack.pop()
                continue
            if b not in driver:
                raise MechcError(f"Yosys left net bit {b} undriven")
            c = mod["cells"][driver[b]]
            pins = [p for p in "ABCD" if p in c["connections"]]
            ins = [c["connections"][p][0] for p in pins]
            todo = [i for i in ins if i not in net_of]
            if todo:
                stack.extend(todo)
                continue
            stack.pop()
            if c["type"] == _BUFFER:
                net_of[b] = net_of[ins[0]]
                continue
            t, _n, _cell = cells[c["type"]]
            counter["cell"] += 1
            net = named.get(b) or fresh()
            add(f"c{counter['cell']}", t, tuple(net_of[i] for i in ins), net, {})
            net_of[b] = net
        return net_of[bit]

    for o in outputs:
        nl.set_output(o, build(out_bits[o]))
    nl.check()
    return nl
