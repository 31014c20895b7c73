"""The one report every proof engine returns, its JSON form and its text for the terminal.

A report reads like its JSON (``report["cases"]``, ``report.get("failure_kinds")``), so code
that looks at a proof's figures needs no engine-specific type; ``to_json()`` is the exact dict
``mechc simulate --report`` writes.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field

from mechc.ui import table

#: Coverage keys that come before "cases" in the JSON (the sequential kinematic walk's steps).
BEFORE_CASES = ("steps",)
#: Failures listed on the terminal (the report file has up to the engine's own limit).
SHOWN_FAILURES = 10
#: The figures of the logic level: positions, margins and joints are not defined there.
LOGIC_FIGURES = {"max_position_error_fraction": None, "min_margin_fraction": None,
                 "max_joint_violation_mm": None, "min_transmission_angle_deg": None}
#: Summary table rows: JSON key, label (a row only where the report has a value).
SUMMARY_KEYS = [
    ("cases", "input states / changes"), ("transitions", "single-input changes"),
    ("max_position_error_fraction", "max output error vs closed form (fraction of stroke)"),
    ("max_deviation_fraction", "max output deviation from spec (fraction of stroke)"),
    ("min_margin_fraction", "min margin to mid-stroke (fraction of stroke)"),
    ("max_joint_violation_mm", "max joint violation (mm)"),
    ("max_contact_penetration_mm", "max contact overrun (mm)"),
    ("max_settle_time_s", "max time outputs moved on after an input stopped (s)"),
    ("min_transmission_angle_deg", "min transmission angle (deg)"),
    ("min_toggle_distance_deg", "min distance from toggle (deg)"),
    ("min_slack_s", "min slack (s)"),
    ("seconds", "seconds"),
]


@dataclass(eq=False)
class ProofReport(Mapping):
    """What a proof checked, what failed, what it measured.

    The JSON lists, in this order: passed, level, ``coverage`` (what was walked, around
    "cases"), failure_count, failure_kinds and overlaps_by_cell (where the engine counts
    them), failures, ``figures`` (the level's measurements), seconds, accuracy (when asked
    for), and ``source`` (the files proved, set by the caller)."""

    level: str  # logic | kinematic | dynamic
    kind: str  # combinational | sequential (not in the JSON: the spec says which)
    passed: bool
    cases: int
    failure_count: int
    failures: list[dict]
    seconds: float
    coverage: dict = field(default_factory=dict)
    failure_kinds: dict[str, int] | None = None
    overlaps_by_cell: dict[str, int] | None = None
    figures: dict = field(default_factory=dict)
    accuracy: dict | None = None
    source: dict = field(default_factory=dict)

    def nothing_moved(self) -> str:
        """A sequential proof that took no input change proves power-up only, and says so
        where the verdict is read."""
        if self.kind == "sequential" and self.level == "timing":
            # its cases are ordering requirements, not input changes
            return (" (the flow table's analysis found no ordering requirement to time)"
                    if self.cases == 0 else "")
        if self.kind == "sequential" and (self.cases == 0 or
                                          self.coverage.get("transitions") == 0):
            return " (no input change to check: power-up state only)"
        return ""

    def to_json(self) -> dict:
        lead = {k: v for k, v in self.coverage.items() if k in BEFORE_CASES}
        rest = {k: v for k, v in self.coverage.items() if k not in BEFORE_CASES}
        out = {"passed": self.passed, "level": self.level, **lead, "cases": self.cases, **rest,
               "failure_count": self.failure_count}
        if self.failure_kinds is not None:
            out["failure_kinds"] = self.failure_kinds
        if self.overlaps_by_cell is not None:
            out["overlaps_by_cell"] = self.overlaps_by_cell
        out["failures"] = self.failures
        out.update(self.figures)
        out["seconds"] = self.seconds
        if self.accuracy is not None:
            out["accuracy"] = self.accuracy
        out.update(self.source)
        return out

    def __getitem__(self, key: str):
        return self.to_json()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.to_json())

    def __len__(self) -> int:
        return len(self.to_json())

    def add_failure(self, kind: str, message: str) -> None:
        """A failure found after the engine ran (a check on the run as a whole): listed first."""
        self.passed = False
        self.failure_count += 1
        self.failure_kinds = {**(self.failure_kinds or {}), kind: 1}
        self.failures.insert(0, {"kind": kind, "message": message})

    def summary_text(self) -> str:
        """The terminal's account: the figures, the verdict, the first failures and the
        orderings a sequential circuit must respect."""
        r = self.to_json()
        rows = [[label, r[k]] for k, label in SUMMARY_KEYS if r.get(k) is not None]
        # a sequential timing proof's cases are its ordering requirements: named so
        requirements = self.level == "timing" and self.kind == "sequential"
        if requirements:
            rows[0][0] = "ordering requirements"
        lines = [table(rows, ["level " + self.level, "value"])]
        if self.accuracy:
            lines.append(accuracy_text(self.accuracy))
        verdict = "PASSED" if self.passed else "FAILED"
        kinds = self.failure_kinds
        extra = f" ({', '.join(f'{v} {k}' for k, v in kinds.items())})" if kinds else ""
        # a sampled proof says so where the verdict is read, not only in --report
        cases = sampled_text(self.cases, self.coverage)
        if requirements:
            cases = f"{self.cases} ordering requirement{'' if self.cases == 1 else 's'}"
        lines.append(f"{verdict}: level {self.level}, {cases}, "
                     f"{self.failure_count} failures{extra}, {self.seconds:.3f} s"
                     + self.nothing_moved())
        lines += ["  " + failure_text(f) for f in self.failures[:SHOWN_FAILURES]]
        if self.failure_count > SHOWN_FAILURES:
            lines.append(f"  ... and {self.failure_count - SHOWN_FAILURES} more (see --report)")
        lines += recheck_text(r) or solver_hint(r)
        lines += hold_text(r)
        lines += timing_text(r)
        hazards = (r.get("sequential") or {}).get("hazards") or []
        if hazards:  # timing the logic cannot remove: what the mechanism must respect
            lines.append(f"ordering requirements ({len(hazards)}; the kinematic and dynamic "
                         "levels check them):")
            lines += [f"  {h['kind']}: {h['requires']}" for h in hazards[:10]]
        return "\n".join(lines)


def solver_hint(r: dict) -> list[str]:
    """A joint stretch, a contact overrun or a late settle may be the solver's (too few
    iterations, too coarse a step) rather than the mechanism's; the run that tells them apart
    is the same proof at finer settings, so the terminal names it (docs/performance.md,
    "Where the methods break")."""
    kinds = r.get("failure_kinds") or {}
    st = r.get("settings") or {}
    if not {"solver", "contact", "settle"} & set(kinds) or not st or r.get("accuracy"):
        return []
    it, dt = st.get("iterations"), st.get("dt_s")
    if it is None or dt is None:
        return []
    return ["joint stretch, contact overrun and late settling can be the solver's, not the "
            f"mechanism's: run again with --iterations {2 * it} or --dt {dt / 2:g}; a failure "
            "that goes away there was the solver's"]


def recheck_text(r: dict) -> list[str]:
    """What the re-run of the failing changes at twice the iterations told apart
    (``mechc.proofs.dynamic.recheck_failures``): a change that passes every check there
    failed by the solver and is proved there (it counts as passed); one that still fails is
    the mechanism's or needs finer settings still. The changes beyond the re-run's cap keep
    the generic hint."""
    rc = r.get("recheck")
    if not rc:
        return []
    it, k, ok = rc["iterations"], rc["changes"], rc["passed_finer"]
    loose = rc.get("passed_unproved", 0)  # a sequential step passing in a piece that fails
    bad = k - ok - loose
    fails = "fails" if bad == 1 else "fail"
    parts = [f"{ok} of {k} failing change{'' if k == 1 else 's'} "
             f"{'passes' if ok == 1 else 'pass'} there"]
    if ok:
        parts[0] += (f" (the solver's: proved at {it} iterations, "
                     f"{'it counts' if ok == 1 else 'they count'} as passed)")
    if loose:
        parts.append(f"{loose} {'passes' if loose == 1 else 'pass'} there in a piece of walk "
                     "that still fails at another step (not proved)")
    if bad:
        who = "(the mechanism's, or the solver's at finer settings still)"
        parts.append(f"{bad} still {fails} {who}" if ok or loose
                     else f"{'it' if k == 1 else 'all'} still {fails} {who}")
    lines = [f"re-run at {it} iterations: " + ", ".join(parts)]
    base = (r.get("settings") or {}).get("iterations", it // 2)
    lines += ["  " + failure_text({
        "kind": f"proved at {it} iterations", "inputs": p["inputs"], "moving": p["moving"],
        "to": p["to"],
        "message": (f"in walk {p['sequence']} step {p['step']} " if "sequence" in p else "")
        + f"(failed on {', '.join(p['failure_kinds_at_settings'])} at {base})"})
        for p in rc.get("proved_finer", [])[:SHOWN_FAILURES]]
    if rc.get("not_rechecked"):
        lines.append(f"{rc['not_rechecked']} more such failing changes were not re-run (at "
                     f"most {rc['cap']} are): " + " ".join(solver_hint(r)))
    return lines


def hold_text(r: dict) -> list[str]:
    """Why a change was held longer than the default before the next one
    (:mod:`mechc.proofs.hold`): a reader of a settle failure, or a builder timing the
    machine's inputs, needs to know what the hold was and where it came from."""
    st = r.get("settings") or {}
    why, hold = st.get("hold_from"), st.get("settle_time_s")
    if hold is None:
        return []
    late = (r.get("failure_kinds") or {}).get("settle", 0)
    slow = ([f"{late} change{' was' if late == 1 else 's were'} still moving when the "
             f"{hold:.3f} s hold ran out: one that is only slow settles with a longer --hold S, "
             "one that never comes to rest does not"] if late else [])
    if why in (None, "default"):
        return slow
    if why == "static path":
        path = st["static_path"]
        cells = path["cells"]
        shown = ", ".join(cells) if len(cells) <= 6 else (
            f"{', '.join(cells[:3])}, ... {', '.join(cells[-2:])}")
        because = (f"{path['factor']:g} x the design's static critical path, "
                   f"{path['seconds']:.3f} s through {len(cells)} cell"
                   f"{'' if len(cells) == 1 else 's'} ({shown})")
        if path.get("untabled"):
            because += (f"; {len(path['untabled'])} cells that could not be measured "
                        "counted at their stated delay")
    elif why == "memories":
        because = "the design's memories, each in turn, may switch after the move"
    else:
        because = "as --hold asked"
    return [f"each change held {hold:.3f} s after its move: {because}", *slow]


