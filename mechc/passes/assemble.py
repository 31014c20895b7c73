"""Synthesis stage: netlist + layout -> a mechanism with every part dimensioned and placed.

``Netlist, Layout -> Mechanism``. Steps: a force budget from the outputs back to the inputs
(each cell's springs are sized for what its output must move, and it reports what it asks of
its inputs); every cell synthesised at a local origin and placed by column (logic depth) and
row (the layout's order, each cell moved up or down towards what it is joined to), columns
spaced by their real widths plus a channel of fan-out slots (bars one above the other share
one); primary inputs become sliders driven by bounded-force actuators; every net becomes a fan-out
bar on its driver's output slider with one horizontal rod to each load (the rods then work at a
90° transmission angle in every state).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from mechc.cells.builder import Builder, rect
from mechc.cells.library import Library
from mechc.cells.materials import DEFAULT_MATERIAL, material
from mechc.errors import DesignError, UsageError
from mechc.geometry.transform import bounds, translate
from mechc.ir.check import Check
from mechc.ir.layout import Layout
from mechc.ir.mechanism import (
    Body,
    Demand,
    Joint,
    Mechanism,
    Part,
    Point,
    SynthContext,
    Terminal,
)
from mechc.ir.netlist import Netlist
from mechc.parts.pushrod import ROLE, PushRod, bar_outline
from mechc.passes.bosses import add_bosses
from mechc.passes.route import Piece, assign_planes
from mechc.passes.strength import size_parts


@dataclass
class MechOptions:
    stroke: float = 20.0
    actuator_force: float = 100.0  # N, rated force of each input actuator
    output_load: float = 0.5  # N, what each circuit output must move, either way
    clearance: float = 1.0  # mm, least gap between parts on one plane (a design rule)
    material: str = DEFAULT_MATERIAL  # plate material (mechc/cells/materials.py)
    spring_margin: float = 1.3  # spring preload >= this x what it must move (SynthContext)
    overtravel: float = 0.02  # over-travel stops, fraction of stroke beyond the working range
    angle_margin: float = 0.0  # degrees of transmission angle beyond the limit (SynthContext)


def synth_context(opts: MechOptions) -> SynthContext:
    """The design rules every part of a mechanism is synthesised with."""
    mat = material(opts.material)
    return SynthContext(stroke=opts.stroke, density=mat.density, material=mat.name,
                        clearance=opts.clearance, margin=opts.spring_margin,
                        overtravel=opts.overtravel, angle_margin=opts.angle_margin)



def synthesise_cell(cls, cid: str, ctx: SynthContext, n: int, params: dict, d: Demand) -> Part:
    """``cls.synthesise``, with a cell that has no geometry (a user cell written without
    ``synthesise``) named as a usage error rather than an internal one."""
    try:
        return cls.synthesise(cid, ctx, n, params, d)
    except NotImplementedError:
        raise UsageError(f"cell '{cls.name}' ({cls.source}) has no mechanism: implement "
                         "synthesise() (see docs/write-a-cell.md)") from None


def assemble_mechanism(nl: Netlist, layout: Layout, lib: Library,
                         opts: MechOptions | None = None) -> Mechanism:
    opts = opts or MechOptions()
    ctx = synth_context(opts)
    S, w = ctx.stroke, ctx.bar
    order = [c.id for c in nl.topo_cells()]
    cells = {c.id: c for c in nl.cells.values()}
    loads: dict[str, list[tuple[str, str]]] = {}  # net -> [(cell id, pin)]
    for cid in order:
        c = cells[cid]
        pins = lib[c.cell].input_names(len(c.inputs))
        for net, pin in zip(c.inputs, pins):
            loads.setdefault(net, []).append((cid, pin))
    out_nets = set(nl.outputs.values())

    # ---- force budget and cell synthesis, outputs first -------------------------------------
    # a feedback net (a MEMORY's state) is loaded by cells synthesised after its driver: size
    # again with the loads found in the pass before until the demands stop growing
    feedback = any(getattr(lib[c.cell], "stateful", False) for c in cells.values())
    before: dict[str, Demand] = {}
    for _ in range(4 if feedback else 1):
        demand, local = _size_cells(order, cells, lib, ctx, opts, out_nets, loads, before)
        grown = any(demand[n].right > before.get(n, Demand()).right + 1e-9
                    or demand[n].left > before.get(n, Demand()).left + 1e-9 for n in demand)
        before = demand
        if not grown:
            break
    converged = not feedback or not grown

    # ---- placement: columns by depth, real sizes -------------------------------------------
    depth = nl.depth()
    ncol = max(depth.values(), default=0) + 1
    cols: list[list[str]] = [[] for _ in range(ncol)]
    for cid in sorted(order, key=lambda c: (depth[c], layout.cells[c].row if c in layout.cells
                                             else 0)):
        cols[depth[cid]].append(cid)
    sizes = {cid: bounds(p) for cid, p in local.items()}
    # nets whose fan-out bar sits in the gap after column k
    driver_col: dict[str, int] = {name: 0 for name in nl.inputs}
    for cid in order:
        for net in cells[cid].outputs:
            driver_col[net] = depth[cid]
    gap_nets: dict[int, list[str]] = {}
    for net in sorted(driver_col, key=lambda n: (driver_col[n], n)):
        if net in loads:
            gap_nets.setdefault(driver_col[net], []).append(net)
    channel = S + 2 * w  # neighbouring fan-out bars may move a full stroke apart
    in_len = 1.5 * S
    row_gap = 1.5 * w

    # ---- primary inputs: sliders in column 0, rows in the layout's order --------------------
    inputs: dict[str, Part] = {}
    in_order = sorted(nl.inputs, key=lambda n: layout.inputs[n].row if n in layout.inputs else 0)
    pitch_in = max(ctx.pitch, 2 * w)
    for i, name in enumerate(in_order):
        b = Builder(f"in:{name}", ctx)
        y = -i * pitch_in * 2
        sig = b.slider("slider", 0.0, in_len, y, f"input {name}")
        b.terminal(name, sig.body, (in_len, y))
        inputs[name] = b.part

    # ---- rows: heights first (they do not depend on x), each cell near what it connects to --
    def part_of(node: str) -> Part:
        """A cell at its local origin, or an input as placed."""
        return inputs[node[3:]] if node.startswith("in:") else local[node]

    def pin_y(node: str, pin: str) -> float:
        return _mid(part_of(node).terminals[pin])[1]

    def driver_pin(net: str) -> tuple[str, str]:
        return (f"in:{net}", net) if net in nl.inputs else nl.driver[net]

    links: list[tuple[str, str, str, str, float]] = []  # driver, its pin, load, its pin, weight
    for net, ls in loads.items():
        links += [(*driver_pin(net), c, p, 1.0 / len(ls)) for c, p in ls]
    shift_y = _rows(cols[1:], sizes, row_gap, links, pin_y)

    # ---- columns: real widths plus a channel of fan-out slots after each --------------------
    sweep = S / 2 + ctx.overtravel * S  # how far a net's parts move from the design pose

    def bar_span(net: str) -> tuple[float, float]:
        """The heights a net's fan-out bar covers (from the driver's terminal to every
        load's), grown by how far the driver moves up or down."""
        ys = [pin_y(node, pin) + shift_y.get(node, 0.0)
              for node, pin in [driver_pin(net), *loads[net]]]
        node, pin = driver_pin(net)
        part = part_of(node)
        dy = abs((part.body(part.terminals[pin].body).axis or (1.0, 0.0))[1]) * sweep
        return min(ys) - w / 2 - dy, max(ys) + w / 2 + dy

    slots, n_slots = _channel_slots(gap_nets, {n: bar_span(n) for ns in gap_nets.values()
                                               for n in ns},
                                    {n: sum(1 if depth[c] > k else -1 for c, _ in loads[n])
                                     for k, ns in gap_nets.items() for n in ns},
                                    opts.clearance)
    col_x = [0.0] * ncol
    col_w = [0.0] * ncol
    col_w[0] = in_len + S / 2
    for k in range(1, ncol):
        col_w[k] = max(sizes[c][2] - sizes[c][0] for c in cols[k])
    for k in range(1, ncol):
        col_x[k] = col_x[k - 1] + col_w[k - 1] + (n_slots.get(k - 1, 0) + 1) * channel + S
    placed: dict[str, Part] = {}
    for k in range(1, ncol):
        for cid in cols[k]:
            placed[cid] = translate(local[cid], col_x[k] - sizes[cid][0], shift_y[cid])

    # ---- nets: fan-out bar on the driver, horizontal rods to the loads ----------------------
    def driver_of(net: str) -> tuple[str, Terminal]:
        node, pin = driver_pin(net)
        return node, (inputs[net] if node.startswith("in:") else placed[node]).terminals[pin]

    nets = _route_nets(gap_nets, slots, col_x, col_w, channel, loads, driver_of, inputs, placed,
                       demand, ctx, opts)

    # ---- outputs and actuators --------------------------------------------------------------
    outputs: dict[str, tuple[str, str]] = {}
    for name, net in nl.outputs.items():
        if net in nl.inputs:
            outputs[name] = (f"in:{net}", net)
        else:
            node, pin = nl.driver[net]
            outputs[name] = (node, pin)
    actuators = {}
    checks: list[Check] = []
    if not converged:  # each pass around a MEMORY loop asks more force: it needs amplifiers
        checks.append(Check("force budget converged", "feedback loops", 0.0, 1.0, ">="))
    for name in nl.inputs:
        d = demand.get(name, Demand())
        need = max(d.right, d.left) + ctx.friction
        actuators[name] = {"rated_force_N": opts.actuator_force,
                           "required_right_N": round(d.right + ctx.friction, 4),
                           "required_left_N": round(d.left + ctx.friction, 4)}
        checks.append(Check("actuator force", f"input {name}", opts.actuator_force / need,
                            1.0, ">=", "x"))
    mech = Mechanism(ctx, placed, inputs, nets, outputs, actuators, order, checks)
    size_parts(mech)  # pins and rod guides from the loads just budgeted
    add_bosses(mech)  # material round every pin, now that the pins are sized
    return mech


