"""Timing level: every input change's switching and settle times from the closed form and
the cells' characterised tables (:mod:`mechc.cells.characterise`), without a pymunk scene.

A linkage is quasi-static to first order: where an output stands at each instant of an input's
move is what the closed form says for the input's position then. So per change (the dynamic
proof's own plan) the whole mechanism's closed form is evaluated along the move, and each
sample's time is where the minimum-jerk profile puts that input position. On top, each cell
on the switching path adds what its table says the dynamics add at its input speed and the
mass its output net drives, for the way its output switches: the lag of its mid-stroke
crossing, and (the last cell) how much later it settles; an AMPLIFIER, timed as the design
built it, passes its late landing on, as the waveform it lands with: the cells after it are
timed on that, not on their closed form (a step there; :class:`Landing`). A gate whose
output body only its own spring moves one way (a bar held back by its inputs) and whose net's
loads are free is timed as built too, by a one-dimensional model of that body
(:class:`Follower`): its spring, the guides' friction and the mass it moves, as the parts
give them.
Path delays are the longest sum through the cells whose output switches (static timing
analysis over the netlist's DAG).

Per change and switching output: ``switch_s`` (the output crosses mid-stroke) and
``settle_s`` (it stays within 0.5 % of stroke of its end), both from the start of the input's
move; the slack of a change is the time the dynamic proof allows (the move and the hold)
less the latest settle. A change fails when an output, or any switching net inside (the
dynamic proof's settle asks every body still), is predicted to settle after that time. The
critical path is the change, output and cells of the latest settle. A sequential design's
ordering requirements (S·R overlap, essential hazards; found at compile,
``mechc.passes.ordering``) become timing inequalities with the cells' characterised delays in
place of their stated ones, each with its slack.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import networkx as nx
import numpy as np

from mechc.cells.characterise import (
    DIRECTED,
    SETTLED,
    SHAPE_T,
    CellTable,
    Move,
    Tables,
    crossing,
    directed,
    measuring,
    per_instance,
    settled_at,
)
from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.mechanism import GROUND
from mechc.ir.netlist import Netlist
from mechc.ir.paths import essential_hazard_times, set_reset_skew
from mechc.ir.seqspec import SeqSpec
from mechc.ir.spec import Spec
from mechc.parts.pushrod import net_loads, net_rods
from mechc.physics.evaluate import evaluate, output_signals, signal_of
from mechc.physics.scene import DynSettings, min_jerk
from mechc.proofs.dynamic import plan_changes
from mechc.proofs.hold import MEMORY_THROW_S
from mechc.proofs.kinematic import prove_kinematic
from mechc.proofs.prune import blocker
from mechc.proofs.registry import OnProgress, engine
from mechc.proofs.report import ProofReport
from mechc.proofs.settings import ProofSettings, dyn_settings

#: Closed-form samples along each input move.
SAMPLES = 81
#: Changes evaluated in one closed-form call (bounds memory on big designs).
CHUNK = 64
#: Per-change records kept in the report.
MAX_CHANGES_LISTED = 200
#: An ordering inequality must hold by this (s), as at compile (``mechc.passes.ordering``).
MARGIN_S = 0.02


def sample_times(move_time: float, k: int = SAMPLES) -> np.ndarray:
    """The time (s) at which a minimum-jerk move passes each of ``k`` evenly spaced
    positions (the inverse of :func:`mechc.physics.scene.min_jerk`, by interpolation)."""
    tau = np.linspace(0.0, 1.0, 4001)
    return move_time * np.interp(np.linspace(0.0, 1.0, k), min_jerk(tau), tau)


def cell_tables(design: Design, lib: Library, progress: OnProgress | None,
                names: list[str] | None = None,
                changes: list[tuple[int, int]] | None = None
                ) -> tuple[dict[str, CellTable | None], Tables]:
    """Each cell's table: shipped, cached, or measured now (``progress`` told the grid
    points of a cell being measured). A cell with a delay of its own (``per_instance``) is
    timed as the design built it, on the first of ``changes`` that switches it on and the
    first that switches it off (without ``changes``: its alone table)."""
    stroke = design.mechanism.ctx.stroke
    nl = design.netlist
    per = None

    def moves_of(cid: str) -> list[Move]:
        nonlocal per
        if per is None:
            per = _switches(nl, names or [], changes or [], stepped)
        n = len(names or [])
        out = []
        for cur, vec, jumps in per.get(cid, []):
            k = n - (cur ^ vec).bit_length()
            out.append(Move({nm: float((cur >> (n - 1 - q)) & 1) for q, nm in enumerate(names)},
                            names[k], float((vec >> (n - 1 - k)) & 1), ramp=jumps))
        return out

    tabs = Tables(lib, measuring(progress))
    stepped = frozenset(c.id for c in nl.cells.values()  # a step in the closed form
                        if per_instance(lib[c.cell]) and not lib[c.cell].stateful)
    out: dict[str, CellTable | None] = {}
    for c in nl.topo_cells():
        if changes and c.id in stepped:
            out[c.id] = tabs.instance(design, c.id, lambda cid=c.id: moves_of(cid))
        else:
            out[c.id] = tabs.get(c.cell, c.type, len(c.inputs), dict(c.params), stroke)
    return out, tabs


def _switches(nl: Netlist, names: list[str], changes: list[tuple[int, int]],
              stepped: frozenset[str] = frozenset()) -> dict[str, list[tuple[int, int, bool]]]:
    """Per cell: the first change of ``changes`` that switches its output on and the first
    that switches it off, each with whether a cell of ``stepped`` (timed as built: a step in
    the closed form) switches in the cell's fan-in on it (then its inputs jump in the closed
    form, and it is timed on a ramp instead: :attr:`mechc.cells.characterise.Move.ramp`)."""
    n = len(names)
    if not changes or nl.state_nets():
        return {}
    logic = nl.evaluate({nm: np.array([[(v >> (n - 1 - k)) & 1 for v in pair]
                                       for pair in changes], dtype=bool).ravel()
                         for k, nm in enumerate(names)})
    flips = {net: np.asarray(v).reshape(-1, 2) for net, v in logic.items()}
    g = nl.combinational_graph() if stepped else None
    out: dict[str, list[tuple[int, int, bool]]] = {}
    for c in nl.cells.values():
        v = flips.get(c.outputs[0])
        if v is None:
            continue
        ups = [flips[nl.cells[u].outputs[0]] for u in
               (nx.ancestors(g, c.id) & stepped if g is not None and c.id in g else ())
               if nl.cells[u].outputs[0] in flips]
        for want in (True, False):
            hit = np.flatnonzero((v[:, 0] != v[:, 1]) & (v[:, 1] == want))
            if len(hit):
                i = int(hit[0])
                out.setdefault(c.id, []).append(
                    (*changes[i], any(bool(u[i, 0] != u[i, 1]) for u in ups)))
    return out


@engine("timing", "combinational")
def timing_engine(design: Design, spec: Spec, lib: Library, settings: ProofSettings,
                  progress: OnProgress | None) -> ProofReport:
    return prove_timing(design, spec, lib, settings, progress)


def prove_timing(design: Design, spec: Spec, lib: Library,
                 settings: ProofSettings | None = None,
                 progress: OnProgress | None = None) -> ProofReport:
    """The timing proof of a combinational design (see the module docstring)."""
    t0 = time.perf_counter()
    settings = settings or ProofSettings()
    kin = prove_kinematic(design, spec, lib, tolerance=settings.tolerance, seed=settings.seed)
    st = dyn_settings(design, lib, dt=settings.dt, iterations=settings.iterations,
                      move_time=settings.move_time, hold=settings.hold,
                      progress=progress)
    names = list(spec.inputs)
    # the dynamic proof's changes (beyond 10 inputs: those switching every cell first)
    changes, _chosen = plan_changes(design, names, settings.cases, settings.seed,
                                    independent=blocker(design.netlist, lib) is None)
    tables, tabs = cell_tables(design, lib, progress, names, changes)
    timed = predict_changes(design, lib, names, changes, st, tables, detail=True)
    budget = st.move_time + st.settle_time
    failures: list[dict] = []
    for f in kin.failures:
        failures.append({**f, "kind": f"kinematic {f.get('kind', '')}".strip()})
    crit = None
    late = 0
    for ch in timed:
        ch["slack_s"] = round(budget - ch["settle_s"], 5)
        # an internal net still moving after the budget keeps the scene from settling even
        # when every output is in time (the dynamic proof's settle asks every body still)
        nets = ch.pop("nets_settle_s", ch["settle_s"])
        for key in ("switched", "nets_lag_s", "closed_form_end", "closed_form_swing"):
            ch.pop(key, None)
        if ch["slack_s"] < 0 or nets > budget:
            late += 1
            what = ("" if ch["slack_s"] < 0 else
                    f"an internal net is predicted to settle {nets:.4f} s after the move "
                    "starts, its outputs ")
            if len(failures) < 50:
                failures.append({"kind": "settle", "inputs": ch["inputs"],
                                 "moving": ch["moving"], "to": ch["to"],
                                 "message": f"{what}predicted to settle {ch['settle_s']:.4f} s "
                                 f"after the move starts (allowed {budget:.3f} s)"})
        if crit is None or ch["settle_s"] > crit["settle_s"]:
            crit = ch
    kinds = {}
    if kin.failure_count:
        kinds["kinematic"] = kin.failure_count
    if late:
        kinds["settle"] = late
    fails = kin.failure_count + late
    crit_json = None
    if crit is not None and crit["outputs"]:
        o = max(crit["outputs"], key=lambda k: crit["outputs"][k]["settle_s"])
        crit_json = {"inputs": crit["inputs"], "moving": crit["moving"], "to": crit["to"],
                     "output": o, **crit["outputs"][o]}
    slacks = [c["slack_s"] for c in timed]
    measured = sorted(set(tabs.measured))
    return ProofReport(
        level="timing", kind="combinational", passed=fails == 0, cases=len(timed),
        coverage={"random_changes": settings.cases, "seed": settings.seed,
                  "tolerance_fraction": settings.tolerance},
        failure_count=fails, failure_kinds=kinds or None, failures=failures,
        figures={
            "max_settle_time_s": round(max(0.0, (crit or {"settle_s": 0.0})["settle_s"]
                                           - st.move_time), 5),
            "max_deviation_fraction": kin.figures.get("max_deviation_fraction"),
            "min_transmission_angle_deg": kin.figures.get("min_transmission_angle_deg"),
            "min_slack_s": round(min(slacks), 5) if slacks else None,
            "critical_path": crit_json,
            "budget_s": round(budget, 5),
            "move_time_s": st.move_time,
            "settings": st.to_json(),
            "cell_tables": {"cells": len(tables), **tabs.found,
                            "untimed": sorted(k for k, v in tables.items() if v is None),
                            "measured_now": measured},
            "changes": timed[:MAX_CHANGES_LISTED],
        },
        seconds=round(time.perf_counter() - t0, 4))


def predict_changes(design: Design, lib: Library, names: list[str],
                    changes: list[tuple[int, int]], st: DynSettings,
                    tables: dict[str, CellTable | None], detail: bool = False) -> list[dict]:
    """Per change (from input vector, to input vector; one input differs): its switching
    outputs' predicted ``switch_s``, ``settle_s`` and the path of cells that sets them. With
    ``detail`` (what the screened proof reads, :mod:`mechc.proofs.screen`) also: ``switched``,
    the cells whose output switches and in which direction; ``nets_lag_s``, each switching
    net's predicted mid-stroke crossing after its closed form's; ``nets_settle_s``, the latest
    predicted settle of any switching net, internal ones included, each from where its own
    closed form settles, as an output's (taking the move's end instead put an amplifier's
    input, switching mid-move, 20-40 % late on the 2-bit adder); ``closed_form_end`` and
    ``closed_form_swing``, every output's closed-form position at the move's end and its
    largest distance from its start along the move."""
    mech, nl = design.mechanism, design.netlist
    types = {c.id: c.cell for c in nl.cells.values()}
    n = len(names)
    ts = sample_times(st.move_time)
    driver = {c.outputs[0]: c for c in nl.cells.values()}
    loads = net_loads(design.mechanism)
    figs = {cid: ({**tab.at(st.move_time, loads.get(nl.cells[cid].outputs[0], 0.0)),
                   "as_built": tab.as_built} if tab is not None else None)
            for cid, tab in tables.items()}
    follow = followers(design, lib)
    landing = Landing(tables, {c.id: loads.get(c.outputs[0], 0.0) for c in nl.cells.values()},
                      follow, st.move_time)
    out_cells = [c.id for c in nl.cells.values() if c.id in mech.cells
                 and lib[types[c.id]].outputs[0] in mech.cells[c.id].terminals] if detail else []
    hold = st.move_time + st.settle_time
    out: list[dict] = []
    frac = np.linspace(0.0, 1.0, SAMPLES)
    for lo in range(0, len(changes), CHUNK):
        chunk = changes[lo:lo + CHUNK]
        vals = {}
        for k, nm in enumerate(names):
            cols = []
            for cur, vec in chunk:
                a = (cur >> (n - 1 - k)) & 1
                b = (vec >> (n - 1 - k)) & 1
                cols.append(a + (b - a) * frac)
            vals[nm] = np.concatenate(cols)
        poses = evaluate(mech, lib, types, vals)
        sig = output_signals(mech, poses)
        bodies = mech.body_index() if (follow or detail) else {}
        # every cell output's closed form (a follower's model reads it; with ``detail`` each
        # switching internal net settles from its own closed form's settle, not the move's end)
        fsig = {}
        for cid in (out_cells if detail else follow):
            term = mech.cells[cid].terminals[lib[types[cid]].outputs[0]]
            fsig[cid] = signal_of(term, bodies[term.body], poses)
        logic = nl.evaluate({nm: np.array([[(v >> (n - 1 - k)) & 1 for v in pair]
                                           for pair in chunk], dtype=bool).ravel()
                             for k, nm in enumerate(names)})
        for i, (cur, vec) in enumerate(chunk):
            k = n - (cur ^ vec).bit_length()
            moving = names[k]
            switched = {net for net, v in logic.items() if v[2 * i] != v[2 * i + 1]}
            # each switching cell's figures for the way its output goes (on or off)
            here = dict(figs)
            for c in nl.cells.values():
                f = figs.get(c.id)
                if f is None or c.outputs[0] not in switched:
                    continue
                on = bool(logic[c.outputs[0]][2 * i + 1])
                here[c.id] = {**f, **{k: f.get(directed(k, on), f[k]) for k in DIRECTED},
                              "on": on}
                fo = follow.get(c.id)
                got = (_follow(fo, ts, fsig[c.id][i * SAMPLES:(i + 1) * SAMPLES], hold)
                       if fo is not None else None)
                if got is not None:
                    here[c.id]["follower"] = got
            arrive, settle, path = _paths(nl, "in:" + moving, switched, here, landing)
            rec = {"inputs": _vec(vec, names), "moving": moving,
                   "to": int((vec >> (n - 1 - k)) & 1), "outputs": {}, "settle_s": 0.0}
            if detail:
                rec["switched"] = {c.id: bool(logic[c.outputs[0]][2 * i + 1])
                                   for c in nl.cells.values() if c.outputs[0] in switched}
                rec["nets_lag_s"] = {net: v for net, v in arrive.items() if net in switched}
                rec["nets_settle_s"] = max(
                    (_net_settle(fsig.get(driver[net].id) if net in driver else None, i, ts,
                                 st.move_time) + v
                     for net, v in settle.items() if net in switched), default=st.move_time)
                rec["closed_form_end"] = {}
                rec["closed_form_swing"] = {}
                for o in nl.outputs:
                    if o in sig:
                        s = sig[o][i * SAMPLES:(i + 1) * SAMPLES]
                        rec["closed_form_end"][o] = float(s[-1])
                        rec["closed_form_swing"][o] = float(np.max(np.abs(s - s[0])))
            for o, net in nl.outputs.items():
                if net not in switched or o not in sig:
                    continue
                s = sig[o][i * SAMPLES:(i + 1) * SAMPLES]
                cf_cross = crossing(ts, s)
                cf_settle = settled_at(ts, s, end=float(s[-1]), within=SETTLED)
                if not math.isfinite(cf_cross):
                    cf_cross = ts[-1]
                cid = driver[net].id if net in driver else None
                lag = arrive.get(net, 0.0)
                extra = settle.get(net, 0.0)
                rec["outputs"][o] = {"switch_s": round(cf_cross + lag, 6),
                                     "settle_s": round(cf_settle + extra, 6),
                                     "closed_form_switch_s": round(cf_cross, 6),
                                     "closed_form_settle_s": round(cf_settle, 6),
                                     "path": path.get(net, [cid] if cid else [])}
                rec["settle_s"] = max(rec["settle_s"], rec["outputs"][o]["settle_s"])
            if detail:
                rec["nets_settle_s"] = max(rec["nets_settle_s"], rec["settle_s"])
            out.append(rec)
    return out


def _net_settle(sig: np.ndarray | None, i: int, ts: np.ndarray, move_time: float) -> float:
    """When the ``i``-th change's closed form of a net settles (its last entry into the band
    round its end), at the latest the move's end (no closed form of the net: the move's end)."""
    if sig is None:
        return move_time
    s = sig[i * SAMPLES:(i + 1) * SAMPLES]
    if not np.isfinite(s).all() or abs(float(s[-1]) - float(s[0])) < 0.5:
        return move_time  # the closed form does not show the switch: the move's end
    t = settled_at(ts, s, end=float(s[-1]), within=SETTLED)
    return min(t, move_time) if math.isfinite(t) else move_time


def _follow(fo: Follower, ts: np.ndarray, cf: np.ndarray, until: float
            ) -> tuple[float, float] | None:
    """How much later than its closed form ``cf`` (at times ``ts``) a follower's output
    crosses mid-stroke and settles when its spring moves it, by :meth:`Follower.run`; None
    when the closed form does not cross or the output is pushed against its spring."""
    cf_cross = crossing(ts, cf)
    pull = fo.force(0.5)[0]
    if not math.isfinite(cf_cross) or pull * (cf[-1] - cf[0]) <= 0.0:
        return None  # pushed against its spring: the inputs move it, the table times it
    # a spring that can give the body every acceleration its bound asks keeps it on the bound
    # all the way (no lag, nothing to simulate): the common case of a light output
    speed = np.gradient(cf, ts)
    need = float(np.max(np.abs(np.gradient(speed, ts)))) * fo.stroke / 1000.0  # m/s^2
    top = float(np.max(np.abs(speed))) * fo.stroke
    can = min(abs(f) - damp * top for f, damp in map(fo.force, (0.0, 0.5, 1.0))) - fo.friction
    if can > 0.0 and can / fo.mass >= 1.25 * need:
        return 0.0, 0.0
    t, x = fo.run(ts, cf, until)
    cross = crossing(t, x)
    if not math.isfinite(cross):
        cross = until
    cf_settle = settled_at(ts, cf, end=float(cf[-1]), within=SETTLED)
    return cross - cf_cross, settled_at(t, x, end=float(cf[-1]), within=SETTLED) - cf_settle


def _paths(nl: Netlist, source: str, switched: set[str], figs: dict[str, dict | None],
           landing: Landing | None = None
           ) -> tuple[dict[str, float], dict[str, float], dict[str, list[str]]]:
    """Per switched net: the longest sum of the switching cells' lags from ``source`` (the
    arrival of its mid-stroke crossing beyond the closed form's), the settle delay (the
    upstream lags plus the driving cell's own settle extra, or the late landing of a cell timed
    as built upstream passed on; passing every gate's alone-table settle on predicted 26 % and
    82 % late on the random circuits, see docs/performance.md) and the cells on the longest
    path. A cell's figures carry its direction's lag and settle extra, ``on`` (the way it
    switches) and ``follower``, its :class:`Follower` model's (used when no late landing
    reaches its inputs). Behind a late landing, with ``landing``, each net also carries the
    waveform it lands with (:class:`Landing`): a follower is then run on it, a cell timed as
    built is read at the input speed it gives, and both settle when their own landing does."""
    arrive: dict[str, float] = {source[3:]: 0.0}
    settle: dict[str, float] = {}
    carried: dict[str, float] = {}
    wave: dict[str, np.ndarray] = {}
    path: dict[str, list[str]] = {source[3:]: []}
    for c in nl.topo_cells():
        net = c.outputs[0]
        if net not in switched:
            continue
        came = [(arrive[x], x) for x in c.inputs if x in arrive]
        if not came:
            continue
        a, via = max(came)
        f = figs.get(c.id) or {"lag_s": 0.0, "settle_extra_s": 0.0}
        # a cell timed as built (an amplifier) lands late: what follows it settles late too
        late = max((carried[x] for x in c.inputs if x in carried), default=0.0)
        if "follower" in f and not late:
            # a follower's own model, when its inputs move as the closed form says (behind
            # an amplifier they do not: its closed form is a step, its landing is carried)
            lag, extra = f["follower"]
            f = {**f, "lag_s": max(f["lag_s"], lag),
                 "settle_extra_s": max(f["settle_extra_s"], extra)}
        got = None
        if landing is not None:
            w_in = max(((arrive[x], x) for x in c.inputs if x in wave), default=None)
            got = landing.through(c.id, f, wave[w_in[1]] if w_in else None)
        if got is not None:
            lag, w_out = got
            arrive[net] = a + lag
            # never before what the tables alone say (the landing only adds what they miss)
            settle[net] = max(arrive[net] + landing.settles(w_out), late + lag,
                              a + f["settle_extra_s"])
            wave[net] = w_out
        else:
            arrive[net] = a + f["lag_s"]
            settle[net] = max(a + f["settle_extra_s"], late + f["lag_s"])
        if f.get("as_built") or late > 0.0:
            carried[net] = settle[net]
        path[net] = [*path[via], c.id]
    return arrive, settle, path


#: Share of a minimum-jerk move spent between 10 % and 90 % of its way.
_MJ_10_90 = float(np.subtract(*sample_times(1.0, 11)[[9, 1]]))


@dataclass
class Landing:
    """What carries a late landing on, cell by cell (:func:`_paths`): the waveform a net
    lands with, as its share of the way at each of ``SHAPE_T`` from its crossing. It starts
    at a cell timed as built (its table's ``shapes``), passes unchanged through a gate its
    input pushes, and through a :class:`Follower` as the follower's own run against it (a
    bar its spring moves lags a landing as it lags a closed form: adder4's carry AND gates
    19 ms behind their amplifier, 0.2 ms by their alone table). A cell timed as built behind
    a landing is read at the move time whose minimum-jerk move rises from 10 % to 90 % as
    fast as the landing does (its table was measured on inputs moved so: ``Move.ramp``)."""

    tables: dict[str, CellTable | None]
    loads: dict[str, float]  # cell -> the mass its output net drives (kg)
    follow: dict[str, Follower]
    move_time: float

    def through(self, cid: str, f: dict, w_in: np.ndarray | None
                ) -> tuple[float, np.ndarray] | None:
        """The cell's lag and the waveform it lands with, or None when no landing reaches
        or starts at it (the closed form drives it)."""
        tab = self.tables.get(cid)
        on = bool(f.get("on", True))
        if tab is not None and tab.as_built and tab.shapes:
            mt = self.move_time if w_in is None else self.move_time_of(w_in)
            v = tab.at(mt, self.loads.get(cid, 0.0))
            shape = tab.shape(on, mt, self.loads.get(cid, 0.0))
            if shape is not None and np.isfinite(shape).all():
                return v.get(directed("lag_s", on), v["lag_s"]), shape
            return None
        if w_in is None:
            return None
        fo = self.follow.get(cid)
        start, end = (0.0, 1.0) if on else (1.0, 0.0)
        if fo is None or fo.force(0.5)[0] * (end - start) <= 0.0:
            return f["lag_s"], w_in  # pushed by its input: the landing passes on
        t = np.asarray(SHAPE_T) - SHAPE_T[0]
        bound = start + (end - start) * np.clip(w_in, 0.0, 1.0)
        tt, x = fo.run(t, bound, float(t[-1]) + 0.1)
        cross = crossing(tt, x)
        if not math.isfinite(cross):
            return None
        lag = cross - crossing(t, bound)
        w_out = np.interp(cross + np.asarray(SHAPE_T), tt, (x - start) / (end - start))
        return max(f["lag_s"], lag), w_out

    @staticmethod
    def move_time_of(w: np.ndarray) -> float:
        """The minimum-jerk move time whose 10-90 % rise takes as long as ``w``'s."""
        t = np.asarray(SHAPE_T)
        return max(1e-3, (crossing(t, w, 0.9) - crossing(t, w, 0.1)) / _MJ_10_90)

    @staticmethod
    def settles(w: np.ndarray) -> float:
        """From its crossing, when ``w`` stays within ``SETTLED`` of its end (at the latest
        the last of ``SHAPE_T``)."""
        return settled_at(np.asarray(SHAPE_T), w, end=1.0, within=SETTLED)


