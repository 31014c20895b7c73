"""Screened level: the dynamic proof's verdict, with pymunk run only on the input changes
the timing level cannot vouch for (the default proof of ``mechc simulate``).

The whole-scene dynamic proof (:mod:`mechc.proofs.dynamic`) stays the reference: the screen
runs its plan, its scenes and its checks, on fewer changes. Every change of the plan is timed
first (:mod:`mechc.proofs.timing`, no scene); a change is *cleared* only when, for every kind
of failure the dynamic proof can report, the screen models it with a stated margin:

- ``settle``: the latest predicted settle of any switching net, grown by ``SETTLE_MARGIN``
  (twice the timing model's worst *early* prediction over every change of the benchmark
  circuits' plans, ``benchmarks/screen.py``: a late prediction is on the safe side), is
  within the move and the hold.
- ``rest``: every output's closed-form end is within ``tolerance - REST_MARGIN`` of what the
  spec asks (a settled scene stands within ``SETTLED`` of its closed form: twice that).
- ``glitch``: every output that must hold is held by the logic whatever order its cells
  switch in (ternary simulation, the moving input unknown: no hazard under any delays), and
  its closed form along the move stays within ``tolerance`` less ``HELD_MARGIN_SHARE`` of it
  (the most a held output moved beyond its closed form on the benchmark circuits, x 1.5).
- ``solver``, ``contact``, ``stall``: *not modelled* by the timing level (joint stretch and
  contact overrun vary from change to change in ways the switching cells do not explain).
  Every (cell kind, direction) a cleared change switches is switched by a change that ran in
  pymunk (its *witness*), and those runs must leave a share of each limit free:
  ``JOINT_HEADROOM`` of the joint limit, ``CONTACT_HEADROOM`` of the contact limit. A
  headroom is the most a change reached beyond the mildest change switching any of its cell
  kinds alike (every witness the worst choice), as a share of the limit, over every change
  of the benchmark circuits, times 1.5. Stretch and overrun are mostly preload and
  compliance every change shows (the 2-bit adder's overrun is 0.13-0.16 mm on all its 47
  changes) plus a dynamic part: what a witness did not see is an *addition* to what it saw,
  not a multiple of it (a ratio on a witness far below the limit says nothing). The input's
  lag at the end keeps a factor, ``SOLVER_FACTOR``. These are measured margins, not bounds:
  a design whose changes come nearer a limit runs every change in pymunk.

Anything else goes to dynamics with its reason: a switching cell without a table or outside
the move times and loads its table measured, a switching cell driving more than ``HEAVY_KG``
(its stretch varies from change to change: such a change runs, witnesses nothing and
calibrates nothing), a held output with a possible hazard, small slack. A switching
AMPLIFIER is timed by its table measured as the design built it; its (geometry, direction)
must be switched by a change that ran, like every cell kind. What the model assumes is
checked on the changes that ran (the *calibration*): their measured settle no later than the
prediction by more than the model's error, held outputs' excess over the closed form within
half the least room the cleared changes leave on theirs (the tolerance less their closed
form's move, at least the held margin), joints and contacts within their headroom, the
servo's lag within the stall limit by ``SOLVER_FACTOR``. A change that fails a check
vouches for nothing: every cleared change it concerns runs in pymunk, namely those that
switch one of its (cell kind, direction) (it witnessed that kind for them: the headrooms
bound a cleared change only through changes that ran, switched its kinds alike and
passed), those moving the same input (its driver and the cells it moves
without switching them; a change that switches no cell has no other witness), and, for a
held output that moved too far, every cleared change that must hold that output. The
changes that fall back are checked in turn, and so on until no check fails: a cleared
change is left cleared only when every change that ran and shares a kind or its moving
input passed. A design that holds state (its rest depends on the past), a sequential
design, a run asked for a pose trace or for an accuracy: the whole dynamic proof, and the
report says so.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace

import numpy as np

from mechc.cells.characterise import SETTLED, CellTable
from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.ir.netlist import Netlist
from mechc.ir.seqspec import SeqSpec
from mechc.ir.spec import Spec
from mechc.ir.ternary import evaluate3
from mechc.logic.cubes import DC
from mechc.parts.pushrod import net_loads
from mechc.physics.scene import DynSettings
from mechc.proofs.dynamic import (
    RECHECK_MAX,
    dynamic_engine,
    finer_entry,
    plan_changes,
    prove_dynamic,
    recheck_failures,
)
from mechc.proofs.prune import blocker
from mechc.proofs.registry import OnProgress, check_interface, engine
from mechc.proofs.report import ProofReport
from mechc.proofs.seq_mechanism import sequential_dynamic_engine
from mechc.proofs.settings import ProofSettings, dyn_settings
from mechc.proofs.timing import cell_tables, predict_changes

#: The timing model's worst early prediction of a change's settle (the latest switching net,
#: what the screen reads; the whole scene settled later than predicted by this share of its
#: settle), over every change of the plans of the benchmark circuits a screen may clear (no
#: heavy cell; ``benchmarks/screen.py``'s ``settle_early_worst``): 18.4 % (random81, a change
#: settling 16 ms after the move; the 2-bit adder 12.4 %), rounded up. A late prediction is
#: safe for the screen. Heavy changes were up to 25.7 % early: they always run. (A change
#: a witness ran that settled later than this is caught by the calibration.) On random
#: circuits never used for it, cleared changes were up to 27.8 % early: inside the
#: 1 - 1 / (1 + SETTLE_MARGIN) = 28.6 % the settle margin tolerates, with little room; on 22
#: more, up to 19.6 %, and no cleared change used more than 0.11 of the hold after the move
#: (``cleared_settle_share``; docs/performance.md).
MODEL_ERROR = 0.20
#: Safety factor on that error: a change is cleared when its predicted settle times
#: ``1 + SETTLE_MARGIN`` is within the move and the hold.
SETTLE_MARGIN = 2.0 * MODEL_ERROR
#: A settled scene's outputs stand within SETTLED of the closed form; twice that.
REST_MARGIN = 2.0 * SETTLED
#: Share of the tolerance kept for the dynamics on an output that must hold: the most a held
#: output moved beyond its closed form on a change the screen may clear, over the benchmark
#: circuits, was 0.446 of the tolerance (0.0223 of stroke, random81; random23 0.41;
#: ``benchmarks/screen.py``), times 1.5, rounded up.
HELD_MARGIN_SHARE = 0.67
#: Share of the contact limit the changes that ran must leave free: on the benchmark
#: circuits, a change's overrun was up to 0.342 of the limit beyond the mildest change
#: switching any of its cell kinds alike (random23; every witness the mildest one), times
#: 1.5, rounded up.
CONTACT_HEADROOM = 0.52
#: Share of the joint limit the changes that ran must leave free: measured as the contact
#: headroom, 0.445 of the limit (random81, heavy changes aside), times 1.5, rounded up.
JOINT_HEADROOM = 0.7
#: A switching cell whose net is heavier than this (kg) sends its change to pymunk: the stretch
#: of such changes is not witnessed by another change switching the same kind alike
#: (random81's NOR4 gates driving 0.10-0.11 kg stretched 0.010-0.079 mm, up to 0.69 of the
#: limit apart, as the input that moved differed; ``benchmarks/screen.py``).
HEAVY_KG = 0.09
#: The changes that ran must stay below the stall limit (an input ending short) by this factor.
SOLVER_FACTOR = 6.0
#: Calibration checks a witness may pass at twice the iterations instead (the solver's error
#: is part of them: random81's witness stretched a joint 0.0348 mm at 60 iterations, 0.0175
#: mm at 120).
FINER_CHECKS = frozenset({"joint", "contact"})
#: Per-change decisions kept in the report.
MAX_LISTED = 200
#: Failed calibration checks listed in the report (all are counted).
MAX_FAILED = 50


@engine("screened", "combinational")
def screened_engine(design: Design, spec: Spec, lib: Library, settings: ProofSettings,
                    progress: OnProgress | None) -> ProofReport:
    """The dynamic proof's verdict with pymunk run only where the timing level cannot vouch."""
    why = None
    if settings.accuracy is not None:
        why = "--accuracy chooses the solver settings on the whole run"
    elif settings.trace is not None:
        why = "a pose trace records every change"
    elif settings.prune:
        why = "--prune asks for per-change pruned scenes"
    else:
        why = blocker(design.netlist, lib)  # a design that holds state, or None
    if why is not None:
        return _unscreened(dynamic_engine(design, spec, lib, settings, progress), why)
    return prove_screened(design, spec, lib, settings, progress)


