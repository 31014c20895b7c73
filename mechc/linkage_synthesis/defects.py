"""Circuit and branch defects of a linkage assembled from synthesised dyads.

Precision-position synthesis treats each position separately, so the dyads it returns may join
into a four-bar that reaches some positions in one assembly and the others in the other one
(Mather & Erdman 2023 leave this check out; see their refs. 19-25).  A four-bar driven by its
input link has two assemblies at each input angle, told apart by the sign of the angle between
coupler and follower (the transmission-angle sign):

* if the sign differs between prescribed positions the linkage cannot pass through all of them
  without being taken apart: a *circuit* defect when the linkage is Grashof with a fully rotating
  input (the assemblies are separate circuits), a *branch* defect otherwise (they meet at a
  toggle, where the input would have to stop and the linkage could go either way);
* even with equal signs the input may have to pass a toggle on its way from one position to the
  next (a non-rotatable input): also a branch defect.  This is found by driving the input through
  each leg and watching the discriminant of the loop closure.

A six-bar is checked loop by loop with the same sign test (:func:`loop_signs`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechc.geometry.circles import circle_intersection, circle_meeting
from mechc.linkage_synthesis.mk_circles import ChainSolution


def loop_signs(driver_moving, follower_moving, follower_pivot) -> np.ndarray:
    """Assembly sign of a four-bar loop at each position: the sign of the angle from the coupler
    (driver's moving pivot -> follower's moving pivot) to the follower (its moving pivot -> its
    pivot).  Rotation- and translation-invariant, so it also works for a loop whose 'ground' is
    a moving link of a six-bar."""
    a = np.asarray(follower_moving, complex) - np.asarray(driver_moving, complex)
    b = np.asarray(follower_pivot, complex) - np.asarray(follower_moving, complex)
    return np.sign(np.imag(np.conj(a) * b))


@dataclass(frozen=True)
class FourBar:
    """Ground pivots ga (input) and gb, moving pivots ka, kb in position 1."""

    ga: complex
    gb: complex
    ka: complex
    kb: complex

    @property
    def lengths(self) -> tuple[float, float, float, float]:
        """(ground, input, coupler, follower)."""
        return (abs(self.gb - self.ga), abs(self.ka - self.ga), abs(self.kb - self.ka),
                abs(self.kb - self.gb))

    @property
    def grashof(self) -> bool:
        ls = sorted(self.lengths)
        return ls[0] + ls[3] <= ls[1] + ls[2]

    @property
    def input_rotates(self) -> bool:
        """Grashof with the input the shortest link (crank-rocker) or the ground shortest
        (double crank)."""
        g, i, c, f = self.lengths
        return self.grashof and min(self.lengths) in (i, g)


def fourbar_from_dyads(driver: ChainSolution, follower: ChainSolution) -> FourBar:
    """Join two dyads synthesised for the same positions (the same coupler rotations)."""
    return FourBar(driver.ground, follower.ground, driver.pivots[1], follower.pivots[1])


def solve_follower(fb: FourBar, input_angle, sign: float):
    """Moving pivots for input angles (absolute, rad) in the assembly with the given sign.
    Returns (ka, kb, discriminant); kb is NaN where the loop cannot close."""
    g, i, c, f = fb.lengths
    ka = fb.ga + i * np.exp(1j * np.asarray(input_angle, float))
    kb_pos, disc = circle_meeting(ka, c, fb.gb, f, 1, miss="nan")
    kb_neg = circle_intersection(ka, c, fb.gb, f, -1, miss="nan")
    s_pos = loop_signs(ka, kb_pos, fb.gb)
    kb = np.where(s_pos == sign, kb_pos, kb_neg)
    return ka, kb, disc


@dataclass
class DefectReport:
    signs: list[int]  # assembly sign at each prescribed position
    grashof: bool
    input_rotates: bool
    circuit_defect: bool
    branch_defect: bool
    order_reversals: list[int] = field(default_factory=list)  # legs where the input turns back
    toggles: list[tuple[int, float]] = field(default_factory=list)  # (leg, input angle deg)
    min_transmission_deg: float = float("nan")  # along the legs that can be travelled
    messages: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not (self.circuit_defect or self.branch_defect)

    def to_json(self) -> dict:
        return {"ok": self.ok, "signs": self.signs, "grashof": self.grashof,
                "input_rotates": self.input_rotates, "circuit_defect": self.circuit_defect,
                "branch_defect": self.branch_defect, "order_reversals": self.order_reversals,
                "toggles": [[j, a] for j, a in self.toggles],
                "min_transmission_deg": self.min_transmission_deg, "messages": self.messages}


def check_fourbar(fb: FourBar, ka_positions, kb_positions, samples: int = 721) -> DefectReport:
    """Defects of ``fb`` for the prescribed poses (moving pivots at each position)."""
    ka_p = np.asarray(ka_positions, complex)
    kb_p = np.asarray(kb_positions, complex)
    signs = loop_signs(ka_p, kb_p, fb.gb).astype(int)
    th = np.angle(ka_p - fb.ga)
    rep = DefectReport([int(s) for s in signs], fb.grashof, fb.input_rotates, False, False)
    if len(set(signs.tolist())) > 1:
        if fb.input_rotates:
            rep.circuit_defect = True
            rep.messages.append("circuit defect: the positions lie on both circuits "
                                f"(assembly signs {rep.signs})")
        else:
            rep.branch_defect = True
            rep.messages.append("branch defect: the positions lie on both branches, joined only "
                                f"through a toggle (assembly signs {rep.signs})")
    steps = np.angle(np.exp(1j * np.diff(th)))  # shortest signed turn per leg
    direction = np.sign(steps.sum()) or 1.0
    mins = []
    for j, stp in enumerate(steps):
        if np.sign(stp) != direction and stp != 0.0:
            rep.order_reversals.append(j + 1)
        path = th[j] + np.linspace(0.0, stp, samples)
        ka, kb, disc = solve_follower(fb, path, signs[j])
        bad = ~(disc > 1e-12 * max(fb.lengths) ** 2)
        if bad.any():
            k = int(np.argmax(bad))
            rep.toggles.append((j + 1, float(np.degrees(path[k]))))
            rep.branch_defect = True
            rep.messages.append(f"branch defect: between positions {j + 1} and {j + 2} the input "
                                f"reaches a toggle at {np.degrees(path[k]):.2f} deg")
            continue
        cosang = np.real((ka - kb) * np.conj(fb.gb - kb)) / (fb.lengths[2] * fb.lengths[3])
        ang = np.degrees(np.arccos(np.clip(cosang, -1, 1)))
        mins.append(float(np.min(np.minimum(ang, 180 - ang))))
    if rep.order_reversals:
        rep.messages.append("order: the input turns back before positions "
                            + ", ".join(str(j + 1) for j in rep.order_reversals))
    rep.min_transmission_deg = float(min(mins)) if mins else float("nan")
    return rep


def check_dyads(driver: ChainSolution, follower: ChainSolution) -> DefectReport:
    """Assemble two synthesised dyads into a four-bar and check it at their positions."""
    fb = fourbar_from_dyads(driver, follower)
    n = driver.angles.shape[1]
    ka = np.array([driver.pose(j)[1] for j in range(n)])
    kb = np.array([follower.pose(j)[1] for j in range(n)])
    return check_fourbar(fb, ka, kb)


def check_loops(loops: list[tuple]) -> list[dict]:
    """Six-bar (or any multi-loop) check: each loop given as (driver_moving, follower_moving,
    follower_pivot) arrays over the positions; flags every loop whose assembly sign changes."""
    out = []
    for i, (dm, fm, fp) in enumerate(loops):
        s = loop_signs(dm, fm, fp).astype(int)
        changed = len(set(s.tolist())) > 1
        out.append({"loop": i + 1, "signs": [int(v) for v in s], "defect": changed,
                    "message": (f"loop {i + 1}: assembly changes between positions "
                                f"(signs {s.tolist()})") if changed else ""})
    return out