def timing_text(r: dict) -> list[str]:
    """The timing level's findings a reader looks for first: the critical path (the latest
    settle of any output over every change, and the cells it goes through) and each ordering
    requirement of a sequential design with its slack and what decided it."""
    out = []
    crit = r.get("critical_path")
    if crit:
        start = " ".join(f"{k}={v}" for k, v in crit["inputs"].items())
        out.append(f"critical path: {crit['output']} settles {crit['settle_s']:.4f} s after "
                   f"{crit['moving']} starts to go to {crit['to']} (to {start}), through "
                   f"{', '.join(crit['path']) or 'no cell'}; budget {r['budget_s']:.3f} s "
                   "(move and hold)")
    reqs = r.get("requirements") or []
    if reqs:
        out.append(f"ordering requirements as timing inequalities ({len(reqs)}):")
        for q in reqs[:SHOWN_FAILURES]:
            verdict = ("met" if q["met"] else "not met by the inequality, met by compile's "
                       "dynamic walk" if q["met_by_dynamic_walk"] else "NOT MET")
            out.append(f"  {q['kind']} ({q['input']} -> {', '.join(q['memories'])}): "
                       f"{q['text']}: {verdict}")
        if len(reqs) > SHOWN_FAILURES:
            out.append(f"  ... and {len(reqs) - SHOWN_FAILURES} more (see --report)")
    return out