@engine("screened", "sequential")
def seq_screened_engine(design: Design, spec: SeqSpec, lib: Library, settings: ProofSettings,
                        progress: OnProgress | None) -> ProofReport:
    """A sequential design: every transition runs in pymunk (the timing level does not
    model a memory's transitions; its ordering requirements are checked by the walk)."""
    return _unscreened(sequential_dynamic_engine(design, spec, lib, settings, progress),
                       "sequential: every transition runs in pymunk")


def _unscreened(rep: ProofReport, why: str) -> ProofReport:
    """The whole dynamic proof's report, saying why the screen was not applied."""
    rep.figures["screen"] = {"applied": False, "reason": why,
                             "text": f"screen not applied ({why}): every change ran in pymunk"}
    return rep


def prove_screened(design: Design, spec: Spec, lib: Library, settings: ProofSettings,
                   progress: OnProgress | None = None,
                   st: DynSettings | None = None) -> ProofReport:
    """See the module docstring. ``st``: physics settings other than ``settings`` makes
    (tests: a hold too short for the circuit)."""
    t0 = time.perf_counter()
    check_interface(design.netlist, spec)
    st = st or dyn_settings(design, lib, dt=settings.dt, iterations=settings.iterations,
                            move_time=settings.move_time, hold=settings.hold,
                            progress=progress)
    n = len(spec.inputs)
    pairs, timed, decisions = decide(design, spec, lib, settings, st, progress)
    budget = st.move_time + st.settle_time
    held_margin = HELD_MARGIN_SHARE * settings.tolerance
    run = [i for i, d in enumerate(decisions) if d["route"] == "dynamic"]
    record: list[dict] = []
    done_before = 0  # changes run by earlier rounds: a fallback's count goes on from them

    def tick(done: int, total: int) -> None:
        if progress is not None:
            progress(done_before + done, done_before + total)

    # the finer re-run of the failures comes once, after every round (recheck_failures below)
    kw = {"tolerance": settings.tolerance, "extra": settings.cases, "seed": settings.seed,
          "jobs": settings.jobs, "scheduler": settings.scheduler, "recheck": False}
    rep = prove_dynamic(design, spec, lib, st, progress=tick, only=run, record=record, **kw)
    for i, r in zip(run, record):
        decisions[i]["measured_settle_s"] = (round(r["settle_time_s"] + st.move_time, 5)
                                             if math.isfinite(r["settle_time_s"]) else None)
    # the room the cleared changes leave on their held outputs (at least held_margin each)
    room = min((d["held_room"] for d in decisions if d["route"] == "timing"),
               default=settings.tolerance)
    stroke = design.mechanism.ctx.stroke
    keys = [set(d["kinds"]) for d in decisions]
    failures = calibration_failures(decisions, timed, run, record, st, room,
                                    settings.tolerance, stroke)
    finer: list[dict] = []  # the witnesses that passed their calibration at finer settings
    tried = 0  # changes run again finer, at most RECHECK_MAX

    def finer_witnesses(failures: list[dict]) -> list[dict]:
        nonlocal done_before, tried
        done_before = len(run) + tried
        if not settings.recheck:  # --no-recheck: the verdict is the proof's settings' alone
            return failures
        left, got, n = witnesses_finer(design, spec, lib, st, decisions, timed, failures, room,
                                       settings, RECHECK_MAX - tried, tick)
        finer.extend(got)
        tried += n
        return left

    failures = finer_witnesses(failures)
    bad = [f["text"] for f in failures]
    ran = list(zip(run, record))  # every change run in pymunk and its record
    fell_back = 0
    while failures:
        # a failing change vouches for nothing: the cleared changes it concerns run, and
        # they are checked in turn (their failures may concern more)
        rest: dict[int, str] = {}
        for f in failures:
            for i in concerned(f, decisions, keys):
                rest.setdefault(i, f["text"])
        for i, text in rest.items():
            decisions[i]["route"] = "dynamic"
            decisions[i]["why"].append("calibration failed: " + text)
        if not rest:
            break
        more_rec: list[dict] = []
        again = sorted(rest)
        done_before = len(run) + tried
        more = prove_dynamic(design, spec, lib, st, progress=tick, only=again,
                             record=more_rec, **kw)
        for i, r in zip(again, more_rec):
            decisions[i]["measured_settle_s"] = (round(r["settle_time_s"] + st.move_time, 5)
                                                 if math.isfinite(r["settle_time_s"]) else None)
        rep = _merge(rep, more)
        ran += list(zip(again, more_rec))
        run = sorted(run + again)
        fell_back += len(again)
        failures = finer_witnesses(calibration_failures(decisions, timed, again, more_rec, st,
                                                        room, settings.tolerance, stroke))
        bad += [f["text"] for f in failures]
    if settings.recheck and rep.failure_count:  # as the dynamic proof does, in plan order
        recheck_failures(design, spec, lib, st, rep,
                         [r for _, r in sorted(ran, key=lambda x: x[0])], settings.tolerance,
                         jobs=settings.jobs, scheduler=settings.scheduler, progress=progress,
                         done_before=len(run) + tried)
    cleared = len(pairs) - len(run)
    # the cleared changes a witness run finer vouches for are cleared at its setting
    at_finer = sorted({i for w in finer for i in concerned(w, decisions, keys)})
    for i in at_finer:
        decisions[i]["witness_iterations"] = 2 * st.iterations
    text = (f"screen: {len(run)} of {len(pairs)} changes ran in pymunk, {cleared} cleared by "
            f"timing (cleared when predicted settle x {1 + SETTLE_MARGIN:g} <= "
            f"{budget:.3f} s, i.e. slack >= {SETTLE_MARGIN:.0%} of the settle)"
            + (f"; {len(finer)} witness(es) left too little headroom at {st.iterations} "
               f"iterations and passed at {2 * st.iterations}: the {len(at_finer)} cleared "
               f"changes they vouch for are proved at {2 * st.iterations} iterations"
               if at_finer else "")
            + (f"; calibration failed ({bad[0]}"
               + (f" and {len(bad) - 1} more" if len(bad) > 1 else "")
               + f"): {fell_back} changes it concerned ran too" if bad else ""))
    reasons: dict[str, int] = {}
    for d in decisions:
        if d["route"] == "dynamic":
            key = d["why"][0].split(":")[0] if d["why"] else "?"
            key = "slack" if key.startswith("slack") else key
            reasons[key] = reasons.get(key, 0) + 1
    rep.figures["screen"] = {
        "applied": True, "text": text, "changes": len(pairs), "dynamic": len(run),
        "cleared_by_timing": cleared, "budget_s": round(budget, 5),
        "settle_margin": SETTLE_MARGIN, "rest_margin_fraction": REST_MARGIN,
        "held_margin_fraction": held_margin, "joint_headroom": JOINT_HEADROOM,
        "contact_headroom": CONTACT_HEADROOM, "stall_factor": SOLVER_FACTOR,
        "held_room_fraction": round(room, 6),
        "calibration": bad[:MAX_FAILED] or "passed", "calibration_failures": len(bad),
        "witnessed_finer": finer, "cleared_finer": len(at_finer), "rerun_finer": tried,
        "fell_back": fell_back, "reasons": reasons,
        "decisions": decisions[:MAX_LISTED]}
    rep.level = "screened"
    rep.cases = len(pairs)
    rep.coverage = {**rep.coverage, "tour": min(len(pairs), (1 << n) - 1) if n <= 10 else 0,
                    **({"transitions": len(pairs)} if "transitions" in rep.coverage else {}),
                    "ran_in_pymunk": len(run), "cleared_by_timing": cleared}
    rep.seconds = round(time.perf_counter() - t0, 4)
    return rep


