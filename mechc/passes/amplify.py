"""Netlist pass: put AMPLIFIER cells where the circuit needs power or a snap.

Two reasons, both from ``001_…`` §2.6 and Appendix B:

- **force** — a net whose driver cannot move its loads (an input actuator that is asked for more
  than its rating, a MEMORY loop whose force demand grows every time round) gets its loads
  split into groups of at most ``Amplifier.fanout_max`` loads, each group behind its own
  AMPLIFIER; the amplifier's input costs only its slider's friction, its output comes from the
  motor. In a sequential netlist every load of the net moves behind an amplifier, so all its
  paths keep the same delay (a delay on one path only is the SET/RESET overlap of Appendix
  B.2). A combinational netlist gets its force amplifiers planned in one sweep of the force
  budget from the outputs back (``plan_force_amplifiers``): a net is amplified only where its
  driver (a cell under its strength checks, an actuator under its rating) cannot move it, and
  then only its heaviest loads, grouped within the amplifier's own capacity.
- **snap** — an output that must hold while an input travels but whose generator moves partway
  because a MEMORY switches before that input has finished its stroke (the output is X in the
  ternary analysis with the memories free to switch). The AMPLIFIER's bistable toggle switches
  only when its input passes its switching point (half stroke in the closed form, the wedge in
  the dynamics), so the partial motion never reaches the output.

Both are plain functions ``Netlist -> Netlist``; the pipeline decides where.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import networkx as nx

from mechc.cells.library import Library
from mechc.errors import DesignError
from mechc.ir.mechanism import Demand, SynthContext
from mechc.ir.netlist import CellInst, Netlist
from mechc.passes.assemble import MechOptions, synth_context, synthesise_cell
from mechc.passes.strength import cell_holds, force_ceiling, strength_checks

#: Used when the library's AMPLIFIER does not state how many loads it may drive.
DEFAULT_FANOUT = 2


def amplifier_cell(lib: Library):
    cls = lib.for_type("AMPLIFIER", 1)
    if cls is None:
        raise DesignError("the cell library has no AMPLIFIER cell: the design needs one")
    return cls


def fanout_limit(lib: Library) -> int:
    """How many loads the mapper puts on one AMPLIFIER (a cell class attribute)."""
    cls = amplifier_cell(lib)
    return int(getattr(cls, "fanout_max", DEFAULT_FANOUT))


def _rebuild(nl: Netlist, lib: Library, cells: list[CellInst], outputs: dict[str, str]) -> Netlist:
    out = Netlist(nl.inputs)
    for c in cells:
        cls = lib[c.cell]
        out.add_cell(c, pin_names=cls.input_names(len(c.inputs)), out_pins=list(cls.outputs))
    for name, net in outputs.items():
        out.set_output(name, net)
    out.check()
    return out


def _fresh(stem: str, taken: set[str]) -> str:
    k = 1
    while f"{stem}{k}" in taken:
        k += 1
    name = f"{stem}{k}"
    taken.add(name)
    return name


def snap_outputs(nl: Netlist, lib: Library, outputs: Iterable[str]) -> Netlist:
    """Each named primary output is driven through its own AMPLIFIER (other loads of the net
    stay where they are)."""
    amp = amplifier_cell(lib)
    names = _names(nl)
    cells = list(nl.cells.values())
    outs = dict(nl.outputs)
    for o in outputs:
        net = outs[o]
        new = _fresh(f"{o}_amp", names)
        cells.append(CellInst(_fresh("a", names), amp.name, "AMPLIFIER", (net,), (new,),
                              {"reason": "snap"}))
        outs[o] = new
    return _rebuild(nl, lib, cells, outs)


def amplify_nets(nl: Netlist, lib: Library, nets: Iterable[str], reason: str = "force",
                 groups: dict[str, list[list[tuple[str, int]]]] | None = None) -> Netlist:
    """Every load of each named net moves behind AMPLIFIERs, at most the measured fan-out per
    amplifier (or in the ``groups`` given for it: lists of (cell, input index)); primary
    outputs on the net stay on it (their load is small). ``reason`` is recorded in each new
    cell's params (force, or a feedback delay)."""
    amp = amplifier_cell(lib)
    limit = fanout_limit(lib)
    names = _names(nl)
    cells = {c.id: c for c in nl.cells.values()}
    loads: dict[str, list[tuple[str, int]]] = {}
    for c in nl.cells.values():
        if c.type == "AMPLIFIER":  # an amplifier's input costs little: it stays on the net
            continue
        for k, net in enumerate(c.inputs):
            loads.setdefault(net, []).append((c.id, k))
    reach = _memories_reached(nl)
    extra: list[CellInst] = []
    for net in nets:
        for group in (groups or {}).get(net) or _groups(loads.get(net, []), reach, limit):
            new = _fresh(f"{net}_amp", names)
            extra.append(CellInst(_fresh("a", names), amp.name, "AMPLIFIER", (net,), (new,),
                                  {"reason": reason}))
            for cid, k in group:
                c = cells[cid]
                ins = list(c.inputs)
                ins[k] = new
                cells[cid] = CellInst(c.id, c.cell, c.type, tuple(ins), c.outputs, c.params)
    return _rebuild(nl, lib, list(cells.values()) + extra, dict(nl.outputs))


