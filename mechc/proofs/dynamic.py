"""Dynamic level: the pymunk scene driven through input changes, measured against the spec
and against the closed-form (kinematic) positions.

Cases: a Gray-code tour that visits every input vector (each step one input change) followed by
``extra`` seeded random single-input changes. Per change the proof fails when: an output at
rest is not within ``tolerance`` of the value the spec asks for; an output the change must not
move leaves that margin on the way (a glitch); the scene does not settle in time; an input's
actuator cannot bring its slider to the target (stall); a bilateral joint stretches beyond its
limit or a contact is overrun beyond its limit ("solver error" — pymunk stretches joints
silently when overdriven or stepped too coarsely, so this is never passed).

Each change starts on a scene built at rest in its start state (a combinational circuit's rest
is a function of its inputs), so the changes are independent cases: ``jobs`` processes or a Dask
cluster run them (``mechc.proofs.parallel``) and the report is the serial run's, case by case.
With ``prune`` each change runs on a scene of only the cells that can move the outputs
(``mechc.proofs.prune``); off by default, see docs/performance.md for why. The first
``RECHECK_MAX`` changes failing on solver, contact or settle run again at twice the iterations
(:func:`recheck_failures`): one that passes every check there failed by the solver, is proved
there and counts as passed; the report says which.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from mechc.cells.library import Library
from mechc.errors import UsageError
from mechc.ir.design import Design
from mechc.ir.spec import Spec
from mechc.logic.cubes import DC
from mechc.physics.measures import CheckStats
from mechc.physics.scene import DynSettings, MoveResult, Scene
from mechc.proofs.accuracy import HALVING_CASES, ErrorModel, choose, confirm, load_model
from mechc.proofs.cases import gray_tour, random_walk, try_directed
from mechc.proofs.kinematic import sweep
from mechc.proofs.parallel import run_cases
from mechc.proofs.prune import FREEZE, blocker, run_case
from mechc.proofs.registry import OnProgress, check_interface, engine
from mechc.proofs.report import ProofReport
from mechc.proofs.settings import ProofSettings, dyn_settings
from mechc.proofs.trace import TraceRecorder

MAX_LISTED = 50
PRUNE_DEFAULT = False  # per-change pruned scenes (mechc.proofs.prune); see docs/performance.md
#: Failure kinds that can be the solver's rather than the mechanism's: a change failing on one
#: of them is run again at twice the solver iterations (:func:`recheck_failures`).
RECHECKED = frozenset({"solver", "contact", "settle"})
#: The failure kinds of one change (a design check belongs to the mechanism, not a change).
CHANGE_KINDS = ("rest", "glitch", "settle", "stall", "solver", "contact")
#: At most this many failing changes are run again (the first in plan order): each costs about
#: twice a change at the proof's own settings.
RECHECK_MAX = 6


def plan(n: int, extra: int, seed: int) -> list[int]:
    """Input vectors to visit in order, starting from all inputs off."""
    if n > 10:  # a full tour is too long (and never built: 2**n entries): a random walk
        return random_walk(n, 0, max(extra, 64), seed)
    tour = gray_tour(n)[1:]
    walk = random_walk(n, tour[-1] if tour else 0, extra, seed)
    return tour + walk


def plan_changes(design: Design, names: list[str], extra: int, seed: int,
                 independent: bool) -> tuple[list[tuple[int, int]], dict | None]:
    """The changes to run as (from vector, to vector) pairs, and what chose them. Up to 10
    inputs (or when each change cannot be a case of its own): :func:`plan`'s walk. Beyond,
    for a design whose changes are independent cases: the changes that switch every cell
    (:func:`mechc.proofs.cases.directed_changes`), then :func:`plan`'s random walk."""
    n = len(names)
    walk = plan(n, extra, seed)
    pairs = list(zip([0, *walk], walk))
    dr = try_directed(design.netlist, names, seed) if n > 10 and independent else None
    if dr is None:
        return pairs, None
    first = []
    for j in range(len(dr.k)):
        lo = sum(int(dr.lo[i, j]) << (n - 1 - i) for i in range(n))
        first.append((lo, lo | 1 << (n - 1 - int(dr.k[j]))))
    return first + pairs, dr.coverage()