def sampled_text(cases: int, coverage: dict) -> str:
    """'1024 cases', or for a proof that is not exhaustive 'sampled 512 of 32768 cases' (and of
    the single-input changes, where the engine says how many there are); a SAT proof covers
    every vector without enumerating them, and says so."""
    if coverage.get("method") == "sat":
        n = max(int(cases).bit_length() - 1, 0)
        return f"all 2^{n} vectors by a SAT miter ({coverage.get('solver', 'SAT')})"
    if coverage.get("exhaustive") is not False:
        return f"{cases} cases"
    total = coverage.get("cases_total")
    tr, tr_total = coverage.get("transitions"), coverage.get("transitions_total")
    if total is None and tr_total is None:
        return f"{cases} sampled cases (not exhaustive)"
    parts = []
    if total is not None:
        parts.append(f"all {cases} cases" if cases >= total
                     else f"sampled {cases} of {total} cases")
    if tr is not None and tr_total is not None and tr < tr_total:
        parts.append(f"proven on {tr} of {tr_total} single-input changes, sampled")
    if "directed_changes" in coverage:  # how the sample was led (mechc.proofs.cases)
        parts.append(f"{coverage['directed_changes']} of them chosen to switch every cell: "
                     f"{coverage['cells_toggled']} of {coverage['cells']} cells switched"
                     + (f", {coverage['cells_never_toggle']} cannot switch"
                        if coverage.get("cells_never_toggle") else "")
                     + (f", {coverage['cells_not_reached']} not reached"
                        if coverage.get("cells_not_reached") else ""))
    return ", ".join(parts) + " (not exhaustive)"