def _vec(row: int, names: list[str]) -> dict[str, int]:
    n = len(names)
    return {nm: int((row >> (n - 1 - k)) & 1) for k, nm in enumerate(names)}


# ---- sequential: the ordering requirements as timing inequalities ---------------------------
@engine("timing", "sequential")
def seq_timing_engine(design: Design, spec: SeqSpec, lib: Library, settings: ProofSettings,
                      progress: OnProgress | None) -> ProofReport:
    """Every ordering requirement recorded at compile, its inequality evaluated with the
    cells' characterised delays (the larger of a cell's stated ``switching_delay_s`` and its
    table's lag at its load). A requirement whose inequality fails is a failure unless
    compile's dynamic walk of its transitions met it (the inequality is conservative; the
    report says which decided)."""
    t0 = time.perf_counter()
    tables, _tabs = cell_tables(design, lib, progress)
    st = dyn_settings(design, lib, dt=settings.dt, iterations=settings.iterations,
                      move_time=settings.move_time, hold=settings.hold,
                      progress=progress)
    nl = design.netlist
    loads = net_loads(design.mechanism)
    delay = {}
    for c in nl.cells.values():
        tab = tables.get(c.id)
        stated = float(getattr(lib[c.cell], "switching_delay_s", 0.0))
        lag = (tab.at(st.move_time, loads.get(c.outputs[0], 0.0))["lag_s"] if tab is not None
               else 0.0)
        delay[c.id] = max(stated, lag)
    reqs = ((design.stats.get("sequential") or {}).get("ordering") or {}).get("requirements",
                                                                            [])
    found = []
    failures = []
    for r in reqs:
        ineq = inequality(nl, delay, r, st.move_time)
        # the inequality is conservative (a gate passes a half-made move on): one that fails
        # is still met when compile's dynamic walk of its transitions met it
        walked = bool(r.get("met")) and not ineq["met"]
        found.append({"kind": r["kind"], "input": r["input"], "memories": r["memories"],
                      "requires": r["requires"], **ineq, "met_by_dynamic_walk": walked})
        if not ineq["met"] and not walked and len(failures) < 50:
            failures.append({"kind": "ordering", "message": f"{r['kind']}: {ineq['text']}"})
    slacks = [f["slack_s"] for f in found]
    return ProofReport(
        level="timing", kind="sequential", passed=not failures, cases=len(found),
        coverage={"requirements": len(found)}, failure_count=len(failures),
        failure_kinds={"ordering": len(failures)} if failures else None, failures=failures,
        figures={"min_slack_s": round(min(slacks), 5) if slacks else None,
                 "requirements": found, "move_time_s": st.move_time,
                 "cell_delays_s": {k: round(v, 6) for k, v in sorted(delay.items())}},
        seconds=round(time.perf_counter() - t0, 4))


