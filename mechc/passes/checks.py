"""The design-check pass (docs/mechanism.md, "Design checks"): every check of a synthesised
mechanism is made here.

Each check is a number with a limit, so a failure says by how much. In the order the design lists
them: the force checks decided when the mechanism was sized (each input actuator's rating against
what its net needs, a force budget that would not converge), each placed cell's own rules
(``Cell.checks``), then what the kinematic samples of the whole mechanism measure: minimum
transmission angle over every sampled state (rest and along single-input motions), distance from
singular (toggle) configurations, states the closed forms could not solve (parts that cannot
assemble, a pin off the end of its slot, a slider jammed between contradictory limits), spring force
at its weakest against what it must move, for a sequential design each MEMORY's SET and RESET
never pressing together, and on the same states that no two parts on one plane come closer than
the clearance (``mechc.physics.interference``); each cell's rules on the rest states
(``Cell.rest_checks``); and the strength of every part (``mechc/passes/strength.py``: stress,
bending, buckling, pins, springs).
"""

from __future__ import annotations

import numpy as np

from mechc.cells.cell import Cell
from mechc.cells.library import Library
from mechc.cells.prove_cell import user_cell_checks
from mechc.ir.check import Check
from mechc.ir.design import Design
from mechc.parts.poses import PoseTee
from mechc.passes.strength import strength_checks
from mechc.physics.evaluate import settle
from mechc.physics.interference import Interference
from mechc.physics.measures import CheckStats
from mechc.proofs.kinematic import sweep
from mechc.proofs.seq_mechanism import prove_sequential_kinematic


def run_design_checks(design: Design, lib: Library) -> None:
    """Measure the design checks on the closed-form kinematics (every input state and every
    single-input change up to 10 inputs) and record them in the mechanism and the stats."""
    mech = design.mechanism
    stats = CheckStats(mech)
    parts = Interference(mech, mech.ctx.clearance)
    both = PoseTee(stats, parts)  # one sweep feeds both
    wide = len(design.netlist.inputs) > 10
    # a budget of cell-states, so a big design is checked on a sample (the kinematic proof,
    # `mechc simulate --level kinematic`, remains exhaustive up to 10 inputs)
    budget = max(2000, 2_000_000 // max(1, len(design.netlist.cells)))
    result = sweep(design, lib, samples=5 if wide else 11, stats=both, sample=128,
                   max_states=budget)
    measured = stats.checks()
    if design.sequential is not None:
        measured += _memory_checks(design, lib, both)
    measured += parts.checks()
    mech.checks = (mech.synthesis_checks() + cell_checks(design, lib)
                   + rest_checks(design, lib, result["rest_bits"]) + measured
                   + strength_checks(mech))
    failed = [c for c in mech.checks if not c.passed]
    mus = [c.value for c in mech.checks if c.name == "transmission angle"]
    design.stats["design_checks"] = {
        "passed": not failed, "count": len(mech.checks), "failed": [c.text() for c in failed],
        "min_transmission_angle_deg": round(min(mus), 4) if mus else None,
        "interference": parts.summary(),
    }


def cell_checks(design: Design, lib: Library) -> list[Check]:
    """Each placed cell's own rules (``Cell.checks``), cells in topological order."""
    mech = design.mechanism
    out: list[Check] = []
    for cid in mech.order:
        cls = lib[design.netlist.cells[cid].cell]
        out += cls.checks(cid, mech.cells[cid], mech.ctx)
    return out + user_cell_checks(design, lib)  # each user cell proven alone, once


#: Up to this many MEMORY cells, rest states start from every combination of their states.
REST_MEMORY_COMBINATIONS = 4


def rest_checks(design: Design, lib: Library, rest_bits: np.ndarray) -> list[Check]:
    """Each placed cell's rules on the rest states (``Cell.rest_checks``): every input vector
    the sweep took, MEMORY cells settled from each combination of their states (from their
    initial states only beyond ``REST_MEMORY_COMBINATIONS`` memories)."""
    mech = design.mechanism
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    names = list(design.netlist.inputs)
    if all(lib[t].rest_checks.__func__ is Cell.rest_checks.__func__ for t in set(types.values())):
        return []  # no cell of this design has rest rules: skip the evaluation
    mems = [cid for cid in mech.order if getattr(lib[types[cid]], "stateful", False)]
    starts = 1 << len(mems) if len(mems) <= REST_MEMORY_COMBINATIONS else 1
    n = rest_bits.shape[1]
    values = {nm: np.tile(rest_bits[k].astype(float), starts) for k, nm in enumerate(names)}
    state = None
    if starts > 1:
        combo = np.repeat(np.arange(starts), n)
        state = {cid: ((combo >> i) & 1).astype(float) for i, cid in enumerate(mems)}
    poses, _, _ = settle(mech, lib, types, values, state)
    out: list[Check] = []
    for cid in mech.order:
        out += lib[types[cid]].rest_checks(cid, mech.cells[cid], mech.ctx, poses)
    return out


def _memory_checks(design: Design, lib: Library, stats: PoseTee) -> list[Check]:
    """A sequential design is also walked through every specified transition (the kinematic
    sequential proof): each MEMORY's SET and RESET must never press its lever together."""
    r = prove_sequential_kinematic(design, design.spec, lib, random_walks=0, stats=stats)
    per_cell = r["overlaps_by_cell"]
    mems = [c.id for c in design.netlist.cells.values() if c.type == "MEMORY"]
    return [Check("SET and RESET apart (transitions where both press)", f"MEMORY {c}",
                  float(per_cell.get(c, 0)), 0.0, "<=") for c in mems]