@engine("dynamic", "combinational")
def dynamic_engine(design: Design, spec: Spec, lib: Library, settings: ProofSettings,
                   progress: OnProgress | None) -> ProofReport:
    """At the solver options given, or with ``accuracy`` at the cheapest settings meeting it."""
    if settings.accuracy is not None:
        return prove_with_accuracy(design, spec, lib, settings.accuracy,
                                   tolerance=settings.tolerance, extra=settings.cases,
                                   seed=settings.seed, progress=progress, prune=settings.prune,
                                   trace=settings.trace, jobs=settings.jobs,
                                   scheduler=settings.scheduler, hold=settings.hold)
    st = dyn_settings(design, lib, dt=settings.dt, iterations=settings.iterations,
                      move_time=settings.move_time, hold=settings.hold,
                      progress=progress)
    return prove_dynamic(design, spec, lib, st, tolerance=settings.tolerance,
                         extra=settings.cases, seed=settings.seed, progress=progress,
                         prune=settings.prune or PRUNE_DEFAULT, trace=settings.trace,
                         jobs=settings.jobs, scheduler=settings.scheduler,
                         recheck=settings.recheck)


@dataclass
class ChangeJob:
    """What every change of one dynamic proof needs (sent once to each worker)."""

    design: Design
    names: list[str]  # inputs, most significant bit first
    types: dict[str, str]  # cell id -> library cell
    settings: DynSettings
    cells: list[str] | None  # the scene's cells (None: all)
    prune: bool
    freeze: str | None
    trace: TraceRecorder | None  # only when the changes run in this process


@dataclass
class Change:
    """One input change: from input vector ``cur`` to ``vec`` (one input differs), with the
    outputs the spec asks for before and after it (for a trace)."""

    cur: int
    vec: int
    before: dict[str, int]
    after: dict[str, int]


@dataclass
class ChangeRun:
    """What one change gave: the move, and the scene it ran on."""

    result: MoveResult
    scene: dict | None = None  # the whole scene's size
    size: tuple[int, int, int] | None = None  # a pruned scene: cells, dynamic bodies, constraints
    escalated: bool = False
    watch_deviation: float = 0.0


def run_segment(job: ChangeJob, lib: Library, changes: list[Change]) -> list[ChangeRun]:
    """Run ``changes`` in order on one scene built at rest in the first one's start state
    (a pruned scene per change with ``job.prune``)."""
    mech, names, n = job.design.mechanism, job.names, len(job.names)
    state = _vec(changes[0].cur, names) if changes else {}
    state = {k: float(v) for k, v in state.items()}
    scene = None
    out: list[ChangeRun] = []
    for ch in changes:
        k = n - ((ch.cur ^ ch.vec).bit_length())
        name = names[k]
        target = float((ch.vec >> (n - 1 - k)) & 1)
        if job.prune:
            run = run_case(job.design.netlist, mech, lib, job.types, job.settings, state, name,
                           target, freeze=job.freeze)
            out.append(ChangeRun(_lean(run.result), size=(run.cells, run.bodies,
                                                           run.constraints),
                                 escalated=run.escalated, watch_deviation=run.watch_deviation))
        else:
            if scene is None:
                scene = Scene.build(mech, lib, job.types, job.settings, dict(state), job.cells)
                scene.sink = job.trace
            tr = job.trace
            if tr is not None:
                tr.begin("change", name, _vec(ch.cur, names), _vec(ch.vec, names), ch.before,
                         ch.after)
            r = scene.move(name, target)
            if tr is not None:
                tr.end()
            out.append(ChangeRun(_lean(r), scene=_scene_json(scene, [])))
        state[name] = target
    return out


def _lean(r: MoveResult) -> MoveResult:
    """The move without what the proof does not read (sample times, watched sliders), so a
    worker sends less back."""
    r.t = np.zeros(0)
    r.watched = {}
    return r