def _groups(ls: list[tuple[str, int]], reach: dict[str, tuple[str, ...]], limit: int,
            ask: dict[tuple[str, int], Demand] | None = None,
            cap: float = math.inf) -> list[list[tuple[str, int]]]:
    """A net's loads (cell, pin) in the groups that share one amplifier: at most ``limit``
    each and, given what each asks, at most ``cap`` newtons each way; loads that feed the
    same MEMORY together where they can (two amplifiers never switch at quite the same
    moment, and a skew between a memory's SET and RESET paths is the overlap of Appendix
    B.2)."""
    ls = sorted(ls, key=lambda load: (reach.get(load[0], ()), load))
    out: list[list[tuple[str, int]]] = []
    total = Demand()
    for load in ls:
        a = ask[load] if ask is not None else Demand()
        more = total + a
        if not out or len(out[-1]) >= limit or max(more.right, more.left) > cap:
            out.append([])
            more = a
        out[-1].append(load)
        total = more
    return out


def amplifier_capacity(lib: Library, ctx: SynthContext) -> float:
    """The largest demand (N, each way) an AMPLIFIER's output can move with every part of
    it within its strength checks (bisection: the checks only get worse with the load)."""
    amp = amplifier_cell(lib)
    lo, hi = 0.0, force_ceiling(ctx)
    for _ in range(40):
        mid = (lo + hi) / 2
        try:
            ok = _asks(amp, None, ctx, Demand(mid, mid), check=True) is not None
        except DesignError:
            ok = False
        lo, hi = (mid, hi) if ok else (lo, mid)
    return lo