def decide(design: Design, spec: Spec, lib: Library, settings: ProofSettings, st: DynSettings,
           progress: OnProgress | None = None
           ) -> tuple[list[tuple[int, int]], list[dict], list[dict]]:
    """The dynamic proof's plan, each change timed, and each change's route (``dynamic`` or
    ``timing``) with the reasons it must run in pymunk. ``progress`` is told (done, total,
    what) while a cell's table is measured (first use; a cell timed as built, such as an
    AMPLIFIER, about a minute each)."""
    nl = design.netlist
    names = list(spec.inputs)
    n = len(names)
    pairs, _chosen = plan_changes(design, names, settings.cases, settings.seed,
                                  independent=True)
    tables, _tabs = cell_tables(design, lib, progress, names, pairs)
    timed = predict_changes(design, lib, names, pairs, st, tables, detail=True)
    before = spec.values_at(_columns([a for a, _ in pairs], n))
    after = spec.values_at(_columns([b for _, b in pairs], n))
    held_ok = held_by_logic(nl, names, pairs)
    budget = st.move_time + st.settle_time
    loads = net_loads(design.mechanism)
    kind = {c.id: _kind(c, tables.get(c.id)) for c in nl.cells.values()}
    held_margin = HELD_MARGIN_SHARE * settings.tolerance
    decisions: list[dict] = []
    for i, rec in enumerate(timed):
        why: list[str] = []
        sw = rec["switched"]
        untimed = sorted(c for c in sw if tables.get(c) is None)
        if untimed:
            why.append(f"no timing table for switching cell(s) {', '.join(untimed[:3])}")
        outside = sorted(c for c in sw if tables.get(c) is not None
                         and not _in_grid(tables[c], st.move_time,
                                          loads.get(nl.cells[c].outputs[0], 0.0)))
        if outside:
            why.append(f"switching cell(s) {', '.join(outside[:3])} outside their measured "
                       "move times or loads")
        heavy = sorted(c for c in sw if loads.get(nl.cells[c].outputs[0], 0.0) > HEAVY_KG)
        if heavy:
            why.append(f"heavy: switching cell(s) {', '.join(heavy[:3])} drive more than "
                       f"{HEAVY_KG:g} kg (joint stretch not witnessed)")
        need = rec["nets_settle_s"] * (1.0 + SETTLE_MARGIN)
        slack = budget - rec["nets_settle_s"]
        if need > budget:
            why.append(f"slack {slack:.4f} s < {SETTLE_MARGIN:.0%} of the predicted settle "
                       f"{rec['nets_settle_s']:.4f} s")
        room = settings.tolerance  # what the dynamics may add on its held outputs
        holds: list[str] = []
        for o in spec.outputs:
            want, was = int(after[o][i]), int(before[o][i])
            end = rec["closed_form_end"].get(o)
            if want == DC or end is None:
                continue
            if abs(end - want) > settings.tolerance - REST_MARGIN:
                why.append(f"{o}: closed-form rest {abs(end - want):.4f} from {want} (cleared "
                           f"within {settings.tolerance - REST_MARGIN:.4f})")
            if want == was:
                holds.append(o)
                if not held_ok[o][i]:
                    why.append(f"{o} must hold: a hazard is possible (ternary simulation)")
                dev = abs(end - want) + rec["closed_form_swing"][o]
                room = min(room, settings.tolerance - dev)
                if dev > settings.tolerance - held_margin:
                    why.append(f"{o} must hold: closed form moves {dev:.4f} (cleared within "
                               f"{settings.tolerance - held_margin:.4f})")
        decisions.append({"inputs": rec["inputs"], "moving": rec["moving"], "to": rec["to"],
                          "route": "dynamic" if why else "timing", "why": why,
                          "predicted_settle_s": round(rec["nets_settle_s"], 5),
                          "slack_s": round(slack, 5), "heavy": bool(heavy),
                          "held_room": round(room, 6), "holds": holds})
    # the cleared changes' cells (kind, direction) each switched by a change run in pymunk (a
    # heavy change witnesses nothing: its stretch is its own)
    covered = {(kind[c], d) for dec, rec in zip(decisions, timed)
               if dec["route"] == "dynamic" and not dec["heavy"]
               for c, d in rec["switched"].items()}
    need_cover = {(kind[c], d) for dec, rec in zip(decisions, timed) if dec["route"] == "timing"
                  for c, d in rec["switched"].items()} - covered
    while need_cover:
        best = max((i for i, d in enumerate(decisions) if d["route"] == "timing"),
                   key=lambda i: (len({(kind[c], d) for c, d in timed[i]["switched"].items()}
                                      & need_cover), -i))
        got = {(kind[c], d) for c, d in timed[best]["switched"].items()} & need_cover
        decisions[best]["route"] = "dynamic"
        decisions[best]["why"].append(f"witness: the first run of {len(got)} (cell kind, "
                                      "direction) the cleared changes switch")
        need_cover -= got
    # each change's (cell kind, direction) as short ids: what a calibration failure concerns
    ids = {k: j for j, k in enumerate(sorted(set(kind.values())))}
    for dec, rec in zip(decisions, timed):
        dec["kinds"] = sorted(f"{ids[kind[c]]}:{int(d)}" for c, d in rec["switched"].items())
    return pairs, timed, decisions