def inequality(nl: Netlist, delay: dict[str, float], req: dict, move_time: float) -> dict:
    """One requirement as an inequality with its slack, at ``delay`` (compile's own, at the
    stated delays: :func:`mechc.passes.ordering.timing_inequality`; both sides from
    :mod:`mechc.ir.paths`): for an essential hazard, the moving input must reach every
    SET/RESET generator (longest path) before a switching memory's new state does and comes
    back (shortest path, the memory's throw); for SET and RESET moving together, the skew
    between the input's paths to the two pins must stay within the margin."""
    if req["kind"] == "set-reset-together":
        skew = set_reset_skew(nl, delay, req["input"], req["memories"])
        slack = MARGIN_S - skew
        return {"skew_s": round(skew, 5), "slack_s": round(slack, 5), "met": slack >= 0,
                "text": f"skew {skew:.4f} s <= margin {MARGIN_S:.3f} s (slack {slack:+.4f} s)"}
    t_in, t_mem = essential_hazard_times(nl, delay, req["input"], req["memories"], move_time,
                                         MEMORY_THROW_S)
    slack = t_mem - t_in - MARGIN_S
    return {"t_input_s": round(t_in, 5), "t_memory_feedback_s": round(t_mem, 5),
            "slack_s": round(slack, 5), "met": slack >= 0,
            "text": f"t_memory {t_mem:.4f} s - t_input {t_in:.4f} s >= margin {MARGIN_S:.3f} s "
                    f"(slack {slack:+.4f} s)"}