def plan_force_amplifiers(nl: Netlist, lib: Library, opts: MechOptions
                          ) -> tuple[dict[str, str], dict[str, list[list[tuple[str, int]]]]]:
    """Nets to amplify so that every cell can drive what it must, chosen in one sweep of the
    force budget from the outputs back (combinational netlists).

    A cell's demand is what its output net's loads ask; each level multiplies it (a spring
    preloaded 1.3x what it moves, rising 30 % over the stroke, is what the next cell back must
    overcome), so in a deep chain it grows until some part yields. Sweeping back, each cell is
    synthesised for its net's demand; where the cell alone fails a strength check under that
    load (``strength.cell_holds``), or an input actuator would need more than its rating, that
    net goes behind amplifiers (their inputs ask only slider friction), which resets the
    demand seen further back. An amplifier is put in only where a cell cannot do without one,
    as far back as it can be, so one amplifier relieves as many levels as the parts allow.
    An amplifier moves at most :func:`amplifier_capacity`, so a cell that would ask more than
    that of one input is relieved too, and a net's loads are grouped by force as well as by
    count. Only the heaviest loads of a net go behind amplifiers, as many as its driver needs;
    in a combinational network a delay on some paths and not others changes no settled value
    and no ternary (hazard) result, and the kinematic proof checks the design as built.
    Returns net -> reason and net -> its groups of loads (for :func:`amplify_nets`)."""
    ctx = synth_context(opts)
    limit = fanout_limit(lib)
    cap = amplifier_capacity(lib, ctx)
    amp = amplifier_cell(lib)
    reach = _memories_reached(nl)
    loads: dict[str, list[tuple[str, int]]] = {}
    for c in nl.cells.values():
        if c.type != "AMPLIFIER":
            for k, net in enumerate(c.inputs):
                loads.setdefault(net, []).append((c.id, k))
    ask: dict[tuple[str, int], Demand] = {}  # (cell, pin) -> what it asks, friction included
    base: dict[str, Demand] = {}  # net -> demand of what stays on it if amplified
    for net in nl.outputs.values():
        base[net] = Demand(opts.output_load, opts.output_load)
    for c in nl.cells.values():
        if c.type == "AMPLIFIER":
            a = _asks(amp, c, ctx, Demand())
            base[c.inputs[0]] = base.get(c.inputs[0], Demand()) + a[0]
    out: dict[str, str] = {}

    def demand_of(net: str) -> Demand:
        d = base.get(net, Demand())
        for load in loads.get(net, []):
            d = d + ask[load]
        return d

    groups: dict[str, list[list[tuple[str, int]]]] = {}

    def amplified(net: str, fits) -> Demand:
        """Put the heaviest loads of ``net`` behind amplifiers, as few as leave a demand its
        driver ``fits`` (all of them if none does); the lightest stay on the net."""
        ls = sorted(loads.get(net, []), key=lambda load: (max(ask[load].right,
                                                                ask[load].left), load))

        def split(k: int) -> tuple[Demand, list[list[tuple[str, int]]]]:
            d = base.get(net, Demand())
            for load in ls[:k]:
                d = d + ask[load]
            gs = _groups(ls[k:], reach, limit, ask, cap)
            for group in gs:
                own = Demand()
                for load in group:
                    own = own + ask[load]
                d = d + _asks(amp, None, ctx, own)[0]
            return d, gs

        lo, hi = 0, len(ls) - 1  # the most loads kept direct: bisection (fewer weigh less)
        while lo < hi:
            mid = (lo + hi + 1) // 2
            lo, hi = (mid, hi) if fits(split(mid)[0]) else (lo, mid - 1)
        d, groups[net] = split(lo)
        return d

    state = nl.state_nets()
    for cell in reversed(nl.topo_cells()):
        net = cell.outputs[0]
        cls = lib[cell.cell]

        def fits(d: Demand, cell=cell, cls=cls) -> bool:
            asks = _asks(cls, cell, ctx, d, check=True)
            return asks is not None and max((max(a.right, a.left) for a in asks),
                                            default=0.0) <= cap

        d = demand_of(net)
        if not fits(d) and loads.get(net) and net not in state:
            out[net] = f"force: {cell.id} ({cell.type}) cannot drive its loads' demand"
            d = amplified(net, fits)
        for k, a in enumerate(_asks(cls, cell, ctx, d)):
            ask[(cell.id, k)] = a

    def actuator_fits(d: Demand) -> bool:
        return max(d.right, d.left) + ctx.friction <= opts.actuator_force

    for net in nl.inputs:
        if not actuator_fits(demand_of(net)) and loads.get(net):
            out[net] = "force: its actuator would be asked more than its rating"
            amplified(net, actuator_fits)
    return out, groups