def calibration_failures(decisions: list[dict], timed: list[dict], run: list[int],
                         record: list[dict], st: DynSettings, held_margin: float,
                         tolerance: float, stroke: float) -> list[dict]:
    """Each disagreement of a change run in pymunk with the screen's model: ``change`` (its
    index), ``check`` (``joint``, ``contact``, ``stall``, ``settle`` or ``held``), ``text``
    and, for ``held``, the ``output``. ``held_margin``: the least room the cleared changes
    leave the dynamics on an output that must hold (the tolerance less its closed form's
    move); a held output of a change that ran must have moved beyond its closed form by at
    most half that."""
    bad: list[dict] = []
    for i, r in zip(run, record):
        where = f"change {i} ({decisions[i]['moving']} to {decisions[i]['to']})"
        if decisions[i].get("heavy"):
            continue  # outside the model (stretch, settle): the dynamic proof judges it alone

        def fail(check: str, text: str, i: int = i, where: str = where, **more) -> None:
            bad.append({"change": i, "check": check, "text": f"{where}: {text}", **more})

        if r["max_violation_mm"] > (1 - JOINT_HEADROOM) * st.violation_limit or \
                not math.isfinite(r["max_violation_mm"]):
            fail("joint", f"joint stretch {r['max_violation_mm']:.4g} mm leaves less than "
                 f"{JOINT_HEADROOM:.0%} of the limit {st.violation_limit:g} mm")
        if r["max_penetration_mm"] > (1 - CONTACT_HEADROOM) * st.penetration_limit:
            fail("contact", f"contact overrun {r['max_penetration_mm']:.4g} mm leaves less "
                 f"than {CONTACT_HEADROOM:.0%} of the limit {st.penetration_limit:g} mm")
        lag = r.get("servo_lag_end_mm", 0.0)
        if lag * SOLVER_FACTOR > tolerance * stroke:
            fail("stall", f"input ended {lag:.4g} mm short, within {SOLVER_FACTOR:g}x of the "
                 f"stall limit {tolerance * stroke:.4g} mm")
        s = r["settle_time_s"]
        pred = timed[i]["nets_settle_s"]
        if not math.isfinite(s) or (s > 0 and s + st.move_time > pred * (1 + MODEL_ERROR)):
            fail("settle", f"settled {s + st.move_time:.4f} s, predicted {pred:.4f} s (model "
                 f"error bound {MODEL_ERROR:.0%})")
        for o, dev in r.get("held_deviation", {}).items():
            cf = timed[i]["closed_form_swing"].get(o, 0.0)
            if dev - cf > held_margin / 2:
                fail("held", f"held output {o} moved {dev:.4f}, closed form {cf:.4f} (margin "
                     f"{held_margin:.4f})", output=o)
    return bad