# ---- a spring-driven output: how fast its own spring can move what its net carries --------
#: Time step (s) of the one-dimensional follower model.
FOLLOW_DT = 5e-4


@dataclass
class Follower:
    """A cell output body that a spring of its own moves one way, held back by one-sided
    contacts with the cell's inputs (a bar gate's bar): going that way it can lead nowhere
    and lags when the spring, less the guides' friction, cannot accelerate the body and
    what its net carries as fast as the closed form asks. Its net's loads must be free (no
    load holds a sprung part against its input), so the spring is the only force moving
    the net: then this is the whole force balance, read from the parts as built."""

    cid: str
    net: str
    mass: float  # kg: the output body, the net's rods and its loads' input sliders
    friction: float  # N: Coulomb guide friction of every slider that moves
    stroke: float  # mm
    axis: tuple[float, float]  # unit vector off -> on
    start: tuple[float, float]  # the terminal's point at signal 0 (off)
    design: tuple[float, float]  # the body's terminal point at the design pose
    springs: list[tuple[tuple[float, float], tuple[float, float], float, float, float]]
    #        (ground anchor, attachment at the design pose, rate N/mm, rest mm, damping N s/mm)

    def force(self, x: float) -> tuple[float, float]:
        """The springs' pull along the output's axis (N, + towards on) with the output at
        signal ``x``, and their damping (N s/mm) along it."""
        ux, uy = self.axis
        dx = (self.start[0] + ux * x * self.stroke) - self.design[0]
        dy = (self.start[1] + uy * x * self.stroke) - self.design[1]
        f = c = 0.0
        for (ax, ay), (px, py), rate, rest, damp in self.springs:
            vx, vy = ax - (px + dx), ay - (py + dy)
            ln = math.hypot(vx, vy)
            if ln > rest and ln > 0.0:
                proj = (vx * ux + vy * uy) / ln
                f += rate * (ln - rest) * proj
                c += damp * proj * proj
        return f, c

    def run(self, ts: np.ndarray, hook: np.ndarray, until: float) -> tuple[np.ndarray,
                                                                          np.ndarray]:
        """The output's path (signal) while the input-held bound ``hook`` (the closed form at
        times ``ts``, held at its end after them) moves: free under spring, damping and
        friction, never beyond the bound on the spring's side, stopped at the end the spring
        pulls to."""
        n = int(until / FOLLOW_DT) + 1
        t = np.arange(n) * FOLLOW_DT
        h = np.interp(t, ts, hook)
        pull = 1.0 if self.force(0.5)[0] >= 0.0 else -1.0
        end = 1.0 if pull > 0 else 0.0
        x, v = float(h[0]), 0.0  # signal, signal/s
        out = np.empty(n)
        k = 1000.0 / (self.mass * self.stroke)  # N -> signal/s^2
        for i in range(n):
            if i:
                f, c = self.force(x)
                f -= c * v * self.stroke
                if v != 0.0:
                    f -= math.copysign(self.friction, v)
                elif abs(f) <= self.friction:
                    f = 0.0
                else:
                    f -= math.copysign(self.friction, f)
                v += f * k * FOLLOW_DT
                x += v * FOLLOW_DT
                if pull * (x - h[i]) > 0.0:  # the inputs hold it back: it rides the bound
                    x, v = float(h[i]), (float(h[i]) - float(h[i - 1])) / FOLLOW_DT
                if pull * (x - end) > 0.0:  # its stop
                    x, v = end, 0.0
                if v == 0.0 and t[i] > ts[-1] and x == h[i]:  # at rest where the move left it
                    out[i:] = x
                    break
            out[i] = x
        return t, out