def failure_text(f: dict) -> str:
    """One failure on one line, from whichever of its fields the engine filled in."""
    if "message" in f and "inputs" not in f:
        return f["message"]
    ins = " ".join(f"{k}={v}" for k, v in f.get("inputs", {}).items())
    kind = f.get("kind", "")
    if kind in ("", "rest") and "got" in f:
        return f"{f['output']}: expected {f['expected']}, got {f['got']} at {ins}"
    head = f"{kind}: "
    if "moving" in f:
        head += f"{f['moving']} -> {f.get('to', '')} " if "to" in f else f"{f['moving']} moving "
    if "output" in f:
        head += f"output {f['output']} (expected {f['expected']}) "
        for key in ("position", "max_deviation", "max_deviation_fraction", "deviation_fraction"):
            if key in f:
                head += f"{key.replace('_', ' ')} {f[key]} "
    if "message" in f:
        head += f["message"] + " "
    line = head + f"at {ins}"
    finer = f.get("finer")
    if finer:  # what the re-run at finer settings gave (mechc.proofs.dynamic.recheck_failures)
        line += (f"; at {finer['iterations']} iterations: "
                 + ("still fails" if not finer["passed"] else
                    "passes, but its piece of walk still fails there"
                    if finer.get("piece_passed") is False else "passes"))
    return line


def accuracy_text(check: dict) -> str:
    """Two lines for an accuracy-driven run: settings used, error obtained."""
    c = check["chosen"]
    verdict = "confirmed" if check["confirmed"] else "NOT confirmed"
    return (f"accuracy {check['target_fraction']:g} of stroke: dt {c['dt_s']:g} s, "
            f"{c['iterations']} iterations, move time {c['move_time_s']:g} s (model error "
            f"{c['model_error_fraction']:.3g})\n"
            f"  obtained {check['obtained_fraction']:.4g} (closed form "
            f"{check['error_vs_closed_form_fraction']:.4g}, step halving "
            f"{check['halving_estimate_fraction']:.4g} on {check['halving_cases']} changes): "
            f"{verdict}")