def witnesses_finer(design: Design, spec: Spec, lib: Library, st: DynSettings,
                    decisions: list[dict], timed: list[dict], failures: list[dict],
                    room: float, settings: ProofSettings, cap: int,
                    progress: OnProgress | None = None
                    ) -> tuple[list[dict], list[dict], int]:
    """Run the changes whose calibration failed on joint stretch or contact overrun alone (the
    kinds the solver's error is part of; at most ``cap``, in plan order) again at twice the
    iterations, as the dynamic proof's re-run does (:func:`recheck_failures`). One that
    passes every calibration check there witnesses at that setting: its failures are dropped
    and the changes it vouches for stay cleared, proved at that setting. Returns the failures
    left, per such witness what each run gave, and how many changes ran again."""
    by: dict[int, list[dict]] = {}
    for f in failures:
        by.setdefault(f["change"], []).append(f)
    todo = sorted(i for i, fs in by.items() if all(f["check"] in FINER_CHECKS for f in fs))
    todo = todo[:max(cap, 0)]
    if not todo:
        return failures, [], 0
    finer = replace(st, iterations=2 * st.iterations)
    rec: list[dict] = []
    prove_dynamic(design, spec, lib, finer, progress=progress, only=todo, record=rec,
                  tolerance=settings.tolerance, extra=settings.cases, seed=settings.seed,
                  jobs=settings.jobs, scheduler=settings.scheduler, recheck=False)
    still = {f["change"] for f in calibration_failures(
        decisions, timed, todo, rec, finer, room, settings.tolerance,
        design.mechanism.ctx.stroke)}
    passed = {i: r for i, r in zip(todo, rec) if i not in still}
    got = [{"change": i, "moving": decisions[i]["moving"], "to": decisions[i]["to"],
            "failed_at_settings": [f["text"] for f in by[i]],
            **finer_entry(finer.iterations, [], r["max_violation_mm"],
                          r["max_penetration_mm"], r["settle_time_s"])}
           for i, r in passed.items()]
    return [f for f in failures if f["change"] not in passed], got, len(todo)