def followers(design: Design, lib: Library) -> dict[str, Follower]:
    """Every cell whose output body is a :class:`Follower` (see there) and whose net's loads
    are free: no sprung part of a load cell touches the load's input body (an AMPLIFIER's
    input, a design output); a load that presses on its input helps or resists depending on
    its own state, which the cell tables cover instead."""
    mech, nl = design.mechanism, design.netlist
    index = mech.body_index()
    loads = net_loads(design.mechanism)
    S, fr = mech.ctx.stroke, mech.ctx.friction

    def pressed(body: str, part) -> bool:
        """Whether ``body`` has a one-sided contact with another moving body of ``part``."""
        return any(j.kind in ("contact", "touch") and body in (j.a, j.b)
                   and GROUND not in (j.a, j.b) for j in part.joints)

    def sprung_load(body: str, part, out_body: str | None) -> bool:
        """Whether a part of load cell ``part`` sprung to the ground touches ``body`` or
        what moves rigidly with it (rods, pins, grooves): then the load pushes on the net.
        So does a load that moves its own output (``out_body``) rigidly with its input (a
        NOT lever): the net then carries that output's loads too."""
        group, todo = {body}, [body]
        while todo:
            b = todo.pop()
            for j in part.joints:
                if j.kind in ("rod", "pin", "groove") and b in (j.a, j.b):
                    o = j.b if j.a == b else j.a
                    if o != GROUND and o not in group:
                        group.add(o)
                        todo.append(o)
        if out_body in group:
            return True
        sprung = {s.b if s.a == GROUND else s.a for s in part.springs
                  if GROUND in (s.a, s.b)}
        return any(j.kind in ("contact", "touch")
                   and ((j.a in group and j.b in sprung) or (j.b in group and j.a in sprung))
                   for j in part.joints)

    out: dict[str, Follower] = {}
    for c in nl.cells.values():
        cls = lib[c.cell]
        if cls.stateful or per_instance(cls) or c.id not in mech.cells:
            continue
        part = mech.cells[c.id]
        term = part.terminals.get(cls.outputs[0])
        net = c.outputs[0]
        if term is None or term.kind != "translating":
            continue
        body = term.body
        springs = []
        for s in part.springs:
            if s.b == body and s.a == GROUND:
                springs.append((s.pa, s.pb, s.rate, s.rest, s.damping))
            elif s.a == body and s.b == GROUND:
                springs.append((s.pb, s.pa, s.rate, s.rest, s.damping))
        if not springs or not pressed(body, part):
            continue
        sliders = 1 if index[body].kind == "slider" else 0
        free = True
        for r in net_rods(mech.nets[net]) if net in mech.nets else ():  # none: an output
            oid = r.load.split(".", 1)[0]
            owner = mech.cells.get(oid)
            out_term = (owner.terminals.get(lib[nl.cells[oid].cell].outputs[0])
                        if owner is not None and oid in nl.cells else None)
            if owner is None or sprung_load(r.load, owner,
                                            out_term.body if out_term else None):
                free = False
                break
            sliders += index[r.load].kind == "slider" if r.load in index else 0
        if not free:
            continue
        dx, dy = term.on[0] - term.off[0], term.on[1] - term.off[1]
        ln = math.hypot(dx, dy)
        out[c.id] = Follower(c.id, net, index[body].mass + loads.get(net, 0.0), fr * sliders,
                             S, (dx / ln, dy / ln), term.off, term.design_point, springs)
    return out