@dataclass
class ChangeCheck:
    """What one change's checks found: its failures (``kind`` and what was measured, without
    the change's inputs) and the figures the report keeps the worst of."""

    failures: list[dict]
    error: float  # the largest distance of an output at rest from its closed-form rest
    deviation: float  # the largest distance of an output from the spec (at rest or held)


def check_change(r: MoveResult, ch: Change, moving: str, st: DynSettings, tolerance: float,
                 stroke: float) -> ChangeCheck:
    """Every check of one change, the one code path for the proof's run and for the finer
    re-run of its failures (:func:`recheck_failures`)."""
    out: list[dict] = []
    err = dev_max = 0.0
    if r.max_violation > st.violation_limit or not math.isfinite(r.max_violation):
        out.append({"kind": "solver", "message": f"solver error: joint {r.worst_joint} "
                    f"stretched {r.max_violation:.4g} mm (limit {st.violation_limit} mm)"})
    if r.max_penetration > st.penetration_limit:
        out.append({"kind": "contact", "message": f"solver error: a contact overrun by "
                    f"{r.max_penetration:.4g} mm (limit {st.penetration_limit} mm)"})
    if not math.isfinite(r.settle_time):
        out.append({"kind": "settle", "message": f"not settled {st.settle_time} s after the "
                    "move"})
    lag = r.servo_lag_end if hasattr(r, "servo_lag_end") else None
    if lag is not None and lag > tolerance * stroke:
        out.append({"kind": "stall", "message": f"input {moving} ended {lag:.3g} mm short of "
                    "its target"})
    for o, want in ch.after.items():
        was = ch.before[o]
        got = r.final.get(o)
        if got is None:
            continue
        ref_end = float(r.reference[o][-1]) if o in r.reference else got
        err = max(err, abs(got - ref_end))
        if want != DC:
            dev = abs(got - want)
            dev_max = max(dev_max, dev)
            if dev > tolerance or not math.isfinite(dev):
                out.append({"kind": "rest", "output": o, "expected": want,
                            "position": round(got, 6)})
        if want != DC and want == was and o in r.outputs:
            glitch = float(np.max(np.abs(r.outputs[o] - want)))
            dev_max = max(dev_max, glitch)
            if glitch > tolerance:
                out.append({"kind": "glitch", "output": o, "expected": want,
                            "max_deviation": round(glitch, 6)})
    return ChangeCheck(out, err, dev_max)


