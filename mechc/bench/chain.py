"""One input change, cell by cell: every switching cell's mid-stroke crossing in the whole
scene against the timing level's prediction (``benchmarks/chain.py`` prints and charts it;
the tests check the timing level with it).

The change runs once in pymunk from rest in its start state, as ``benchmarks/timing.py`` runs
each change, with every switching cell's output recorded. Each cell gets its *stage lag*: its
crossing after that of its latest-switching input, in the scene and in the model, and how the
timing level times it: ``amplifier`` (its table as the design built it), ``follower`` (a bar
its own spring moves, :class:`mechc.proofs.timing.Follower`) or ``pushed`` (its alone table).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from mechc.cells.characterise import crossing, settled_at
from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.physics.scene import Scene
from mechc.proofs.dynamic import plan_changes
from mechc.proofs.prune import blocker
from mechc.proofs.settings import dyn_settings
from mechc.proofs.timing import cell_tables, followers, predict_changes

PREFIX = "__cell:"


@dataclass
class Chain:
    """One change compared: ``rows`` per switching cell (``cell``, ``type``, ``timed_as``,
    ``scene_cross_s``, ``model_cross_s``, ``scene_settle_s`` and, with a switching input,
    ``input``, ``scene_stage_s``, ``model_stage_s``), in the order they cross in the scene."""

    change: int
    changes: int
    moving: str
    to: int
    rows: list[dict]
    predicted_settle_s: float  # the latest switching net's, from the move's start
    scene_settle_s: float  # the dynamic proof's (every body still), from the move's start
    scene_seconds: float
    outputs: dict[str, np.ndarray]  # every switching cell's output in the scene (PREFIX + id)
    t: np.ndarray  # the scene's sample times


def compare(d: Design, lib: Library, change: int | None = None,
            iterations: int | None = None) -> Chain:
    """The ``change``-th change of the dynamic proof's plan (default: the one the timing
    level predicts to settle latest), run (at ``iterations`` of the solver: default the
    proof's) and predicted."""
    nl, mech = d.netlist, d.mechanism
    names = list(d.spec.inputs)
    n = len(names)
    st = dyn_settings(d, lib, iterations=iterations)
    pairs, _ = plan_changes(d, names, 16, 0, independent=blocker(nl, lib) is None)
    tables, _ = cell_tables(d, lib, None, names, pairs)
    timed = predict_changes(d, lib, names, pairs, st, tables, detail=True)
    k = change if change is not None else max(range(len(timed)),
                                              key=lambda i: timed[i]["nets_settle_s"])
    rec = timed[k]
    cur, vec = pairs[k]
    bit = n - (cur ^ vec).bit_length()
    types = {c.id: c.cell for c in nl.cells.values()}
    outs = dict(mech.outputs)
    for cid in rec["switched"]:
        outs[PREFIX + cid] = (cid, lib[types[cid]].outputs[0])
    start = {nm: float((cur >> (n - 1 - q)) & 1) for q, nm in enumerate(names)}
    t0 = time.perf_counter()
    sc = Scene.build(dataclasses.replace(mech, outputs=outs), lib, types,
                     dataclasses.replace(st, record_every=1), start)
    r = sc.move(names[bit], float((vec >> (n - 1 - bit)) & 1))
    secs = time.perf_counter() - t0
    fol = followers(d, lib)
    drv = {c.outputs[0]: c.id for c in nl.cells.values()}
    rows: dict[str, dict] = {}
    for cid in rec["switched"]:
        x, ref = r.outputs[PREFIX + cid], r.reference[PREFIX + cid]
        tab = tables.get(cid)
        rows[cid] = {"cell": cid, "type": nl.cells[cid].type,
                     "timed_as": ("amplifier" if tab is not None and tab.as_built
                                  else "follower" if cid in fol else "pushed"),
                     "scene_cross_s": crossing(r.t, x),
                     "model_cross_s": (crossing(r.t, ref)
                                       + rec["nets_lag_s"].get(nl.cells[cid].outputs[0], 0.0)),
                     "scene_settle_s": settled_at(r.t, x, end=float(x[-1]))}
    order = sorted(rows, key=lambda c: rows[c]["scene_cross_s"])
    for cid in order:
        ins = [drv[x] for x in nl.cells[cid].inputs if drv.get(x) in rows]
        if ins:
            up = max(ins, key=lambda c: rows[c]["scene_cross_s"])
            upm = max(ins, key=lambda c: rows[c]["model_cross_s"])
            rows[cid]["input"] = up
            rows[cid]["scene_stage_s"] = rows[cid]["scene_cross_s"] - rows[up]["scene_cross_s"]
            rows[cid]["model_stage_s"] = rows[cid]["model_cross_s"] - rows[upm]["model_cross_s"]
    return Chain(k, len(pairs), names[bit], (vec >> (n - 1 - bit)) & 1,
                 [rows[c] for c in order], rec["nets_settle_s"], st.move_time + r.settle_time,
                 secs, r.outputs, r.t)