def concerned(failure: dict, decisions: list[dict], keys: list[set]) -> list[int]:
    """The cleared changes a calibration failure takes the vouching from: those sharing a
    (cell kind, direction) with the failing change (what it witnessed), those moving the same
    input (its driver and the cells it feeds without switching them: a change that switches
    no cell has no witness but these), and for a held output that moved too far, every
    cleared change that must hold that output."""
    w = failure["change"]
    mine, moving = keys[w], decisions[w]["moving"]
    out = failure.get("output")
    return [i for i, d in enumerate(decisions) if d["route"] == "timing"
            and (keys[i] & mine or d["moving"] == moving
                 or (out is not None and out in d.get("holds", [])))]


def _merge(a: ProofReport, b: ProofReport) -> ProofReport:
    """Two dynamic reports on disjoint changes of one plan as one."""
    kinds = dict(a.failure_kinds or {})
    for k, v in (b.failure_kinds or {}).items():
        kinds[k] = kinds.get(k, 0) + v
    fig = dict(a.figures)
    for k in ("max_position_error_fraction", "max_deviation_fraction",
              "max_contact_penetration_mm", "max_settle_time_s"):
        fig[k] = max(a.figures.get(k) or 0.0, b.figures.get(k) or 0.0)
    if (b.figures.get("max_joint_violation_mm") or 0) > (a.figures.get("max_joint_violation_mm")
                                                         or 0):
        fig["max_joint_violation_mm"] = b.figures["max_joint_violation_mm"]
        fig["worst_joint"] = b.figures["worst_joint"]
    fig["min_margin_fraction"] = round(0.5 - fig["max_deviation_fraction"], 6)
    fig["steps"] = a.figures.get("steps", 0) + b.figures.get("steps", 0)
    # design checks are listed by both: once
    design = [f for f in b.failures if f.get("kind") == "design check"]
    extra = [f for f in b.failures if f.get("kind") != "design check"]
    count = a.failure_count + b.failure_count - len(design)
    return ProofReport(level=a.level, kind=a.kind, passed=a.passed and b.passed,
                       cases=a.cases + b.cases, coverage=a.coverage, failure_count=count,
                       failure_kinds=kinds if (a.failure_kinds is not None
                                               or b.failure_kinds is not None) else None,
                       failures=(a.failures + extra)[:50],
                       figures=fig, seconds=a.seconds + b.seconds)