def prove_dynamic(design: Design, spec: Spec, lib: Library, settings: DynSettings | None = None,
                  tolerance: float = 0.05, extra: int = 16, seed: int = 0,
                  progress: Callable[[int, int], None] | None = None,
                  cells: list[str] | None = None, prune: bool = PRUNE_DEFAULT,
                  max_cases: int | None = None, record: list | None = None,
                  freeze: str | None = None, trace: TraceRecorder | None = None,
                  jobs: int = 1, scheduler: str | None = None,
                  only: list[int] | None = None, recheck: bool = True) -> ProofReport:
    """Every change is a case of its own: it runs on a scene built at rest (the closed form)
    in its start state, so cases can run on ``jobs`` processes or on the Dask cluster at
    ``scheduler`` (:mod:`mechc.proofs.parallel`) and the report is the serial one, case by
    case. ``prune``: that scene holds only what can move the outputs (``mechc.proofs.prune``);
    else the whole mechanism (or ``cells``). A design with a stateful cell runs the whole
    tour on one scene (its rest depends on the past), in this process. ``max_cases`` keeps
    the first changes of the plan only, ``only`` the changes of the plan at these indices
    (the screened proof, ``mechc.proofs.screen``); ``record`` (a list) receives each change's
    inputs, final output positions and measures (for step-halving checks and the screen);
    ``freeze``: which still bodies a pruned
    scene holds static (``mechc.proofs.prune.build_scene``; default ``prune.FREEZE``).
    ``recheck``: the changes failing on a kind the solver may cause run again at twice the
    iterations (:func:`recheck_failures`; not on one scene nor with a trace); one passing
    every check there is proved there and counts as passed."""
    t0 = time.perf_counter()
    st = settings or dyn_settings(design, lib)
    if design.mechanism is None:
        raise UsageError("the design has no geometry (compile it with this mechc version)")
    check_interface(design.netlist, spec)
    mech = design.mechanism
    names = list(spec.inputs)
    n = len(names)
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    why_not = None if prune and cells is None else "not requested"
    if why_not is None:
        why_not = blocker(design.netlist, lib)
    prune = why_not is None
    if prune and trace is not None:
        raise UsageError("a pose trace records the whole scene: it cannot be taken with "
                         "per-change pruned scenes (--prune)")
    sizes: list[tuple[int, int, int]] = []  # pruned scenes: (cells, dynamic bodies, constraints)
    escalated = 0
    max_watch = 0.0
    # a circuit whose rest depends on its past (a stateful cell) runs the whole tour on one
    # scene; otherwise every change is a case of its own, on a scene built at its start
    one_scene = blocker(design.netlist, lib) is not None
    pairs, chosen = plan_changes(design, names, extra, seed, independent=not one_scene)
    if max_cases is not None:
        pairs = pairs[:max_cases]
    if only is not None:
        pairs = [pairs[i] for i in only]
    vectors = [vec for _, vec in pairs]

    job = ChangeJob(design, names, types, st, cells, prune, freeze, trace)
    changes = _changes(spec, names, pairs)
    segments = [changes] if one_scene else [[c] for c in changes]
    if trace is not None:  # the recorder lives in this process: the changes run here
        jobs, scheduler = 1, None
    runs = [run for seg in run_cases(run_segment, job, segments, lib, jobs, scheduler, progress,
                                     [len(seg) for seg in segments])
            for run in seg]
    steps = 0
    outcomes: list[dict] = []  # each change's failures and measures (recheck_failures)
    for ch, run in zip(changes, runs):
        r = run.result
        if prune:
            sizes.append(run.size)
            escalated += run.escalated
            max_watch = max(max_watch, run.watch_deviation)
        steps += r.steps
        case = _case(ch, names)
        found = check_change(r, ch, case["moving"], st, tolerance, mech.ctx.stroke)
        outcome = _outcome(ch, case, r, found)
        outcomes.append(outcome)
        if record is not None:
            record.append({**outcome, "final": dict(r.final), "steps": r.steps,
                           "servo_lag_end_mm": r.servo_lag_end,
                           "held_deviation": {o: float(np.max(np.abs(r.outputs[o] - b)))
                                              for o in spec.outputs if o in r.outputs
                                              and (b := ch.before[o]) != DC
                                              and b == ch.after[o]}})
    stats = CheckStats(mech)
    sweep(design, lib, samples=5, stats=stats)
    kin_checks = stats.checks() + mech.synthesis_checks()
    mus = [c.value for c in kin_checks if c.name == "transmission angle"]
    bad_checks = [c for c in kin_checks if not c.passed]
    failures, counts, fig = tally(outcomes)
    checks = [{"kind": "design check", "check": c.name, "where": c.where,
               "value": round(c.value, 6), "limit": c.limit, "message": c.text()}
              for c in bad_checks]
    total_fail = sum(counts.values()) + len(bad_checks)
    report = ProofReport(
        level="dynamic", kind="combinational", passed=total_fail == 0, cases=len(vectors),
        coverage={"tour": min(len(vectors), (1 << n) - 1) if n <= 10 else 0,
                  "random_changes": extra, "seed": seed, "tolerance_fraction": tolerance,
                  # beyond 10 inputs a sample: of how many single-input changes, chosen how
                  **({"exhaustive": False, "transitions": len(pairs),
                      "transitions_total": n << (n - 1), **(chosen or {})} if n > 10 else {})},
        failure_count=total_fail, failure_kinds={k: v for k, v in counts.items() if v},
        failures=(failures + checks)[:MAX_LISTED],
        figures={
            **fig,
            "min_transmission_angle_deg": round(min(mus), 4) if mus else None,
            "steps": steps,
            "scene": (_scene_json(None, sizes) if prune else runs[0].scene if runs
                      else _scene_json(Scene.build(mech, lib, types, st,
                                                   {k: 0.0 for k in names}, cells), [])),
            "pruning": _pruning_json(why_not, sizes, escalated, max_watch, len(mech.order),
                                     freeze),
            "settings": st.to_json(),
        },
        seconds=0.0)
    if recheck and report.failure_count and not one_scene and trace is None:
        recheck_failures(design, spec, lib, st, report, outcomes, tolerance, prune=prune,
                         cells=cells, freeze=freeze, jobs=jobs, scheduler=scheduler,
                         progress=progress, done_before=len(changes))
    report.seconds = round(time.perf_counter() - t0, 4)
    return report


