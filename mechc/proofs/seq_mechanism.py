"""Sequential proofs of the mechanism: the closed form and the pymunk scene walked through the
spec's input sequences in fundamental mode (one input changes, the circuit settles).

The walks are the logic level's (``transition_tour``: every specified transition from every
reachable stable state, then seeded random walks); the expected outputs at each stable state
come from the spec's own semantics (``expected_after``), never from the netlist. Per step the
proof fails on: a wrong output at rest, a glitch on an output the step must not change, a
MEMORY driven by SET and RESET together (the lever binds: reported as an S·R overlap), states
that keep changing (oscillation), and at the dynamic level the solver checks of
``mechc.proofs.dynamic`` (joint stretch, contact overrun, settle, stall). As there, the
steps failing on a kind the solver may cause run again at twice the iterations: here the first
``RECHECK_MAX`` pieces of walks that hold one, whole (a step's state is its walk's so far).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.seqspec import SeqSpec
from mechc.parts.poses import PoseSink
from mechc.physics.closed_form import KinematicsError
from mechc.physics.evaluate import output_signals, settle
from mechc.physics.scene import DynSettings, MoveResult, Scene
from mechc.proofs.dynamic import RECHECK_MAX, RECHECKED, finer_entry
from mechc.proofs.parallel import run_cases
from mechc.proofs.registry import OnProgress, engine
from mechc.proofs.report import ProofReport
from mechc.proofs.seq_logic import (
    Piece,
    expected_after,
    expected_states,
    split_walks,
    transition_tour,
)
from mechc.proofs.settings import ProofSettings, dyn_settings
from mechc.proofs.trace import TraceRecorder

MAX_LISTED = 50


def _types(design: Design) -> dict[str, str]:
    return {c.id: c.cell for c in design.netlist.cells.values()}


def stateful_cells(design: Design, lib: Library) -> list[str]:
    return [c.id for c in design.netlist.cells.values()
            if getattr(lib[c.cell], "stateful", False)]


class _Failures:
    def __init__(self):
        self.items: list[dict] = []
        self.counts: dict[str, int] = {}
        self.by_cell: dict[tuple[str, str], int] = {}

    def add(self, kind: str, **info) -> None:
        self.counts[kind] = self.counts.get(kind, 0) + 1
        if "cell" in info:  # every one counted per cell, also past the listed ones
            key = (kind, info["cell"])
            self.by_cell[key] = self.by_cell.get(key, 0) + 1
        if len(self.items) < MAX_LISTED:
            self.items.append({"kind": kind, **info})

    @property
    def total(self) -> int:
        return sum(self.counts.values())


def _synthesis_failures(fails: _Failures, design: Design) -> None:
    """Force checks decided at synthesis fail the proof too (a design that needs amplifiers)."""
    for c in design.mechanism.synthesis_checks():
        if not c.passed:
            fails.add("design check", check=c.name, where=c.where, value=round(c.value, 6),
                      limit=c.limit, message=c.text())


def _walks(spec, seed: int, random_walks: int):
    seqs = transition_tour(spec, seed=seed, random_walks=random_walks)
    return [(s, expected_after(spec, s)) for s in seqs]


def _judge_outputs(fails, where, outs_end, outs_path, before, after, tolerance, dev_acc):
    for o, want in after.items():
        if want is None or o not in outs_end:
            continue
        got = float(outs_end[o])
        dev = abs(got - want)
        dev_acc[0] = max(dev_acc[0], dev if math.isfinite(dev) else math.inf)
        if not dev <= tolerance:
            fails.add("rest", **where, output=o, expected=int(want), position=round(got, 6))
        if before.get(o) is not None and before[o] == want and o in outs_path:
            glitch = float(np.max(np.abs(np.asarray(outs_path[o]) - want)))
            dev_acc[0] = max(dev_acc[0], glitch)
            if glitch > tolerance:
                fails.add("glitch", **where, output=o, expected=int(want),
                          max_deviation=round(glitch, 6))


@engine("kinematic", "sequential")
def sequential_kinematic_engine(design: Design, spec: SeqSpec, lib: Library,
                                settings: ProofSettings,
                                progress: OnProgress | None) -> ProofReport:
    return prove_sequential_kinematic(design, spec, lib, tolerance=settings.tolerance,
                                      seed=settings.seed, trace=settings.trace)


def prove_sequential_kinematic(design: Design, spec, lib: Library, tolerance: float = 0.05,
                               samples: int = 21, seed: int = 0, random_walks: int = 4,
                               stats: PoseSink | None = None,
                               trace: TraceRecorder | None = None) -> ProofReport:
    """Walk the closed form through the spec's sequences (each step sampled along the moving
    input, the stateful cells settled at every sample); ``trace`` receives every body's pose
    at power-up and along every step."""
    try:
        return _prove_sequential_kinematic(design, spec, lib, tolerance, samples, seed,
                                           random_walks, stats, trace)
    except KinematicsError as e:  # as the combinational kinematic proof reports it
        raise UsageError(f"the geometry is not a determinate mechanism: {e}") from None


def _prove_sequential_kinematic(design: Design, spec, lib: Library, tolerance: float,
                                samples: int, seed: int, random_walks: int,
                                stats: PoseSink | None,
                                trace: TraceRecorder | None) -> ProofReport:
    t0 = time.perf_counter()
    mech, types = design.mechanism, _types(design)
    mems = stateful_cells(design, lib)
    fails = _Failures()
    _synthesis_failures(fails, design)
    dev = [0.0]
    steps = 0
    t = np.linspace(0.0, 1.0, samples)
    for si, (seq, want) in enumerate(_walks(spec, seed, random_walks)):
        cur = {k: float(v) for k, v in seq[0].items()}
        vals = {k: np.array([v]) for k, v in cur.items()}
        poses, state, osc = settle(mech, lib, types, vals)
        if stats is not None:
            stats.add(poses)
        _judge_outputs(fails, {"sequence": si, "step": 0}, _last(output_signals(mech, poses)),
                       {}, {}, want[0], tolerance, dev)
        state_names = expected_states(spec, seq) if trace is not None else []
        if trace is not None:
            trace.add("rest", None, seq[0], seq[0], want[0], want[0], [0.0], [1.0],
                      trace.frames_of(poses, 1), sequence=si, step=0,
                      expected_state=state_names[0])
        for k in range(1, len(seq)):
            moved = next(n for n in seq[k] if seq[k][n] != cur[n])
            vals = {n: np.full(samples, v) for n, v in cur.items()}
            vals[moved] = cur[moved] + (seq[k][moved] - cur[moved]) * t
            prior = {c: np.full(samples, v[-1]) for c, v in state.items()}
            poses, path_state, osc = settle(mech, lib, types, vals, prior)
            if stats is not None:
                stats.add(poses)
            where = {"sequence": si, "step": k, "moving": moved, "to": int(seq[k][moved]),
                     "inputs": {n: int(v) for n, v in seq[k].items()}}
            jam = [c for c in mems if any(poses.bad.get(b.id, np.zeros(1, bool)).any()
                                          for b in mech.cells[c].bodies)]
            for c in jam:
                fails.add("S·R overlap", **where, cell=c,
                          message=f"MEMORY {c} driven by SET and RESET at once (binds)")
            if osc.any():
                fails.add("oscillation", **where, message="the states keep changing")
            outs = output_signals(mech, poses)
            _judge_outputs(fails, where, _last(outs), outs, want[k - 1], want[k], tolerance, dev)
            if trace is not None:
                trace.add("change", moved, seq[k - 1], seq[k], want[k - 1], want[k],
                          t * trace.move_time, t, trace.frames_of(poses, samples),
                          sequence=si, step=k, expected_state=state_names[k])
            state = path_state
            cur = {n: float(v) for n, v in seq[k].items()}
            steps += 1
    return ProofReport(
        level="kinematic", kind="sequential", passed=fails.total == 0, cases=steps,
        coverage={"steps": steps, "memories": len(mems), "tolerance_fraction": tolerance},
        failure_count=fails.total, failure_kinds=fails.counts,
        overlaps_by_cell={c: n for (k, c), n in fails.by_cell.items() if k == "S·R overlap"},
        failures=fails.items,
        figures={"max_deviation_fraction": round(dev[0], 6),
                 "min_margin_fraction": round(0.5 - dev[0], 6)},
        seconds=round(time.perf_counter() - t0, 3))


def _memory_inputs(mech, lib, types, scene) -> dict[str, tuple[str, str]]:
    """Stateful cell -> (S body, R body) for the cells present in the scene."""
    out = {}
    for cid, part in mech.cells.items():
        if getattr(lib[types[cid]], "stateful", False) and "S" in part.terminals:
            pair = (part.terminals["S"].body, part.terminals["R"].body)
            if all(b in scene.bodies for b in pair):
                out[cid] = pair
    return out


def _binding(mech, lib, types, watch, watched) -> list[str]:
    """Stateful cells whose recorded S and R positions the closed form cannot accept (the
    faces press the lever from both sides): an S·R overlap seen in the dynamics, e.g. one path
    delayed by an AMPLIFIER (001 Appendix B.2)."""
    bad = []
    for cid, (s_body, r_body) in watch.items():
        if s_body not in watched or r_body not in watched:
            continue
        us, ur = watched[s_body], watched[r_body]
        part = mech.cells[cid]
        poses = lib[types[cid]].kinematics(part, {s_body: us, r_body: ur}, len(us),
                                           np.zeros(len(us)))
        lever = [b.id for b in part.bodies if b.id in poses.bad]
        if any(poses.bad[b].any() for b in lever):
            bad.append(cid)
    return bad


def _last(outs: dict[str, np.ndarray]) -> dict[str, float]:
    return {o: float(np.ravel(v)[-1]) for o, v in outs.items()}


@dataclass
class WalkJob:
    """What every walk of one sequential dynamic proof needs (sent once to each worker)."""

    design: Design
    types: dict[str, str]
    settings: DynSettings
    trace: TraceRecorder | None  # only when the walks run in this process


def run_walk(job: WalkJob, lib: Library, case) -> list[tuple[MoveResult, list[str]]]:
    """One sequence (``case``: index, input vectors, expected outputs, expected states for a
    trace) on a fresh scene from power-up: per step the move and the MEMORY cells whose SET
    and RESET bound."""
    si, seq, want, state_names = case
    mech, types, trace = job.design.mechanism, job.types, job.trace
    cur = {k: float(v) for k, v in seq[0].items()}
    scene = Scene.build(mech, lib, types, job.settings, cur)
    watch = _memory_inputs(mech, lib, types, scene)
    scene.watch = [b for pair in watch.values() for b in pair]
    if trace is not None:
        scene.sink = trace
        trace.begin("rest", None, seq[0], seq[0], want[0], want[0], sequence=si, step=0,
                    expected_state=state_names[0])
        trace.sample(scene, 0.0, 1.0)
        trace.end()
    out = []
    for k in range(1, len(seq)):
        moved = next(n for n in seq[k] if seq[k][n] != cur[n])
        if trace is not None:
            trace.begin("change", moved, seq[k - 1], seq[k], want[k - 1], want[k],
                        sequence=si, step=k, expected_state=state_names[k])
        r = scene.move(moved, float(seq[k][moved]))
        if trace is not None:
            trace.end()
        binding = _binding(mech, lib, types, watch, r.watched)
        r.t, r.watched = np.zeros(0), {}  # not read by the proof: less to send back
        out.append((r, binding))
        cur[moved] = float(seq[k][moved])
    return out


@engine("dynamic", "sequential")
def sequential_dynamic_engine(design: Design, spec: SeqSpec, lib: Library,
                              settings: ProofSettings,
                              progress: OnProgress | None) -> ProofReport:
    st = dyn_settings(design, lib, dt=settings.dt, iterations=settings.iterations,
                      move_time=settings.move_time, hold=settings.hold,
                      progress=progress)
    return prove_sequential_dynamic(design, spec, lib, settings=st,
                                    tolerance=settings.tolerance, seed=settings.seed,
                                    progress=progress, trace=settings.trace,
                                    jobs=settings.jobs, scheduler=settings.scheduler,
                                    recheck=settings.recheck)


#: The fields of a failure entry that name its step (``prefix`` only on the way to a piece's
#: start state).
WHERE = ("sequence", "step", "prefix", "moving", "to", "inputs")


@dataclass
class _Figures:
    """The worst of what the steps measured, kept for the report."""

    max_vio: float = 0.0
    worst: str = ""
    max_pen: float = 0.0
    max_err: float = 0.0
    max_settle: float = 0.0
    dev: list[float] = field(default_factory=lambda: [0.0])


def _where(p: Piece, k: int, seq: list[dict[str, int]], moved: str) -> dict:
    """How the report names step ``k`` of piece ``p``: its walk and step there (a prefix
    change: the piece's start step and its place on the way), the input moved, the inputs
    after it."""
    where = {"sequence": p.walk, "step": p.start + k - p.prefix, "moving": moved,
             "to": int(seq[k][moved]), "inputs": {n: int(v) for n, v in seq[k].items()}}
    if k <= p.prefix:  # on the way to the piece's start state
        where = {**where, "step": p.start, "prefix": k}
    return where


def _step_key(entry: dict) -> str:
    """A step's identity from a failure entry or a ``where``: its naming fields."""
    return repr(sorted((k, entry[k] if k != "inputs" else sorted(entry[k].items()))
                       for k in WHERE if k in entry))


def _judge_step(fails: _Failures, figs: _Figures, where: dict, r: MoveResult,
                binding: list[str], before: dict, after: dict, st: DynSettings,
                tolerance: float, stroke: float) -> list[str]:
    """Every check of one step, the one code path for the proof's run and for the finer
    re-run of its failing pieces: adds to ``fails`` and ``figs`` and returns the kinds this
    step failed on (sorted; counted, not only listed)."""
    was = dict(fails.counts)
    if r.max_violation > figs.max_vio:
        figs.max_vio, figs.worst = r.max_violation, r.worst_joint
    figs.max_pen = max(figs.max_pen, r.max_penetration)
    if not r.max_violation <= st.violation_limit:
        fails.add("solver", **where, message=f"solver error: joint {r.worst_joint} "
                  f"stretched {r.max_violation:.4g} mm (limit {st.violation_limit} mm)")
    for c in binding:
        fails.add("S·R overlap", **where, cell=c, message=f"MEMORY {c}: SET and RESET "
                  "pressed the lever from both sides at once (binds)")
    if r.max_penetration > st.penetration_limit:
        fails.add("contact", **where, message=f"a contact overrun by "
                  f"{r.max_penetration:.4g} mm (limit {st.penetration_limit} mm)")
    if not math.isfinite(r.settle_time):
        fails.add("settle", **where, message=f"not settled {st.settle_time} s after")
    else:
        figs.max_settle = max(figs.max_settle, r.settle_time)
    if r.servo_lag_end > tolerance * stroke:
        fails.add("stall", **where, message=f"input {where['moving']} ended "
                  f"{r.servo_lag_end:.3g} mm short of its target")
    for o, got in r.final.items():
        if o in r.reference:
            figs.max_err = max(figs.max_err, abs(got - float(r.reference[o][-1])))
    _judge_outputs(fails, where, r.final, r.outputs, before, after, tolerance, figs.dev)
    return sorted(k for k, n in fails.counts.items() if n != was.get(k, 0))


def prove_sequential_dynamic(design: Design, spec, lib: Library,
                             settings: DynSettings | None = None, tolerance: float = 0.05,
                             seed: int = 0, random_walks: int = 2,
                             progress: Callable[[int, int], None] | None = None,
                             sequences: list[list[dict[str, int]]] | None = None,
                             trace: TraceRecorder | None = None, jobs: int = 1,
                             scheduler: str | None = None,
                             record: list | None = None,
                             piece_steps: int | None = None,
                             recheck: bool = True) -> ProofReport:
    """Drive the pymunk scene through the same sequences (or the given input ``sequences``,
    each from the power-up inputs, run whole). A fresh scene starts at power-up for every
    case, so the cases are independent: ``jobs`` processes or the Dask cluster at
    ``scheduler`` run them (``mechc.proofs.parallel``), merged in the serial order. The
    generated walks are cut into pieces (``split_walks``, at most ``piece_steps`` changes
    each) so that processes share them evenly: a piece starts from power-up and first takes
    the shortest way to its start state (those prefix changes are judged too, labelled
    ``prefix``); the cut depends on the spec only, never on ``jobs``, so every run gives the
    same report. ``record`` (a list) receives each step's figures. Without ``settings``, the
    defaults with the circuit's settle allowance (``dyn_settings``). ``trace`` receives every
    body's pose at power-up and along every step (the walks then run whole, in this
    process). ``recheck``: the first ``RECHECK_MAX`` pieces holding a step that failed on a
    kind the solver may cause run again at twice the iterations (:func:`_recheck_pieces`;
    not with a trace); a piece passing every check there is proved there."""
    t0 = time.perf_counter()
    mech = design.mechanism
    st = settings or dyn_settings(design, lib)
    walks = (transition_tour(spec, seed=seed, random_walks=random_walks) if sequences is None
             else sequences)
    if sequences is None and trace is None:
        pieces = split_walks(spec, walks, piece_steps)
    else:
        pieces = [Piece(wi, 0, len(w) - 1, 0, w) for wi, w in enumerate(walks)]
    head = _Failures()  # what fails the design as a whole, listed first
    _synthesis_failures(head, design)
    done = prefix_steps = 0
    job = WalkJob(design, _types(design), st, trace)
    wants = [expected_after(spec, p.sequence) for p in pieces]
    cases = [(p.walk, p.sequence, want,
              expected_states(spec, p.sequence) if trace is not None else [])
             for p, want in zip(pieces, wants)]
    if trace is not None:  # the recorder lives in this process: the walks run here
        jobs, scheduler = 1, None
    weights = [len(p.sequence) - 1 for p in pieces]
    results = run_cases(run_walk, job, cases, lib, jobs, scheduler, progress, weights)
    judged: list[tuple[_Failures, _Figures]] = []  # per piece
    failing: dict[int, dict[str, list[str]]] = {}  # piece -> its steps a finer solver
    #                                                  setting may pass, and their kinds
    for pi, (p, want, steps) in enumerate(zip(pieces, wants, results)):
        fails, figs = _Failures(), _Figures()
        judged.append((fails, figs))
        for k, (r, where, kinds) in enumerate(_judge_piece(fails, figs, p, want, steps, st,
                                                           tolerance, mech.ctx.stroke),
                                              start=1):
            if record is not None:
                record.append({**where, "final": dict(r.final),
                               "max_violation_mm": r.max_violation,
                               "max_penetration_mm": r.max_penetration,
                               "settle_time_s": r.settle_time, "steps": r.steps,
                               "binding": steps[k - 1][1]})
            if RECHECKED & set(kinds):
                failing.setdefault(pi, {})[_step_key(where)] = kinds
            if k <= p.prefix:
                prefix_steps += 1
            else:
                done += 1
    report = ProofReport(
        level="dynamic", kind="sequential", passed=False, cases=done,
        coverage={"sequences": len(walks), "pieces": len(pieces), "prefix_steps": prefix_steps,
                  "seed": seed, "tolerance_fraction": tolerance},
        failure_count=0, failures=[], seconds=0.0)
    _tally(report, head, judged, st)
    if recheck and failing and trace is None:
        _recheck_pieces(design, lib, st, report, pieces, wants, failing, head, judged,
                        tolerance, jobs, scheduler, progress, sum(weights))
    report.seconds = round(time.perf_counter() - t0, 3)
    return report


def _judge_piece(fails: _Failures, figs: _Figures, p: Piece, want: list[dict],
                 steps: list, st: DynSettings, tolerance: float, stroke: float
                 ) -> Iterator[tuple[MoveResult, dict, list[str]]]:
    """Each step of piece ``p`` judged (:func:`_judge_step`) as its run ``steps`` gave it:
    yields its result, where it is and the kinds it failed on."""
    seq = p.sequence
    cur = {k: float(v) for k, v in seq[0].items()}
    for k, (r, binding) in enumerate(steps, start=1):
        moved = next(n for n in seq[k] if seq[k][n] != cur[n])
        where = _where(p, k, seq, moved)
        kinds = _judge_step(fails, figs, where, r, binding, want[k - 1], want[k], st,
                            tolerance, stroke)
        yield r, where, kinds
        cur[moved] = float(seq[k][moved])


def _tally(report: ProofReport, head: _Failures, judged: list[tuple[_Failures, _Figures]],
           st: DynSettings) -> None:
    """``report``'s verdict, failures and figures from the design's own failures ``head`` and
    each piece's: one code path for the proof and for the proof after its re-run proved
    pieces finer (:func:`_recheck_pieces`)."""
    items = list(head.items)
    counts = dict(head.counts)
    figs = _Figures()
    for f, g in judged:
        items += f.items[:max(0, MAX_LISTED - len(items))]
        for k, n in f.counts.items():
            counts[k] = counts.get(k, 0) + n
        if g.max_vio > figs.max_vio:
            figs.max_vio, figs.worst = g.max_vio, g.worst
        figs.max_pen = max(figs.max_pen, g.max_pen)
        figs.max_err = max(figs.max_err, g.max_err)
        figs.max_settle = max(figs.max_settle, g.max_settle)
        figs.dev[0] = max(figs.dev[0], g.dev[0])
    report.failure_count = sum(counts.values())
    report.passed = report.failure_count == 0
    report.failure_kinds = counts
    report.failures = items
    report.figures = {
        **report.figures,
        "max_position_error_fraction": round(figs.max_err, 6),
        "max_deviation_fraction": round(figs.dev[0], 6),
        "min_margin_fraction": round(0.5 - figs.dev[0], 6),
        "max_joint_violation_mm": round(figs.max_vio, 6), "worst_joint": figs.worst,
        "max_contact_overrun_mm": round(figs.max_pen, 6),
        "max_settle_time_s": round(figs.max_settle, 6), "settings": st.to_json()}


def _recheck_pieces(design: Design, lib: Library, st: DynSettings, report: ProofReport,
                    pieces: list[Piece], wants: list[list[dict]],
                    failing: dict[int, dict[str, list[str]]], head: _Failures,
                    judged: list[tuple[_Failures, _Figures]], tolerance: float, jobs: int,
                    scheduler: str | None, progress: Callable[[int, int], None] | None,
                    done_before: int) -> None:
    """Run the first ``RECHECK_MAX`` ``failing`` pieces (piece index -> the keys of its steps
    that failed on solver, contact or settle, and the kinds each failed on) again, whole and
    from power-up as before, at twice ``st``'s iterations, and prove them there. A piece runs
    whole because its state at a step is the walk's up to it. A piece whose every step passes
    there failed by the solver: its finer run replaces its first in ``judged`` and ``report``
    is tallied again (``head``: the design's own failures), so its failures are gone and
    ``recheck`` lists its steps that had failed. In a piece that still fails, each failure
    entry of such a step gains ``finer`` (what the re-run gave; a step may pass there in a
    piece that does not). The figures' ``recheck`` counts steps: ``passed_finer`` those
    proved, ``passed_unproved`` those passing in a piece that does not. ``progress`` goes
    on from ``done_before`` steps."""
    chosen = sorted(failing)[:RECHECK_MAX]
    finer = replace(st, iterations=2 * st.iterations)
    job = WalkJob(design, _types(design), finer, None)
    cases = [(pieces[i].walk, pieces[i].sequence, wants[i], []) for i in chosen]
    weights = [len(pieces[i].sequence) - 1 for i in chosen]

    def tick(done: int, total: int) -> None:
        if progress is not None:
            progress(done_before + done, done_before + total)

    results = run_cases(run_walk, job, cases, lib, jobs, scheduler, tick, weights)
    by_step: dict[str, dict] = {}
    proved: list[dict] = []
    for i, steps in zip(chosen, results):
        fails, figs = _Failures(), _Figures()
        mine: list[dict] = []
        for r, where, kinds in _judge_piece(fails, figs, pieces[i], wants[i], steps, finer,
                                            tolerance, design.mechanism.ctx.stroke):
            if (key := _step_key(where)) in failing[i]:
                by_step[key] = finer_entry(finer.iterations, kinds, r.max_violation,
                                           r.max_penetration, r.settle_time)
                mine.append({**where, "failure_kinds_at_settings": failing[i][key],
                             **by_step[key]})
        for x in mine:
            by_step[_step_key(x)]["piece_passed"] = fails.total == 0
        if fails.total == 0:  # the whole piece passes finer: proved there
            judged[i] = (fails, figs)
            proved += mine
    if proved:
        _tally(report, head, judged, st)
    for f in report.failures:
        if "sequence" in f and (key := _step_key(f)) in by_step:
            f["finer"] = by_step[key]
    failed = sum(not x["passed"] for x in by_step.values())
    report.figures["recheck"] = {
        "iterations": finer.iterations, "changes": len(by_step), "passed_finer": len(proved),
        "failed_finer": failed, "passed_unproved": len(by_step) - len(proved) - failed,
        "not_rechecked": sum(len(failing[i]) for i in failing if i not in set(chosen)),
        "cap": RECHECK_MAX, "proved_finer": proved[:MAX_LISTED]}