def _asks(cls, cell: CellInst | None, ctx, demand: Demand,
          check: bool = False) -> list[Demand] | None:
    """What each input of ``cell`` (an instance of ``cls``) asks of its net, guide friction
    included, when it must deliver ``demand``; ``check``: None if the cell alone then fails
    a strength check."""
    n = len(cell.inputs) if cell is not None else 1
    part = synthesise_cell(cls, cell.id if cell else "amp", ctx, n,
                           dict(cell.params) if cell else {}, demand)
    pins = cls.input_names(n)
    asks = [Demand(part.data["input_loads"][p]["right_N"] + ctx.friction,
                   part.data["input_loads"][p]["left_N"] + ctx.friction) for p in pins]
    if check:
        load = max([demand.right, demand.left] + [max(a.right, a.left) for a in asks])
        if not cell_holds(cell.id if cell else "amp", part, load, ctx):
            return None
    return asks


def nets_short_of_force(nl: Netlist, mech, lib: Library) -> dict[str, str]:
    """Nets to amplify, from the force checks of a synthesised mechanism: every input whose
    actuator is asked for more than its rating, and, when a MEMORY loop's demand did not
    converge, every MEMORY output (the amplifier cuts the loop and delays the feedback, which
    is the ordering fundamental mode wants). Nets whose loads are all amplifiers already are
    left out (amplifying again cannot help)."""
    direct = {net for c in nl.cells.values() if c.type != "AMPLIFIER" for net in c.inputs}
    failed = [c for c in mech.synthesis_checks() if not c.passed]
    out: dict[str, str] = {}
    if any(c.name == "force budget converged" for c in failed):
        # the loops first: until they converge every demand is inflated, the actuators' too
        for cell in nl.cells.values():
            q = cell.outputs[0]
            if cell.type == "MEMORY" and q in direct:
                out[q] = "force: a MEMORY loop asks more force every time round"
        return out
    for c in failed:
        if c.name == "actuator force" and c.where.startswith("input "):
            net = c.where[len("input "):]
            if net in direct:
                out[net] = f"force: the actuator of {net} would need {1 / c.value:.3g}x its rating"
    return out


def nets_overstressed(nl: Netlist, mech) -> dict[str, str]:
    """Nets to amplify where a part is too weak for what it must move, which is how a deep
    (multi-level) chain fails: each cell asks its driver for more force than it delivers, so
    the demand grows back along the chain. A cell that fails a strength check has its output
    net's loads put behind amplifiers (it then moves only their light inputs); an AMPLIFIER
    that fails has the output nets of the cells it drives amplified, which lowers what those
    cells ask of it."""
    failed = [c for c in strength_checks(mech) if not c.passed]
    loads: dict[str, list[CellInst]] = {}
    for c in nl.cells.values():
        for net in c.inputs:
            loads.setdefault(net, []).append(c)

    def amplifiable(net: str) -> bool:  # loads that are not amplifiers already
        return any(c.type != "AMPLIFIER" for c in loads.get(net, ()))

    out: dict[str, str] = {}
    for chk in failed:
        owner = nl.cells.get(chk.where.split(".")[0])
        if owner is None:
            continue
        why = f"force: {chk.name} of {owner.id} ({owner.type}) over its limit"
        if owner.type != "AMPLIFIER":
            targets = list(owner.outputs)
        else:
            targets = [n for c in loads.get(owner.outputs[0], ()) if c.type != "AMPLIFIER"
                       for n in c.outputs]
        for net in targets:
            if amplifiable(net) and net not in out and net not in nl.state_nets():
                out[net] = why
    return out


def _memories_reached(nl: Netlist) -> dict[str, tuple[str, ...]]:
    """Cell -> the MEMORY cells its output reaches through combinational logic (sorted)."""
    g = nl.combinational_graph()
    out = {}
    for cid in nl.cells:
        down = nx.descendants(g, cid)
        out[cid] = tuple(sorted(d for d in down if d in nl.cells
                                and nl.cells[d].type == "MEMORY"))
    return out


def _names(nl: Netlist) -> set[str]:
    taken = set(nl.inputs) | set(nl.cells) | set(nl.outputs) | set(nl.driver)
    for c in nl.cells.values():
        taken.update(c.inputs)
        taken.update(c.outputs)
    return taken