def _outcome(ch: Change, case: dict, r: MoveResult, found: ChangeCheck) -> dict:
    """One change as the report is tallied from it (:func:`tally`): its failures and the
    measures its figures take the worst of."""
    return {**case, "pair": (ch.cur, ch.vec),
            "failures": [{"kind": f["kind"], **case,
                          **{k: v for k, v in f.items() if k != "kind"}}
                         for f in found.failures],
            "failure_kinds": sorted({f["kind"] for f in found.failures}),
            "max_violation_mm": r.max_violation, "worst_joint": r.worst_joint,
            "max_penetration_mm": r.max_penetration, "settle_time_s": r.settle_time,
            "error": found.error, "deviation": found.deviation}


def tally(outcomes: list[dict]) -> tuple[list[dict], dict[str, int], dict]:
    """The failures listed (the first ``MAX_LISTED``), the count of each kind and the figures
    of a run of the changes ``outcomes`` (:func:`_outcome`): one code path for the proof and
    for the proof after a re-run proved changes finer (:func:`recheck_failures`)."""
    counts = dict.fromkeys(CHANGE_KINDS, 0)
    failures: list[dict] = []
    for o in outcomes:
        for f in o["failures"]:
            counts[f["kind"]] += 1
            if len(failures) < MAX_LISTED:
                failures.append(f)
    # a NaN stretch (a diverged run) fails its change but is no figure
    worst = max((o for o in outcomes if not math.isnan(o["max_violation_mm"])),
                key=lambda o: o["max_violation_mm"], default=None)
    dev = max((o["deviation"] for o in outcomes), default=0.0)
    fig = {"max_position_error_fraction": round(max((o["error"] for o in outcomes),
                                                    default=0.0), 6),
           "max_deviation_fraction": round(dev, 6),
           "min_margin_fraction": round(0.5 - dev, 6),
           "max_joint_violation_mm": round(worst["max_violation_mm"], 6) if worst else 0.0,
           "worst_joint": worst["worst_joint"] if worst and worst["max_violation_mm"] > 0
           else "",
           "max_contact_penetration_mm": round(max((o["max_penetration_mm"] for o in outcomes),
                                                   default=0.0), 6),
           "max_settle_time_s": round(max((o["settle_time_s"] for o in outcomes
                                           if math.isfinite(o["settle_time_s"])),
                                          default=0.0), 5)}
    return failures, counts, fig


def finer_entry(iterations: int, kinds: list[str], violation: float, penetration: float,
                settle: float) -> dict:
    """What a re-run at finer settings gave for one change or step, as the report keeps it
    (``finer`` on a failure, an entry of ``recheck.proved_finer``)."""
    return {"iterations": iterations, "passed": not kinds, "failure_kinds": kinds,
            "max_violation_mm": round(violation, 6), "max_penetration_mm": round(penetration, 6),
            "settle_time_s": round(settle, 5) if math.isfinite(settle) else None}