def _size_cells(order, cells, lib, ctx, opts, out_nets, loads, before):
    """One pass of the force budget: cells from the outputs back, each sized for what its
    output must deliver (``before``: a previous pass's demands, a floor for feedback nets)."""
    demand: dict[str, Demand] = {}
    for net in out_nets:
        demand[net] = Demand(opts.output_load, opts.output_load)
    local: dict[str, Part] = {}
    for cid in reversed(order):
        c = cells[cid]
        cls = lib[c.cell]
        d = demand.get(c.outputs[0], Demand())
        prev = before.get(c.outputs[0])
        if prev is not None:
            d = Demand(max(d.right, prev.right), max(d.left, prev.left))
        part = synthesise_cell(cls, cid, ctx, len(c.inputs), c.params, d)
        part.data["output_demand"] = d.to_json()
        local[cid] = part
        for net, pin in zip(c.inputs, cls.input_names(len(c.inputs))):
            ld = part.data["input_loads"][pin]
            add = Demand(ld["right_N"] + ctx.friction, ld["left_N"] + ctx.friction)
            demand[net] = demand.get(net, Demand()) + add
    return demand, local


def _route_nets(gap_nets: dict[int, list[str]], slots: dict[str, int], col_x: list[float],
                col_w: list[float], channel: float, loads: dict[str, list[tuple[str, str]]],
                driver_of,
                inputs: dict[str, Part], placed: dict[str, Part], demand: dict[str, Demand],
                ctx: SynthContext, opts: MechOptions) -> dict[str, Part]:
    """Every net as parts: a fan-out bar (an arm and a vertical bar drawn onto the driver's
    output body, each on its own plane: two plates fastened where they meet) in the channel
    after the driver's column, and per load a ``pushrod`` body of
    plate pinned to that bar and to the load's input slider, straight and horizontal. Planes
    from :func:`mechc.passes.route.assign_planes`; each bar in its slot of the channel
    (:func:`_channel_slots`)."""
    S, w = ctx.stroke, ctx.bar
    cell_planes = [pl for p in [*inputs.values(), *placed.values()] for b in p.bodies
                   for pl in (b.poly_layers or [b.layer])]
    base = max(cell_planes, default=0) + 1  # nets above every cell: rods pass over cells
    sweep = S / 2 + ctx.overtravel * S
    pieces: list[Piece] = []
    plans = []
    for k, names in sorted(gap_nets.items()):
        x_gap = col_x[k] + col_w[k] + channel
        for net in sorted(names, key=lambda n: (slots[n], n)):
            owner, term = driver_of(net)
            dpart = inputs[owner[3:]] if owner.startswith("in:") else placed[owner]
            body = dpart.body(term.body)
            ax = body.axis or (1.0, 0.0)
            move = (abs(ax[0]) * sweep, abs(ax[1]) * sweep)
            tx, ty = _mid(term)
            x_bar = x_gap + slots[net] * channel
            rods = []
            for j, (cid, pin) in enumerate(loads[net]):
                lt = placed[cid].terminals[pin]
                lx, ly = _mid(lt)
                # a load left of its driver is a feedback path (a MEMORY's state): the rod runs
                # back over the cells between, on a plane no cell uses
                if abs(lx - x_bar) < 0.5 * S:
                    raise DesignError(f"net {net}: load {cid}.{pin} too close to its fan-out bar")
                rid = f"net.{net}.rod{j + 1}"
                rods.append((rid, lt, (x_bar, ly), (lx, ly)))
                pieces.append(Piece(rid, net, (_box(bar_outline((x_bar, ly), (lx, ly), w)),),
                                    move, True))
            ys = [ty] + [r[2][1] for r in rods]
            arm = rect(tx, ty - w / 2, x_bar + w / 2, ty + w / 2)
            bar = rect(x_bar - w / 2, min(ys) - w / 2, x_bar + w / 2, max(ys) + w / 2)
            pieces.append(Piece(f"net.{net}", net, (_box(bar),), move, False))
            pieces.append(Piece(f"net.{net}.arm", net, (_box(arm),), move, False, arm=True))
            plans.append((net, owner, term, body, x_bar, arm, bar, rods))
    plane = assign_planes(pieces, opts.clearance, base)
    nets: dict[str, Part] = {}
    for net, owner, term, body, x_bar, arm, bar, rods in plans:
        layers = body.poly_layers or [body.layer] * len(body.outline)
        body.outline += [arm, bar]
        body.poly_layers = layers + [plane[f"net.{net}.arm"], plane[f"net.{net}"]]
        body.mass = ctx.mass(body.outline)
        part = Part()
        info = []
        for rid, lt, pa, pb in rods:
            poly = bar_outline(pa, pb, w)
            mid = ((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2)
            part.bodies.append(Body(rid, PushRod.name, [poly], ctx.mass([poly]), pivot=mid,
                                    layer=plane[rid], role=ROLE))
            part.joints.append(Joint(f"{rid}.driver", "pin", term.body, rid, pa=pa))
            part.joints.append(Joint(f"{rid}.load", "pin", rid, lt.body, pa=pb))
            info.append({"body": rid, "plane": plane[rid],
                         "length_mm": round(abs(pb[0] - pa[0]), 4), "width_mm": w,
                         "thickness_mm": ctx.thickness, "bends": 0,
                         "ends": "square, bar width / 2 beyond each pin centre"})
        d = demand.get(net, Demand())
        part.data = {"driver": owner, "fanout_bar_x": round(x_bar, 3),
                     "fanout_plane": plane[f"net.{net}"], "demand": d.to_json(),
                     "loads": [f"{c}.{p}" for c, p in loads[net]], "rods": info}
        if plane[f"net.{net}.arm"] != plane[f"net.{net}"]:  # the arm on a plane of its own
            part.data["arm_plane"] = plane[f"net.{net}.arm"]
        nets[net] = part
    return nets


def _rows(cols: list[list[str]], sizes: dict[str, tuple[float, float, float, float]],
          gap: float, links: list[tuple[str, str, str, str, float]],
          pin_y: Callable[[str, str], float], sweeps: int = 6) -> dict[str, float]:
    """How far each cell is shifted up or down: stacked in its column's order, a ``gap``
    apart, each as near as that order allows to the terminals it is joined to.

    A net's fan-out bar runs from its driver's terminal to its loads', and every bar a
    height crosses takes a slot of the channel (:func:`_channel_slots`), so the bars' lengths
    set the channels' widths and the rods' lengths. Stacking every column from the top
    left a short column's cells far from their drivers in a long one. Each sweep (to the
    right, then back) moves every cell of a column towards the mean of what its links ask
    (a link of a net with n loads weighs 1/n: a net that spans many rows gains little from
    one of them), and the column's order and gaps are kept by isotonic regression (pool
    adjacent violators), the least-squares placement under them. Inputs stay where they
    are."""
    drop: dict[str, float] = {}  # how far below its column's top a cell's top is, stacked
    for col in cols:
        y = 0.0
        for cid in col:
            drop[cid] = y
            y += (sizes[cid][3] - sizes[cid][1]) + gap
    shift = {cid: -drop[cid] - sizes[cid][3] for cid in drop}  # the stacked start
    want: dict[str, list[tuple[float, float, str, str]]] = {}  # cell -> (weight, pin, other)
    for a, pa, b, pb, wgt in links:
        want.setdefault(b, []).append((wgt, pb, a, pa))
        if not a.startswith("in:"):
            want.setdefault(a, []).append((wgt, pa, b, pb))

    def at(node: str, pin: str) -> float:
        return pin_y(node, pin) + shift.get(node, 0.0)

    order = list(range(len(cols)))
    for s in range(sweeps):
        for k in (order if s % 2 == 0 else order[::-1]):
            col = cols[k]
            if not col:
                continue
            tops, weights = [], []
            for cid in col:
                ws = want.get(cid, [])
                tw = sum(w for w, *_ in ws)
                top = (sum(w * (at(o, op) - pin_y(cid, p)) for w, p, o, op in ws) / tw
                       if tw else shift[cid]) + sizes[cid][3]
                tops.append(top + drop[cid])  # in the column's frame: non-increasing
                weights.append(tw or 1e-9)
            for cid, t in zip(col, _decreasing(tops, weights)):
                shift[cid] = t - drop[cid] - sizes[cid][3]
    return shift


def _decreasing(values: list[float], weights: list[float]) -> list[float]:
    """The non-increasing sequence nearest ``values`` in weighted least squares (pool
    adjacent violators)."""
    blocks: list[list[float]] = []  # [mean, weight, count]
    for v, w in zip(values, weights):
        blocks.append([v, w, 1])
        while len(blocks) > 1 and blocks[-2][0] < blocks[-1][0]:
            m2, w2, n2 = blocks.pop()
            m1, w1, n1 = blocks.pop()
            blocks.append([(m1 * w1 + m2 * w2) / (w1 + w2), w1 + w2, n1 + n2])
    return [m for m, _, n in blocks for _ in range(int(n))]


def _channel_slots(gap_nets: dict[int, list[str]], spans: dict[str, tuple[float, float]],
                   rightward: dict[str, int], clearance: float
                   ) -> tuple[dict[str, int], dict[int, int]]:
    """Each net's fan-out slot in its channel, and how many slots each channel needs.

    Two bars may share a slot when their heights (``spans``, already grown by their drivers'
    travel up or down) stay the clearance apart: both then move only along the slot and
    never meet. Packing them is interval colouring, and the left-edge rule of channel
    routing (each bar, lowest first, into the first slot its predecessor has left) needs
    no more slots than the most bars crossing one height, which is the least any packing
    can. One slot per net made the channel after a 38-cell column 1.2 m wide, and every rod
    crossing it as long (random81's heaviest nets were such rods, 2.4 m). The slots whose
    nets' rods mostly run right go furthest right (feedback nets, whose rods run left, the
    furthest left), which shortens the rods."""
    slots: dict[str, int] = {}
    count: dict[int, int] = {}
    for k, names in gap_nets.items():
        tracks: list[list[str]] = []
        tops: list[float] = []
        for net in sorted(names, key=lambda n: (spans[n][0], n)):
            lo, hi = spans[net]
            t = next((t for t, top in enumerate(tops) if lo - top >= clearance + 1e-6),
                     len(tracks))
            if t == len(tracks):
                tracks.append([])
                tops.append(hi)
            tracks[t].append(net)
            tops[t] = hi
        order = sorted(range(len(tracks)),
                       key=lambda t: (sum(rightward[n] for n in tracks[t]) / len(tracks[t]),
                                      min(tracks[t])))
        for i, t in enumerate(order):
            for net in tracks[t]:
                slots[net] = i
        count[k] = len(tracks)
    return slots, count


def _box(poly: list[Point]) -> tuple[float, float, float, float]:
    return (min(p[0] for p in poly), min(p[1] for p in poly), max(p[0] for p in poly),
            max(p[1] for p in poly))


def _mid(t: Terminal) -> Point:
    return t.design_point
