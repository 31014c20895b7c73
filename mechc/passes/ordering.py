"""Ordering requirements of a sequential design, decided at compile time, and their cure.

The logic cannot remove an essential hazard (Unger) nor keep the SET and RESET of a memory
from moving together when one input drives both: the built mechanism must meet an ordering —
the moving input must reach every SET/RESET generator before a memory's new state does. This
pass finds every such requirement on the netlist (the ternary pass of the logic proof, plus
Unger's test on the reduced table), states its timing inequality from the cells' switching
times, and decides it by driving the pymunk scene through exactly the transitions that need
it (the sequential dynamic proof's own physics and settings, a handful of steps). Where a
requirement is not met it builds the cure in — a feedback delay on the Q nets of the memories
that switch: a chain of AMPLIFIERs (``stdlib/amplifier.py``, whose bistable toggle is the
library's measured delay and restores the full stroke), as many as the inequality asks for —
and decides again. A requirement still unmet becomes a failed design check, so compile
exits 1 naming it.

The inequality (seconds from the start of the input's move, ``move_time`` long)::

    t_input  = move_time + longest switching delay on the input's paths to any SET/RESET pin
    t_memory = move_time / 2 + shortest delay from the input to that memory's SET/RESET pin
               + MEMORY_THROW_S + shortest delay from the memory's Q back to any SET/RESET pin
    met when  t_memory - t_input >= MARGIN_S

It is conservative (a linkage gate passes a half-made input move on, where the inequality
counts only the finished one), so a requirement whose inequality fails may still be met:
the dynamic walk decides; the inequality sizes the delay.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from mechc.cells.library import Library
from mechc.errors import MechcError
from mechc.ir.check import Check
from mechc.ir.design import Design
from mechc.ir.netlist import Netlist
from mechc.ir.paths import essential_hazard_times, set_reset_skew
from mechc.ir.seqspec import (
    SeqSpec,
    bits_text,
    describe_total,
    initial_total_state,
    settle_async,
    stable_graph,
)
from mechc.passes.amplify import amplifier_cell, amplify_nets
from mechc.physics.closed_form import KinematicsError
from mechc.physics.scene import DynSettings
from mechc.proofs.hold import MEMORY_THROW_S
from mechc.proofs.seq_logic import SeqNetlist, X, _moved, _reachable, path_to, ternary_transition
from mechc.proofs.settings import dyn_settings

#: The time an ordering inequality must hold by (s): a quarter of the default input move.
MARGIN_S = 0.02
#: The name of the design check that carries each requirement's verdict.
CHECK_NAME = "ordering requirement met (dynamic walk of its transitions)"


@dataclass
class Requirement:
    """One ordering requirement and the transitions (x, spec state, x2) that need it."""

    kind: str  # "essential" or "set-reset-together"
    input: str
    memories: list[str]  # memories whose switching is the hazard (the feedback to delay)
    requires: str
    transitions: list[tuple[int, object, int]] = field(default_factory=list)
    where: list[str] = field(default_factory=list)
    timing: dict = field(default_factory=dict)
    failures: list[dict] = field(default_factory=list)
    steps: int = 0

    def to_json(self) -> dict:
        return {"kind": self.kind, "input": self.input, "memories": self.memories,
                "requires": self.requires, "transitions": self.where,
                "timing": self.timing, "dynamic_steps": self.steps,
                "dynamic_failures": len(self.failures), "met": not self.failures,
                "first_failure": failure_text(self.failures[0]) if self.failures else None}


def find_requirements(nl: Netlist, spec: SeqSpec,
                      unger: list[dict] | None = None) -> list[Requirement]:
    """Every ordering requirement of the netlist: from each reachable stable total state and
    each specified input change, the ternary pass (input mid-stroke as X, memories free to
    switch) — SET and RESET of a memory both X, or a memory whose end state depends on
    switching before the input has finished — and every transition of Unger's essential
    hazards of the table (``unger``, as ``essential_hazards`` reports them)."""
    sn = SeqNetlist(nl, spec.inputs)
    x0, s0 = initial_total_state(spec)
    st = settle_async(sn.excite(x0), sn.initial(), sn.m)
    if st.overlaps or st.cycle or len(st.finals) != 1:
        return []  # the logic proof and design checks report a circuit that cannot start
    unger_keys = {(h["state"], h["from"], h["input"]) for h in unger or []}
    found: dict[tuple, Requirement] = {}

    def add(kind: str, inp: str, mems: list[str], text: str, tr, where: str) -> None:
        key = (kind, inp, tuple(mems))
        r = found.setdefault(key, Requirement(kind, inp, mems, text))
        if tr not in r.transitions:
            r.transitions.append(tr)
            r.where.append(where)

    m = sn.m
    for (x, s, q), changes in _reachable(sn, spec, (x0, s0, st.finals[0])):
        for x2, _s2, res in changes:
            if res.cycle:
                continue
            moving = _moved(spec, x, x2).split()[0]
            where = f"{describe_total(spec, x, s)}, {_moved(spec, x, x2)}"
            q_end = res.finals[0] if res.finals else q
            switching = [net for j, net in enumerate(sn.mem_nets)
                         if (q ^ q_end) >> (m - 1 - j) & 1]
            t = ternary_transition(sn, x, x2, q)
            for j, net in enumerate(sn.mem_nets):
                sv, rv = sn.sr(t["after_a"], j)
                if sv != 0 and rv != 0:
                    add("set-reset-together", moving, [net],
                        f"SET and RESET of {net} both move when {moving} changes: the one "
                        "going off must release before the other comes on", (x, s, x2), where)
            unresolved = [net for net in sn.mem_nets if t["mem_b"][net] == X]
            key = ((spec.table.rows[s], bits_text(x, spec.n), moving)
                   if spec.table is not None else None)
            if unresolved or key in unger_keys:
                add("essential", moving, switching,
                    f"{moving} must reach every SET/RESET generator before "
                    f"{', '.join(switching) or 'a memory'} switch"
                    f"{'es' if len(switching) == 1 else ''} and feed back (essential hazard)",
                    (x, s, x2), where)
    return list(found.values())


def _delays(nl: Netlist, lib: Library) -> dict[str, float]:
    return {c.id: float(getattr(lib[c.cell], "switching_delay_s", 0.0))
            for c in nl.cells.values()}


def timing_inequality(nl: Netlist, lib: Library, req: Requirement,
                      move_time: float) -> dict:
    """The requirement's inequality with its numbers (see the module docstring), at the
    cells' stated delays; for SET and RESET moving together, the skew between the input's
    paths to the two pins (:mod:`mechc.ir.paths` computes both sides)."""
    delay = _delays(nl, lib)
    if req.kind == "set-reset-together":
        skew = set_reset_skew(nl, delay, req.input, req.memories)
        ok = skew <= MARGIN_S
        return {"skew_s": round(skew, 4), "margin_s": MARGIN_S, "met": ok,
                "feedback_delay_needed_s": 0.0,
                "text": f"skew of {req.input}'s paths to SET and RESET {skew:.3f} s "
                        f"{'<=' if ok else '>'} margin {MARGIN_S:.3f} s"}
    t_in, t_mem = essential_hazard_times(nl, delay, req.input, req.memories, move_time,
                                         MEMORY_THROW_S)
    slack = t_mem - t_in
    need = max(0.0, MARGIN_S - slack)
    return {"t_input_s": round(t_in, 4), "t_memory_feedback_s": round(t_mem, 4),
            "margin_s": MARGIN_S, "slack_s": round(slack, 4), "met": slack >= MARGIN_S,
            "feedback_delay_needed_s": round(need, 4),
            "text": f"t_memory {t_mem:.3f} s - t_input {t_in:.3f} s = {slack:+.3f} s "
                    f"{'>=' if slack >= MARGIN_S else '<'} margin {MARGIN_S:.3f} s"}


def tour_of(spec: SeqSpec, wanted: set[tuple[int, object, int]]) -> list[list[dict[str, int]]]:
    """Input sequences from power-up that take every wanted transition (x, state, x2): from
    where the walk is, the nearest untaken one (breadth-first over the stable graph)."""
    g = stable_graph(spec)
    untaken = {((x, s), x2) for x, s, x2 in wanted}
    seqs: list[list[int]] = []
    while untaken:
        cur, seq = g.initial, [g.initial[0]]
        while untaken:
            here = sorted((x2 for (node, x2) in untaken if node == cur), key=str)
            if here:
                x2 = here[0]
                untaken.discard((cur, x2))
                cur = next(v for xx, v in g.edges[cur] if xx == x2)
                seq.append(x2)
                continue
            path = path_to(g, cur, {node for node, _ in untaken})
            if path is None:
                break
            for x2, node in path:
                seq.append(x2)
                cur = node
        if len(seq) == 1:
            break
        seqs.append(seq)
    n = spec.n
    return [[{name: (x >> (n - 1 - k)) & 1 for k, name in enumerate(spec.inputs)} for x in s]
            for s in seqs]


def verify_requirements(design: Design, lib: Library, reqs: list[Requirement],
                        settings: DynSettings | None = None) -> list[dict]:
    """Drive the scene through the transitions of every requirement (one tour); each
    requirement gets the failures of its own transitions. Returns the failures on the way
    there (a step that is no requirement's transition), which fail the design as well."""
    from mechc.proofs.seq_mechanism import prove_sequential_dynamic

    spec = design.spec
    owner: dict[tuple, list[Requirement]] = {}
    for r in reqs:
        r.failures, r.steps = [], 0
        for tr in r.transitions:
            owner.setdefault(tr, []).append(r)
    seqs = tour_of(spec, set(owner))
    if not seqs:
        return []
    try:
        # the failures as found at these settings: no finer re-run at compile time
        rep = prove_sequential_dynamic(design, spec, lib, settings=settings, sequences=seqs,
                                       recheck=False)
    except (MechcError, KinematicsError) as e:  # a mechanism the scene cannot run fails too
        return [{"kind": "error", "message": str(e)}]
    steps = _steps_of(spec, seqs)
    for tr in steps.values():
        for r in owner.get(tr, []):
            r.steps += 1
    other = []
    for f in rep["failures"]:
        tr = steps.get((f.get("sequence"), f.get("step")))
        rs = owner.get(tr, []) if tr is not None else []
        for r in rs:
            r.failures.append(f)
        if not rs:
            other.append(f)
    if rep["failure_count"] > len(rep["failures"]) and not other:
        other.append({"kind": "more", "message": f"{rep['failure_count']} failures in all"})
    return other


def _steps_of(spec: SeqSpec, seqs) -> dict[tuple[int, int], tuple]:
    """(sequence, step) -> the transition (x, spec state, x2) it takes."""
    from mechc.ir.seqspec import next_stable

    n = spec.n
    out = {}
    for si, seq in enumerate(seqs):
        x, s = initial_total_state(spec)
        for k in range(1, len(seq)):
            x2 = sum(int(seq[k][name]) << (n - 1 - i) for i, name in enumerate(spec.inputs))
            out[(si, k)] = (x, s, x2)
            s, x = next_stable(spec, s, x, x2), x2
    return out


def ordering_checks(reqs: list[Requirement], other: list[dict]) -> list[Check]:
    """One design check per requirement (failing steps of its transitions, limit 0), and one
    for failures met on the way to them."""
    checks = [Check(CHECK_NAME, f"{r.kind}: {r.requires} [{r.where[0]}"
                    f"{f' and {len(r.where) - 1} more' if len(r.where) > 1 else ''}; "
                    f"inequality {r.timing.get('text', '?')}]",
                    float(len(r.failures)), 0.0, "<=") for r in reqs]
    if other:
        checks.append(Check("dynamic walk to the hazardous transitions", "steps before them",
                            float(len(other)), 0.0, "<="))
    return checks


def failure_text(f: dict) -> str:
    """One line for a failure of the dynamic walk."""
    step = f" ({f['moving']} to {f['to']})" if "moving" in f else ""
    if f.get("message"):
        return f"{f.get('kind', '')}: {f['message']}{step}"
    return (f"{f.get('kind')}: {f.get('output', '')} expected {f.get('expected', '?')}, "
            f"at {f.get('position', f.get('max_deviation', '?'))}{step}")


def decide_ordering(design: Design, lib: Library,
                    rebuild: Callable[[Netlist, dict[str, str]], Design | None]) -> Design:
    """Find, time and verify every ordering requirement of ``design``; where one is unmet,
    rebuild with a feedback delay on the Q nets of the memories it names (``rebuild``: the
    delayed netlist and why -> a placed, synthesised, checked design; None when amplifying
    is switched off), sized by the inequality, and decide again — over the transitions of the
    requirements and then the whole default dynamic walk, since the delay changes the
    mechanism everywhere. The requirements, their inequalities, the cure and the verdicts go
    to ``stats.sequential.ordering``; each verdict is a design check."""
    reqs, other = _decide(design, lib)
    cure: dict = {}
    if any(r.failures for r in reqs) or other:
        stages = _delay_stages(design, lib, reqs)
        cured = None
        if stages:
            cured = rebuild(delay_nets(design.netlist, lib, stages), {
                n: f"feedback delay ({k} stage(s)): an ordering requirement was not met "
                   "without it" for n, k in stages.items()})
        if cured is not None:
            reqs2, other2 = _decide(cured, lib)
            if not any(r.failures for r in reqs2) and not other2:
                other2 = _whole_walk(cured, lib)
            bad1 = sum(len(r.failures) for r in reqs) + len(other)
            bad2 = sum(len(r.failures) for r in reqs2) + len(other2)
            cure = {"feedback_delay_on": stages, "cell": amplifier_cell(lib).name,
                    "delay_per_cell_s": _cell_delay(lib), "failing_steps_before": bad1,
                    "failing_steps_after": bad2, "kept": bad2 < bad1}
            if bad2 < bad1:
                design, reqs, other = cured, reqs2, other2
    _record(design, reqs, other, cure)
    return design


def _whole_walk(design: Design, lib: Library) -> list[dict]:
    """The failures of the default sequential dynamic proof (what ``mechc simulate`` runs)."""
    from mechc.proofs.seq_mechanism import prove_sequential_dynamic

    try:
        rep = prove_sequential_dynamic(design, design.spec, lib, recheck=False)
    except (MechcError, KinematicsError) as e:
        return [{"kind": "error", "message": str(e)}]
    return list(rep["failures"])


def delay_nets(nl: Netlist, lib: Library, stages: dict[str, int]) -> Netlist:
    """Every load of each named net behind a chain of ``stages`` delay cells."""
    for net, k in stages.items():
        cur = [net]
        for _ in range(k):
            before = set(nl.cells)
            nl = amplify_nets(nl, lib, cur, reason="delay")
            cur = [c.outputs[0] for cid, c in nl.cells.items() if cid not in before]
    return nl


def _delay_stages(design: Design, lib: Library, reqs: list[Requirement]) -> dict[str, int]:
    """Q net -> delay cells in a chain: for each memory named by an unmet essential
    requirement, enough cells for the largest delay its inequalities ask for (at least one).
    A net whose loads are all delay cells already is left out."""
    nl = design.netlist
    step = _cell_delay(lib)
    out: dict[str, int] = {}
    for r in reqs:
        if not r.failures or r.kind != "essential":
            continue
        need = float(r.timing.get("feedback_delay_needed_s", 0.0))
        k = max(1, math.ceil(need / step - 1e-9)) if step > 0 else 1
        for net in r.memories:
            loads = [v for _u, v, d in nl.graph.edges(data=True) if d["net"] == net]
            if any(v in nl.cells and nl.cells[v].type != "AMPLIFIER" for v in loads):
                out[net] = max(out.get(net, 0), k)
    return out


def _cell_delay(lib: Library) -> float:
    return float(getattr(amplifier_cell(lib), "switching_delay_s", 0.0))


def _decide(design: Design, lib: Library) -> tuple[list[Requirement], list[dict]]:
    se = design.sequential
    unger = se.essential_hazards if se is not None else []
    reqs = find_requirements(design.netlist, design.spec, unger)
    if not reqs:
        return [], []
    st = dyn_settings(design, lib)
    for r in reqs:
        r.timing = timing_inequality(design.netlist, lib, r, st.move_time)
    return reqs, verify_requirements(design, lib, reqs, st)


def _record(design: Design, reqs: list[Requirement], other: list[dict], cure: dict) -> None:
    design.stats.setdefault("sequential", {})["ordering"] = {
        "requirements": [r.to_json() for r in reqs], "margin_s": MARGIN_S,
        "failures_elsewhere": [failure_text(f) for f in other[:10]], "cure": cure}
    mech = design.mechanism
    if mech is None:
        return
    mech.checks = [c for c in mech.checks if c.name != CHECK_NAME] + ordering_checks(reqs,
                                                                                     other)
    failed = [c for c in mech.checks if not c.passed]
    dc = design.stats.setdefault("design_checks", {})
    dc.update({"passed": not failed, "count": len(mech.checks),
               "failed": [c.text() for c in failed]})