def recheck_failures(design: Design, spec: Spec, lib: Library, st: DynSettings,
                     report: ProofReport, outcomes: list[dict], tolerance: float,
                     prune: bool = False, cells: list[str] | None = None,
                     freeze: str | None = None, jobs: int = 1, scheduler: str | None = None,
                     progress: Callable[[int, int], None] | None = None,
                     done_before: int = 0) -> None:
    """Run the first ``RECHECK_MAX`` distinct changes of ``outcomes`` (every change the proof
    ran, :func:`_outcome`, in plan order) that failed on a joint stretch, contact overrun or
    late settle again at twice ``st``'s iterations, on the same kind of scene, and prove them
    there. A change that passes every check at the finer setting failed by the solver: it
    counts as passed, ``report``'s failures, counts, figures and verdict are tallied again
    with its finer run in place of its first one, and ``recheck`` in the figures lists it. A
    change that still fails keeps its failures, each gaining ``finer`` (what the re-run
    gave). ``progress`` goes on from ``done_before`` changes."""
    failing = [o["pair"] for o in outcomes if RECHECKED & set(o["failure_kinds"])]
    distinct = list(dict.fromkeys(failing))
    chosen = distinct[:RECHECK_MAX]
    if not chosen:
        return
    names = list(spec.inputs)
    finer = replace(st, iterations=2 * st.iterations)
    types = {c.id: c.cell for c in design.netlist.cells.values()}
    job = ChangeJob(design, names, types, finer, cells, prune, freeze, None)
    changes = _changes(spec, names, chosen)

    def tick(done: int, total: int) -> None:
        if progress is not None:
            progress(done_before + done, done_before + total)

    runs = [seg[0] for seg in run_cases(run_segment, job, [[c] for c in changes], lib, jobs,
                                        scheduler, tick, [1] * len(changes))]
    again: dict[tuple[int, int], dict] = {}  # pair -> its finer outcome
    for ch, run in zip(changes, runs):
        case = _case(ch, names)
        again[(ch.cur, ch.vec)] = _outcome(ch, case, run.result, check_change(
            run.result, ch, case["moving"], finer, tolerance, design.mechanism.ctx.stroke))

    def summary(o: dict) -> dict:
        return finer_entry(finer.iterations, o["failure_kinds"], o["max_violation_mm"],
                           o["max_penetration_mm"], o["settle_time_s"])

    proved = {pair for pair, o in again.items() if not o["failures"]}
    if proved:  # the report as if those changes had run finer from the start
        merged = [again[o["pair"]] if o["pair"] in proved else o for o in outcomes]
        failures, counts, fig = tally(merged)
        checks = [f for f in report.failures if f.get("kind") == "design check"]
        n_checks = report.failure_count - sum((report.failure_kinds or {}).values())
        report.failure_count = sum(counts.values()) + n_checks
        report.failure_kinds = {k: v for k, v in counts.items() if v}
        report.failures = (failures + checks)[:MAX_LISTED]
        report.figures.update(fig)
        report.passed = report.failure_count == 0
    by_case = {repr({k: o[k] for k in ("inputs", "moving", "to")}): summary(o)
               for o in again.values()}
    for f in report.failures:
        if "inputs" in f:
            key = repr({k: f.get(k) for k in ("inputs", "moving", "to")})
            if key in by_case:
                f["finer"] = by_case[key]
    first = {o["pair"]: o for o in reversed(outcomes)}  # each change's run at st
    report.figures["recheck"] = {
        "iterations": finer.iterations, "changes": len(chosen), "passed_finer": len(proved),
        "failed_finer": len(chosen) - len(proved), "not_rechecked": len(distinct) - len(chosen),
        "cap": RECHECK_MAX,
        "proved_finer": [{**{k: first[p][k] for k in ("inputs", "moving", "to")},
                          "failure_kinds_at_settings": first[p]["failure_kinds"],
                          **summary(again[p])} for p in chosen if p in proved]}