def held_by_logic(nl: Netlist, names: list[str], pairs: list[tuple[int, int]]
                  ) -> dict[str, np.ndarray]:
    """Per output and change: whether the output is the same for every order in which the
    cells can switch — the moving input unknown (X), ternary simulation (a definite output
    has no static hazard under any cell delays)."""
    n = len(names)
    vals = {}
    for k, nm in enumerate(names):
        a = np.array([(c >> (n - 1 - k)) & 1 for c, _ in pairs], dtype=bool)
        b = np.array([(v >> (n - 1 - k)) & 1 for _, v in pairs], dtype=bool)
        vals[nm] = (~a | ~b, a | b)
    t = evaluate3(nl, vals)
    return {o: ~(t[net][0] & t[net][1]) for o, net in nl.outputs.items()}


def _in_grid(tab: CellTable, move_time: float, load: float) -> bool:
    """Whether a table measured ``move_time`` and ``load`` (it is held at its edges, never
    extrapolated: outside, the model does not cover the cell)."""
    eps = 1e-9
    return (tab.move_times[0] - eps <= move_time <= tab.move_times[-1] + eps
            and tab.loads[0] - eps <= load <= tab.loads[-1] + eps)


def _kind(c, tab: CellTable | None = None) -> str:
    """What makes two cell instances alike for the solver: library cell, type, fan-in,
    parameters; for a cell timed as built (an amplifier), also the geometry its table was
    measured on (two toggles sized differently are witnessed apart)."""
    built = tab.key if tab is not None and tab.as_built else None
    return json.dumps([c.cell, c.type, len(c.inputs), c.params, built], sort_keys=True,
                      default=str)


def _columns(vs: list[int], n: int) -> np.ndarray:
    return np.array([[(v >> (n - 1 - k)) & 1 for k in range(n)] for v in vs],
                    dtype=bool).reshape(len(vs), n).T
