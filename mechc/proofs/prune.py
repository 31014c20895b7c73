"""Scene pruning: per input change, only the part of the mechanism that can move the outputs.

The rule that a simulation models no more than its question needs. For one input change the closed
form says which bodies move along the way (41 samples of the moving input, as ``Scene.move`` samples
it). The dynamic scene then holds:

- **cells** — the fan-in cone of the observed outputs, restricted to cells with an input that
  moves, the walk not passing an AMPLIFIER's inputs (an amplifier's powered output isolates
  what it drives from what drives it; :func:`cone`, on the netlist alone);
- **the load** — every kept cell is kept *whole* (its still bodies static, below), so a moving
  net still pushes every spring, guide and contact of every cell it reaches (an AND whose
  other input holds its bar still loads the moving input through its hook), whether or not
  that cell's output moves;
- **boundary** — bodies outside the cone that the scene's rods hang on are placed at their
  closed-form pose (``Scene``'s kinematic boundary bodies); when their pose does not change
  over the case they are static, not driven step by step.
- **still bodies** (``FREEZE``) — bodies of kept cells (and idle primary inputs) that the
  closed form keeps still over the change are made static at their closed-form pose; the
  constraints between two static bodies go. Every constraint on a moving body stays, so a
  moving net still meets every hook, stop and spring it meets in the whole scene, as a rigid
  one. By default (``"inner"``) the kept cells' output terminals stay free, so a dwelling output
  that the moving parts push still shows (as a glitch, or as a watched cut that does not
  hold); ``"all"`` freezes those too (faster, blind to such pushes); ``"none"`` keeps every
  kept body free (the cell-level cone alone).

What pruning assumes, and how the run checks it: a kept cell whose output the closed form
keeps still (it *dwells*) but that drives cells outside the scene must really stay still —
otherwise a dynamic glitch would travel on into cells that were cut away. Those outputs are
watched during the move (:data:`WATCH_PREFIX` pseudo-outputs); if one leaves ``watch_limit``
(fraction of stroke) the case is run again on the whole mechanism (counted as ``escalated``).
Un-moving upstream cells and still bodies are held exactly at their closed-form positions: whether
their springs really hold against the kept cells' loads is the static force-budget check's job
(spring margin, a design check), which runs in every proof. A static body is stiffer than a sprung
one: the largest joint stretch of a frozen scene came out larger than the whole scene's on every
benchmark circuit (docs/performance.md), so the stretch limit is not eased.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
import pymunk

from mechc.cells.library import Library
from mechc.ir.mechanism import Mechanism
from mechc.ir.netlist import Netlist
from mechc.physics.closed_form import Poses
from mechc.physics.evaluate import evaluate, output_signals
from mechc.physics.scene import MOVE_SAMPLES, DynSettings, MoveResult, Scene

CUT_TYPES = frozenset({"AMPLIFIER"})
STATEFUL_TYPES = frozenset({"MEMORY"})  # at rest their output depends on history
WATCH_PREFIX = "__watch:"
SAMPLES = MOVE_SAMPLES  # points along the moving input, as Scene.move samples its reference
WATCH_LIMIT = 0.005  # fraction of stroke a watched (dwelling) cut output may move
FREEZE_MODES = ("none", "inner", "all")
FREEZE = "inner"  # bodies the closed form keeps still are static (see build_scene)
MOVE_EPS = 1e-6  # mm (sliders) or mm at the body's reach (levers): "does not move"


def cone(nl: Netlist, observed: Iterable[str], moving_nets: set[str],
         cut_types: frozenset[str] = CUT_TYPES) -> set[str]:
    """Cells that can influence the observed output nets while ``moving_nets`` move: the
    fan-in cone of the observed nets, the walk stopping at a cell of a ``cut_types`` type
    (which is itself kept), restricted to cells with at least one moving input."""
    seen: set[str] = set()
    stack = [nl.driver[n][0] for n in observed if nl.driver.get(n, ("",))[0] in nl.cells]
    while stack:
        c = stack.pop()
        if c in seen:
            continue
        seen.add(c)
        cell = nl.cells[c]
        if cell.type in cut_types:
            continue
        for net in cell.inputs:
            d = nl.driver[net][0]
            if d in nl.cells and d not in seen:
                stack.append(d)
    return {c for c in seen if any(n in moving_nets for n in nl.cells[c].inputs)}


def blocker(nl: Netlist, lib: Library) -> str | None:
    """Why this design cannot be run change by change from closed-form rest poses, if so: a
    cell whose output at rest depends on the past (MEMORY, or a library cell that says
    ``stateful = True``) needs the state the previous changes left."""
    for c in nl.cells.values():
        cls = lib[c.cell]
        if c.type in STATEFUL_TYPES or getattr(cls, "stateful", False):
            return f"cell {c.id} ({c.type}) holds state: the whole scene runs the tour"
    return None


@dataclass
class CasePlan:
    """The scene for one input change."""

    name: str  # the moving input
    cells: list[str]  # kept cells, topological order
    moving_bodies: set[str]  # bodies the closed form moves during the change
    moving_nets: set[str]
    watch: dict[str, tuple[str, str]] = field(default_factory=dict)  # pseudo-output -> pin
    end_outputs: dict[str, float] = field(default_factory=dict)  # closed form after the change
    static: set[str] = field(default_factory=set)  # scene bodies made static
    poses: Poses | None = None  # closed form along the change (SAMPLES), handed to the scene


def _body_moves(poses: Poses, mech: Mechanism) -> set[str]:
    index = mech.body_index()
    out = set()
    for bid, u in poses.u.items():
        if np.ptp(np.nan_to_num(u)) > MOVE_EPS:
            out.add(bid)
    for bid, (dx, dy) in poses.xy.items():  # links translate as well as turn
        if max(np.ptp(np.nan_to_num(dx)), np.ptp(np.nan_to_num(dy))) > MOVE_EPS:
            out.add(bid)
    for bid, th in poses.theta.items():
        b = index.get(bid)
        reach = 1.0
        if b is not None and b.pivot is not None and b.outline:
            reach = max(1.0, max(np.hypot(p[0] - b.pivot[0], p[1] - b.pivot[1])
                                 for poly in b.outline for p in poly))
        if np.ptp(np.nan_to_num(th)) * reach > MOVE_EPS:
            out.add(bid)
    return out


def plan_case(nl: Netlist, mech: Mechanism, lib: Library, types: dict[str, str],
              state: dict[str, float], name: str, target: float,
              observed: Iterable[str] | None = None) -> CasePlan:
    """Which cells the scene of this input change needs (see the module docstring)."""
    s = np.linspace(0.0, 1.0, SAMPLES)
    vals = {k: np.full(SAMPLES, float(v)) for k, v in state.items()}
    vals[name] = state[name] + (target - state[name]) * s
    poses = evaluate(mech, lib, types, vals)
    moving = _body_moves(poses, mech)
    moving.add(mech.inputs[name].terminals[name].body)
    moving_nets = {net for net, (node, pin) in nl.driver.items()
                   if _terminal_body(mech, node, pin) in moving}
    obs = [nl.outputs[o] for o in (observed if observed is not None else nl.outputs)]
    kept = cone(nl, obs, moving_nets)
    order = [c for c in mech.order if c in kept]
    # kept cells whose output dwells but drives cells outside the scene: watched
    watch = {}
    for c in order:
        for net in nl.cells[c].outputs:
            pin = nl.driver[net][1]
            loads_out = any(c2 not in kept and net in nl.cells[c2].inputs for c2 in nl.cells)
            if loads_out and net not in moving_nets:
                watch[f"{WATCH_PREFIX}{c}.{pin}"] = (c, pin)
    end = {o: float(v[-1]) for o, v in output_signals(mech, poses).items()}
    return CasePlan(name, order, moving, moving_nets, watch, end, poses=poses)


def _terminal_body(mech: Mechanism, node: str, pin: str) -> str | None:
    part = mech.inputs.get(node[3:]) if node.startswith("in:") else mech.cells.get(node)
    if part is None or pin not in part.terminals:
        return None
    return part.terminals[pin].body


def build_scene(plan: CasePlan, nl: Netlist, mech: Mechanism, lib: Library,
                types: dict[str, str], settings: DynSettings, state: dict[str, float],
                freeze: str | None = None) -> Scene:
    """The pruned scene of ``plan``, at rest in the input state ``state``. ``freeze`` (default
    :data:`FREEZE`): which bodies the closed form keeps still are made static — ``"none"``,
    ``"inner"`` (all but the kept cells' output terminals, which stay free so a pushed output
    still shows as a glitch or a cut that does not hold) or ``"all"``."""
    view = dataclasses.replace(mech, outputs={**mech.outputs, **plan.watch})
    sc = Scene.build(view, lib, types, settings, dict(state), plan.cells, poses=plan.poses)
    static: set[str] = set()
    # boundary bodies the closed form keeps still: static, not driven every step
    for bid in list(sc.boundary):
        if bid not in plan.moving_bodies:
            sc.boundary.discard(bid)
            static.add(bid)
    mode = FREEZE if freeze is None else freeze
    if mode not in FREEZE_MODES:
        raise ValueError(f"freeze must be one of {FREEZE_MODES}, not {mode!r}")
    held: set[str] = set()
    if mode != "none":
        held = set(sc.bodies) - plan.moving_bodies
        if mode == "inner":
            for c in plan.cells:
                for net in nl.cells[c].outputs:
                    held.discard(mech.cells[c].terminals[nl.driver[net][1]].body)
    for bid in held:
        b = sc.bodies[bid]
        if b.body_type != pymunk.Body.DYNAMIC:
            continue
        b.body_type = pymunk.Body.KINEMATIC
        b.velocity = (0.0, 0.0)
        b.angular_velocity = 0.0
        static.add(bid)
    frozen = {sc.bodies[b] for b in static}
    for con in list(sc.space.constraints):  # constraints with nothing left to move
        if (con.a.body_type != pymunk.Body.DYNAMIC and con.b.body_type != pymunk.Body.DYNAMIC
                and (con.a in frozen or con.b in frozen)):
            sc.space.remove(con)
    plan.static = static
    return sc


@dataclass
class CaseRun:
    """One input change run on its pruned scene (or on the whole one, if escalated)."""

    result: MoveResult
    plan: CasePlan
    cells: int  # cells in the scene that ran
    bodies: int  # dynamic bodies
    constraints: int
    escalated: bool
    watch_deviation: float  # fraction of stroke, largest over the watched outputs


def scene_size(sc: Scene) -> tuple[int, int]:
    """(dynamic bodies, constraints): what the solver works on every step."""
    dyn = sum(1 for b in sc.bodies.values() if b.body_type == pymunk.Body.DYNAMIC)
    return dyn, len(sc.space.constraints)


def run_case(nl: Netlist, mech: Mechanism, lib: Library, types: dict[str, str],
             settings: DynSettings, state: dict[str, float], name: str, target: float,
             watch_limit: float = WATCH_LIMIT, freeze: str | None = None) -> CaseRun:
    """Move input ``name`` from ``state`` to ``target`` on the pruned scene; outputs outside
    it are reported at their closed-form position (they do not move in this change)."""
    plan = plan_case(nl, mech, lib, types, state, name, target)
    sc = build_scene(plan, nl, mech, lib, types, settings, state, freeze)
    r = sc.move(name, target, reference=plan.poses)
    dev = 0.0
    for key in plan.watch:
        if key in r.outputs and key in r.reference:
            d = np.abs(r.outputs[key] - r.reference[key])
            dev = max(dev, float(np.max(np.where(np.isfinite(d), d, np.inf))))
    escalated = not dev <= watch_limit
    if escalated:  # the cut did not hold: run the change on the whole mechanism
        sc = Scene.build(mech, lib, types, settings, dict(state), poses=plan.poses)
        r = sc.move(name, target, reference=plan.poses)
    for d in (r.outputs, r.reference, r.final):
        for key in [k for k in d if k.startswith(WATCH_PREFIX)]:
            del d[key]
    for o, v in plan.end_outputs.items():
        if o not in r.final:
            r.final[o] = v
            r.reference[o] = np.array([v])
    dyn, cons = scene_size(sc)
    return CaseRun(r, plan, len(sc.cells), dyn, cons, escalated, dev)
