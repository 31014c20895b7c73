"""The figures design checks are made of, measured on the closed forms over many states at
once: transmission angles, distance from toggle (singular) positions, states that cannot be
solved, spring force against what a spring must move. The design-check pass
(``mechc.passes.checks``) and the kinematic and dynamic proofs all measure with these."""

from __future__ import annotations

import numpy as np

from mechc.ir.check import Check
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
        # the angles' extremes are taken in the domain the closed forms give (their tangents):
        # one value per joint and chunk is converted to degrees (``Angles.min_deg``)
        for figures, acc in ((poses.transmission, self.mu), (poses.singular_margin, self.sing)):
            for jid in figures:
                v = figures.min_deg(jid)
                if v is None:
                    continue
                old = acc.get(jid, np.inf)
                acc[jid] = v if np.isnan(v) or np.isnan(old) else min(old, v)
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


def _where(jid: str) -> str:
    """Report checks per cell (``c3``), per net (``net n1``) or per input (``input A``)."""
    if jid.startswith("net."):
        return "net " + jid.split(".")[1]
    if jid.startswith("in:"):
        return "input " + jid[3:].split(".")[0]
    return jid.split(".")[0]