def prove_with_accuracy(design: Design, spec: Spec, lib: Library, target: float,
                        model: ErrorModel | None = None, trace: TraceRecorder | None = None,
                        hold: float | None = None, **kw) -> ProofReport:
    """``prove_dynamic`` at the cheapest settings meeting ``target``
    (:mod:`mechc.proofs.accuracy`), confirmed on the run; the report says which settings, what
    error was obtained, and fails if it was not met. ``trace`` records the proof's run (not
    the step-halving check's)."""
    model = model or load_model()
    point = choose(target, model)
    st = dyn_settings(design, lib, dt=point.dt, iterations=point.iterations,
                      move_time=point.move_time, hold=hold, progress=kw.get("progress"))
    coarse: list[dict] = []
    # no re-run at finer settings: the accuracy check chose these, and confirms them below
    report = prove_dynamic(design, spec, lib, st, record=coarse, trace=trace, recheck=False,
                           **kw)
    half = replace(st, dt=st.dt / 2)
    fine: list[dict] = []
    kw_half = {k: v for k, v in kw.items() if k != "progress"}
    prove_dynamic(design, spec, lib, half, record=fine, max_cases=HALVING_CASES, recheck=False,
                  **kw_half)
    check = confirm(target, report, coarse[:HALVING_CASES], fine)
    check["chosen"] = {"dt_s": point.dt, "iterations": point.iterations,
                       "move_time_s": point.move_time, "model_error_fraction": point.error,
                       "cost_per_change": round(point.cost(model.overhead_iterations), 1)}
    report.accuracy = check
    if not check["confirmed"]:
        report.add_failure(
            "accuracy",
            f"accuracy not confirmed: obtained {check['obtained_fraction']:.4g} of stroke "
            f"(closed form {check['error_vs_closed_form_fraction']:.4g}, step halving "
            f"{check['halving_estimate_fraction']:.4g}) against the requested {target:g}")
    return report


def _changes(spec: Spec, names: list[str], pairs: list[tuple[int, int]]) -> list[Change]:
    """The changes from vector ``cur`` to ``vec``, with the outputs the spec asks for before
    and after each."""
    n = len(names)

    def columns(vs: list[int]) -> np.ndarray:
        return np.array([[(v >> (n - 1 - k)) & 1 for k in range(n)] for v in vs],
                        dtype=bool).reshape(len(vs), n).T

    before = spec.values_at(columns([cur for cur, _ in pairs]))
    after = spec.values_at(columns([vec for _, vec in pairs]))
    return [Change(cur, vec, {o: int(before[o][i]) for o in spec.outputs},
                   {o: int(after[o][i]) for o in spec.outputs})
            for i, (cur, vec) in enumerate(pairs)]


def _case(ch: Change, names: list[str]) -> dict:
    """How the report names a change: the inputs after it, the input that moved, and to what."""
    n = len(names)
    k = n - (ch.cur ^ ch.vec).bit_length()
    return {"inputs": _vec(ch.vec, names), "moving": names[k],
            "to": int((ch.vec >> (n - 1 - k)) & 1)}


def _scene_json(scene: Scene | None, sizes: list[tuple[int, int, int]]) -> dict:
    """The whole scene's size, or the largest pruned scene's."""
    if scene is not None:
        return {"bodies": len(scene.bodies), "joints": len(scene.joints),
                "constraints": len(scene.space.constraints), "cells": len(scene.cells)}
    big = max(sizes, key=lambda x: x[2], default=(0, 0, 0))
    return {"bodies": big[1], "constraints": big[2], "cells": big[0], "largest_of": len(sizes)}


def _pruning_json(why_not: str | None, sizes: list[tuple[int, int, int]], escalated: int,
                  max_watch: float, cells: int, freeze: str | None = None) -> dict:
    if why_not is not None:
        return {"enabled": False, "reason": why_not}
    a = np.array(sizes, dtype=float).reshape(-1, 3)
    return {"enabled": True, "circuit_cells": cells, "freeze": freeze or FREEZE,
            "mean_cells": round(float(a[:, 0].mean()), 3) if len(a) else 0.0,
            "mean_dynamic_bodies": round(float(a[:, 1].mean()), 3) if len(a) else 0.0,
            "mean_constraints": round(float(a[:, 2].mean()), 3) if len(a) else 0.0,
            "escalated_cases": escalated, "max_watch_deviation_fraction": round(max_watch, 6)}


def _vec(row: int, names: list[str]) -> dict[str, int]:
    n = len(names)
    return {nm: int((int(row) >> (n - 1 - k)) & 1) for k, nm in enumerate(names)}
