"""The design-check pass (DESIGN §7): every check of a synthesised mechanism is made here.

Each check is a number with a limit, so a failure says by how much. In the order the design
lists them: the force checks decided when the mechanism was sized (each input actuator's rating
against what its net needs, a force budget that would not converge), each placed cell's own
rules (``Cell.checks``), then what the kinematic samples of the whole mechanism measure: minimum
transmission angle over every sampled state (rest and along single-input motions), distance from
singular (toggle) configurations, states the closed forms could not solve (parts that cannot
assemble, a pin off the end of its slot, a slider jammed between contradictory limits), spring
force at its weakest against what it must move, and for a sequential design each MEMORY's SET
and RESET never pressing together.
"""

from __future__ import annotations

import numpy as np

from mechc.cells.library import Library
from mechc.ir.check import Check
from mechc.ir.design import Design
from mechc.ir.mechanism import GROUND, Mechanism
from mechc.physics.closed_form import Poses, position

MIN_TRANSMISSION_DEG = 45.0
MIN_SINGULAR_MARGIN_DEG = 15.0
MIN_SPRING_MARGIN = 1.15  # springs are designed at 1.3 x what they must move


def owner(joint_or_body: str) -> str:
    return joint_or_body.rsplit(".", 1)[0] if "." in joint_or_body else joint_or_body


class CheckStats:
    """Running minima over chunks of kinematic states (the sweep never holds them all)."""

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.bodies = mech.body_index()
        self.mu: dict[str, float] = {}
        self.sing: dict[str, float] = {}
        self.bad: dict[str, int] = {}
        self.spring: dict[tuple[str, str], float] = {}

    def add(self, poses: Poses) -> None:
        for jid, mu in poses.transmission.items():
            if np.size(mu):
                v = float(np.nanmin(mu)) if not np.isnan(mu).all() else np.nan
                old = self.mu.get(jid, np.inf)
                self.mu[jid] = v if np.isnan(v) or np.isnan(old) else min(old, v)
        for jid, m in poses.singular_margin.items():
            if np.size(m):
                v = float(np.nanmin(m)) if not np.isnan(m).all() else np.nan
                old = self.sing.get(jid, np.inf)
                self.sing[jid] = v if np.isnan(v) or np.isnan(old) else min(old, v)
        for bid, bad in poses.bad.items():
            self.bad[bid] = self.bad.get(bid, 0) + int(np.count_nonzero(bad))
        for cid in self.mech.order:
            part = self.mech.cells[cid]
            need = part.data.get("spring_required_N", {})
            for sp in part.springs:
                if not need.get(sp.id):
                    continue
                a = None if sp.a == GROUND else self.bodies[sp.a]
                b = None if sp.b == GROUND else self.bodies[sp.b]
                if (a is not None and not poses.known(a.id)) or (
                        b is not None and not poses.known(b.id)):
                    continue
                ax, ay = position(a, poses, sp.pa)
                bx, by = position(b, poses, sp.pb)
                force = sp.rate * (np.hypot(bx - ax, by - ay) - sp.rest)
                f = float(np.nanmin(force)) if not np.isnan(force).all() else np.nan
                key = (cid, sp.id)
                old = self.spring.get(key, np.inf)
                self.spring[key] = f if np.isnan(f) or np.isnan(old) else min(old, f)

    def checks(self) -> list[Check]:
        out: list[Check] = []
        for name, data, limit in (("transmission angle", self.mu, MIN_TRANSMISSION_DEG),
                                  ("distance from toggle", self.sing, MIN_SINGULAR_MARGIN_DEG)):
            by_where: dict[str, float] = {}
            for jid, v in data.items():
                w = _where(jid)
                old = by_where.get(w, np.inf)
                by_where[w] = v if np.isnan(v) or np.isnan(old) else min(old, v)
            for w, v in sorted(by_where.items()):
                out.append(Check(name, w, v, limit, ">=", "°"))
        bad_by: dict[str, int] = {}
        for bid, count in self.bad.items():
            if count:
                w = _where(bid)
                bad_by[w] = max(bad_by.get(w, 0), count)
        for w, count in sorted(bad_by.items()):
            out.append(Check("unsolvable states (binding or cannot assemble)", w, float(count),
                             0.0, "<=", ""))
        for (cid, sid), f in self.spring.items():
            req = self.mech.cells[cid].data["spring_required_N"][sid]
            out.append(Check("spring force margin", sid, f / req, MIN_SPRING_MARGIN, ">=", "x"))
        return out


def run_design_checks(design: Design, lib: Library) -> None:
    """Measure the design checks on the closed-form kinematics (every input state and every
    single-input change up to 10 inputs) and record them in the mechanism and the stats."""
    # imported here, not at the top: mechc.proofs.kinematic imports CheckStats from this module
    from mechc.proofs.kinematic import sweep

    mech = design.mechanism
    stats = CheckStats(mech)
    wide = len(design.netlist.inputs) > 10
    # a budget of cell-states, so a big design is checked on a sample (the kinematic proof,
    # `mechc simulate --level kinematic`, remains exhaustive up to 10 inputs)
    budget = max(2000, 2_000_000 // max(1, len(design.netlist.cells)))
    sweep(design, lib, samples=5 if wide else 11, stats=stats, sample=128, max_states=budget)
    measured = stats.checks()
    if design.sequential is not None:
        measured += _memory_checks(design, lib, stats)
    mech.checks = mech.synthesis_checks() + cell_checks(design, lib) + measured
    failed = [c for c in mech.checks if not c.passed]
    mus = [c.value for c in mech.checks if c.name == "transmission angle"]
    design.stats["design_checks"] = {
        "passed": not failed, "count": len(mech.checks), "failed": [c.text() for c in failed],
        "min_transmission_angle_deg": round(min(mus), 4) if mus else None,
    }


def cell_checks(design: Design, lib: Library) -> list[Check]:
    """Each placed cell's own rules (``Cell.checks``), cells in topological order."""
    mech = design.mechanism
    out: list[Check] = []
    for cid in mech.order:
        cls = lib[design.netlist.cells[cid].cell]
        out += cls.checks(cid, mech.cells[cid], mech.ctx)
    return out


def _memory_checks(design: Design, lib: Library, stats: CheckStats) -> list[Check]:
    """A sequential design is also walked through every specified transition (the kinematic
    sequential proof): each MEMORY's SET and RESET must never press its lever together."""
    # imported here, not at the top: mechc.proofs.seq_mechanism imports CheckStats from here
    from mechc.proofs.seq_mechanism import prove_sequential_kinematic

    r = prove_sequential_kinematic(design, design.spec, lib, random_walks=0, stats=stats)
    per_cell = r["overlaps_by_cell"]
    mems = [c.id for c in design.netlist.cells.values() if c.type == "MEMORY"]
    return [Check("SET and RESET apart (transitions where both press)", f"MEMORY {c}",
                  float(per_cell.get(c, 0)), 0.0, "<=") for c in mems]


def kinematic_checks(mech: Mechanism, poses: Poses) -> list[Check]:
    stats = CheckStats(mech)
    stats.add(poses)
    return stats.checks()


def _where(jid: str) -> str:
    """Report checks per cell (``c3``), per net (``net n1``) or per input (``input A``)."""
    if jid.startswith("net."):
        return "net " + jid.split(".")[1]
    if jid.startswith("in:"):
        return "input " + jid[3:].split(".")[0]
    return jid.split(".")[0]
