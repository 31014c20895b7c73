"""The dynamic proof runs the changes failing on a joint stretch, contact overrun or late settle
again at twice the iterations and proves them there: a change that passes every check at the
finer setting failed by the solver and counts as passed (the report is tallied with its finer
run); one that still fails is the mechanism's or needs finer settings still, and says so.
Real failures of the full adder: one iteration per step breaks joints (a few changes pass at
two), at three iterations every failing change passes at six, inputs thrown in 10 ms do not
settle (at 60 iterations nor at 120). The sequential proof runs its failing pieces of walks
again (each from power-up) and proves a piece whose every step passes there: the gated latch
at one iteration."""

from __future__ import annotations

import json

import pytest

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.pipeline import compile_sequential, compile_spec
from mechc.proofs import ProofSettings, dyn_settings, prove
from mechc.proofs.dynamic import RECHECK_MAX, RECHECKED, prove_dynamic
from mechc.proofs.report import ProofReport, failure_text, recheck_text
from mechc.proofs.screen import JOINT_HEADROOM
from mechc.proofs.seq_logic import split_walks, transition_tour
from mechc.proofs.seq_mechanism import prove_sequential_dynamic
from tests.helpers import EXAMPLES

LIB = load_library()


@pytest.fixture(scope="module")
def adder():
    return compile_spec(load_spec(EXAMPLES / "full_adder.bool"))


def _key(entry: dict) -> tuple:
    return tuple(sorted(entry["inputs"].items())), entry["moving"], entry["to"]


def _without_finer(r: ProofReport) -> list[dict]:
    return [{k: v for k, v in f.items() if k != "finer"} for f in r.failures]


def _verdict(r: ProofReport) -> tuple:
    return r.passed, r.failure_count, r.failure_kinds, _without_finer(r)


def _finer_truth(design, iterations: int, **kw) -> dict[tuple, list[str]]:
    """Each change's failure kinds in an independent run at ``iterations`` (no recheck)."""
    rec: list[dict] = []
    prove_dynamic(design, design.spec, LIB, dyn_settings(design, iterations=iterations, **kw),
                  record=rec, recheck=False, jobs=2)
    return {_key(r): r["failure_kinds"] for r in rec}


def _check_finer(first: ProofReport, truth: dict[tuple, list[str]],
                 r: ProofReport | None = None) -> set[tuple]:
    """The changes re-run are the first failing ones (solver, contact, settle) of ``first``
    in plan order; every failure entry ``r`` (default ``first``) still lists for a re-run
    change says what the independent finer run ``truth`` says: it still fails."""
    r = r or first
    order: list[tuple] = []
    for f in first.failures:
        if f.get("kind") in RECHECKED and _key(f) not in order:
            order.append(_key(f))
    rechecked = set(order[:RECHECK_MAX])
    for f in r.failures:
        if "finer" in f:
            want = truth[_key(f)]
            assert _key(f) in rechecked and want, f
            assert f["finer"]["failure_kinds"] == want and not f["finer"]["passed"]
        elif "inputs" in f:
            assert _key(f) not in rechecked or not truth[_key(f)], f
    return rechecked


def _without(r: ProofReport, proved: set[tuple]) -> list[dict]:
    """``r``'s failures but those of the changes in ``proved``, without ``finer``."""
    return [f for f in _without_finer(r) if "inputs" not in f or _key(f) not in proved]


def _expected_figures(coarse: list[dict], fine: list[dict], proved: set[tuple]) -> dict:
    """The figures of a proof whose ``proved`` changes ran finer (records of the two runs)."""
    rows = [r for r in coarse if _key(r) not in proved] + [r for r in fine if _key(r) in proved]
    settles = [r["settle_time_s"] for r in rows if r["settle_time_s"] != float("inf")]
    return {"max_joint_violation_mm": round(max(r["max_violation_mm"] for r in rows), 6),
            "max_contact_penetration_mm": round(max(r["max_penetration_mm"] for r in rows), 6),
            "max_settle_time_s": round(max(settles), 5)}


def test_one_iteration_failures_are_told_apart_at_two(adder):
    st = dyn_settings(adder, iterations=1)
    on = prove_dynamic(adder, adder.spec, LIB, st, jobs=2)
    coarse: list[dict] = []
    off = prove_dynamic(adder, adder.spec, LIB, st, jobs=2, recheck=False, record=coarse)
    assert not on.passed and not off.passed and "solver" in on.failure_kinds
    assert off.failure_count == len(off.failures)  # every failure listed: comparable
    assert "recheck" not in off.figures and not any("finer" in f for f in off.failures)
    truth = _finer_truth(adder, 2)
    rechecked = _check_finer(off, truth, on)
    proved = {k for k in rechecked if not truth[k]}
    rc = on.figures["recheck"]
    assert (rc["iterations"], rc["changes"]) == (2, len(rechecked)) == (2, RECHECK_MAX)
    assert (rc["passed_finer"], rc["failed_finer"]) == (len(proved), RECHECK_MAX - len(proved))
    assert 0 < len(proved) < RECHECK_MAX  # both kinds of failure, for real
    # the changes passing at two count as passed; the rest of the report is the proof's own
    assert {_key(p) for p in rc["proved_finer"]} == proved
    assert _without_finer(on) == _without(off, proved)
    assert on.failure_count == off.failure_count - sum(
        1 for f in off.failures if "inputs" in f and _key(f) in proved)
    fine: list[dict] = []
    prove_dynamic(adder, adder.spec, LIB, dyn_settings(adder, iterations=2), record=fine,
                  recheck=False, jobs=2)
    want = _expected_figures(coarse, fine, proved)
    assert {k: on.figures[k] for k in want} == want
    failing = {_key(f) for f in off.failures if f["kind"] in RECHECKED}
    assert rc["not_rechecked"] == len(failing) - RECHECK_MAX > 0
    text = on.summary_text()
    assert (f"re-run at 2 iterations: {len(proved)} of {RECHECK_MAX} failing changes "
            f"{'passes' if len(proved) == 1 else 'pass'} there (the solver's: proved at 2 "
            f"iterations, {'it counts' if len(proved) == 1 else 'they count'} as passed), "
            f"{RECHECK_MAX - len(proved)} still fail") in text
    assert text.count("  proved at 2 iterations: ") == len(proved)
    # the changes beyond the cap keep the generic hint
    assert f"{rc['not_rechecked']} more such failing changes were not re-run" in text
    assert "run again with --iterations 2 or --dt" in text
    # each listed failure of a re-run change says what the re-run gave; the others say nothing
    for f in on.failures:
        line = failure_text(f)
        if "finer" in f:
            assert line.endswith("; at 2 iterations: still fails")
        else:
            assert "iterations:" not in line
    assert any(failure_text(f) in text for f in on.failures if "finer" in f)


def test_a_design_whose_failures_are_all_the_solvers_passes(adder, cli, tmp_path):
    """At three iterations five changes of the full adder fail; at six each passes, so the
    proof passes, proved partly at six, and says so; without the re-run it fails."""
    coarse: list[dict] = []
    off = prove_dynamic(adder, adder.spec, LIB, dyn_settings(adder, iterations=3), jobs=2,
                        recheck=False, record=coarse)
    failing = {_key(r) for r in coarse if r["failure_kinds"]}
    assert not off.passed and 0 < len(failing) <= RECHECK_MAX
    assert all(set(r["failure_kinds"]) <= RECHECKED for r in coarse)
    fine: list[dict] = []
    prove_dynamic(adder, adder.spec, LIB, dyn_settings(adder, iterations=6), record=fine,
                  recheck=False, jobs=2)
    assert not any(r["failure_kinds"] for r in fine if _key(r) in failing)  # independent
    report = tmp_path / "r.json"
    code, out, _ = cli("simulate", EXAMPLES / "full_adder.bool", "--level", "dynamic",
                       "--iterations", "3", "--report", report)
    r = json.loads(report.read_text())
    assert code == 0 and r["passed"] and r["failure_count"] == 0 and r["failures"] == []
    rc = r["recheck"]
    assert {_key(p) for p in rc["proved_finer"]} == failing
    assert all(p["iterations"] == 6 and p["passed"] and p["failure_kinds_at_settings"]
               for p in rc["proved_finer"])
    assert {k: r[k] for k in ("max_joint_violation_mm", "max_contact_penetration_mm",
                              "max_settle_time_s")} == _expected_figures(coarse, fine, failing)
    assert "PASSED: level dynamic" in out
    assert (f"re-run at 6 iterations: {len(failing)} of {len(failing)} failing changes pass "
            "there (the solver's: proved at 6 iterations, they count as passed)") in out
    assert out.count("  proved at 6 iterations: ") == len(failing)
    assert "(failed on " in out and " at 3)" in out
    code, out, _ = cli("simulate", EXAMPLES / "full_adder.bool", "--level", "dynamic",
                       "--iterations", "3", "--no-recheck")
    assert code == 1 and "FAILED" in out


def test_the_screened_proof_proves_the_same_changes_finer(adder):
    """The screened proof re-runs after its rounds as the dynamic proof does: at three
    iterations both pass, with the same changes proved at six."""
    def proved(r: ProofReport) -> set[tuple]:
        return {_key(p) for p in r.figures["recheck"]["proved_finer"]}

    scr = prove(adder, adder.spec, LIB, "screened", ProofSettings(iterations=3, jobs=2))
    dyn = prove(adder, adder.spec, LIB, "dynamic", ProofSettings(iterations=3, jobs=2))
    assert scr.passed and dyn.passed and proved(scr) == proved(dyn) != set()


def test_a_settle_failure_of_the_mechanism_still_fails_finer_in_the_screened_proof(adder):
    """Inputs thrown in 10 ms: the screened proof (its own rounds, then one recheck) keeps the
    dynamic proof's verdict, and its re-run at 120 iterations still fails every change."""
    seen: list[tuple[int, int]] = []
    scr = prove(adder, adder.spec, LIB, "screened",
                ProofSettings(move_time=0.01, jobs=2), lambda d, t: seen.append((d, t)))
    full = prove_dynamic(adder, adder.spec, LIB, dyn_settings(adder, move_time=0.01), jobs=2,
                         recheck=False)
    assert (scr.passed, scr.failure_count, scr.failure_kinds) == \
        (full.passed, full.failure_count, full.failure_kinds)
    assert not full.passed and full.failure_kinds["settle"] >= 1
    rechecked = _check_finer(scr, _finer_truth(adder, 120, move_time=0.01))
    rc = scr.figures["recheck"]
    assert rc == {"iterations": 120, "changes": len(rechecked), "passed_finer": 0,
                  "failed_finer": len(rechecked), "not_rechecked": 0, "cap": RECHECK_MAX,
                  "proved_finer": []}
    assert f"re-run at 120 iterations: 0 of {len(rechecked)} failing changes pass there, all " \
           "still fail (the mechanism's" in scr.summary_text()
    assert "can be the solver's" not in scr.summary_text()  # every such failure re-ran
    # the progress goes on from the proof's changes to the re-run's, never back
    done = [d for d, _ in seen]
    # (and the witnesses its calibration ran again finer: those that only stretched a joint)
    again = scr.figures["screen"]["rerun_finer"]
    assert done == sorted(done) and seen[-1][0] == seen[-1][1] == 23 + again + len(rechecked)


@pytest.fixture(scope="module")
def sorter():
    return compile_spec(load_spec(EXAMPLES / "sorter.bool"))


def test_a_witness_the_solver_stretched_witnesses_at_twice_the_iterations(sorter):
    """At two iterations the sorter's witnesses stretch joints past the headroom the changes
    they vouch for need; at four they leave it. The screen runs them again there instead of
    running every change they vouch for, and the changes it clears on them pass every check
    of the whole dynamic proof at four iterations, run independently. The verdict is the
    dynamic proof's, which proves its own failing changes at four."""
    s = ProofSettings(iterations=2, jobs=2)
    scr = prove(sorter, sorter.spec, LIB, "screened", s)
    sc = scr.figures["screen"]
    w = sc["witnessed_finer"]
    assert w and all(e["iterations"] == 4 and e["passed"]
                     and e["max_violation_mm"] <= (1 - JOINT_HEADROOM) * 0.1 for e in w)
    assert all("joint stretch" in t for e in w for t in e["failed_at_settings"])
    at4 = [d for d in sc["decisions"] if d.get("witness_iterations") == 4]
    assert len(at4) == sc["cleared_finer"] > 0 and all(d["route"] == "timing" for d in at4)
    assert sc["fell_back"] == 0 and sc["dynamic"] < len(at4)
    truth = _finer_truth(sorter, 4)
    assert all(truth[_key(d)] == [] for d in at4)
    dyn = prove(sorter, sorter.spec, LIB, "dynamic", s)
    assert scr.passed and dyn.passed
    assert f"the {len(at4)} cleared changes they vouch for are proved at 4 iterations" \
        in sc["text"]


def test_no_recheck_keeps_the_witnesses_at_the_proofs_settings(sorter):
    """With the re-run off the witnesses are judged at two iterations: their failures take
    the vouching from every change they concern, which then run."""
    scr = prove(sorter, sorter.spec, LIB, "screened",
                ProofSettings(iterations=2, jobs=2, recheck=False))
    sc = scr.figures["screen"]
    assert sc["witnessed_finer"] == [] and sc["cleared_finer"] == 0
    assert sc["fell_back"] > 0 and sc["calibration"] != "passed"


def test_the_recheck_line_reads_plainly():
    rc = {"iterations": 120, "changes": 4, "passed_finer": 3, "failed_finer": 1,
          "not_rechecked": 0, "cap": RECHECK_MAX,
          "proved_finer": [{"inputs": {"a": 1, "b": 0}, "moving": "a", "to": 1,
                            "failure_kinds_at_settings": ["settle"]}]}
    assert recheck_text({"recheck": rc, "settings": {"iterations": 60}}) == [
        "re-run at 120 iterations: 3 of 4 failing changes pass there (the solver's: proved at "
        "120 iterations, they count as passed), 1 still fails (the mechanism's, or the "
        "solver's at finer settings still)",
        "  proved at 120 iterations: a -> 1 (failed on settle at 60) at a=1 b=0"]
    one = {**rc, "changes": 1, "passed_finer": 1, "failed_finer": 0, "proved_finer": []}
    assert recheck_text({"recheck": one}) == [
        "re-run at 120 iterations: 1 of 1 failing change passes there (the solver's: proved "
        "at 120 iterations, it counts as passed)"]
    assert recheck_text({}) == []


def test_no_recheck_on_the_command_line(cli, tmp_path):
    report = tmp_path / "r.json"
    code, out, _ = cli("simulate", EXAMPLES / "full_adder.bool", "--level", "dynamic",
                       "--iterations", "1", "--no-recheck", "--report", report)
    r = json.loads(report.read_text())
    assert code == 1 and "recheck" not in r and not any("finer" in f for f in r["failures"])
    assert "re-run at" not in out and "can be the solver's" in out


def test_no_recheck_is_refused_where_no_dynamic_proof_runs(cli):
    code, _, err = cli("simulate", EXAMPLES / "sorter.bool", "--level", "timing",
                       "--no-recheck")
    assert code == 2 and "--no-recheck turns off the re-run" in err and "Traceback" not in err


# ---- the sequential dynamic proof: pieces of walks run again, steps counted -------------------
# The gated latch at one iteration per step, its inputs moved in 60 ms: 42 of its 66 steps (3 of
# them on the way to a piece's start) break a joint; at two, 4 do. (At the default 80 ms every
# re-run piece passes at two since the MEMORY's lever rests on its stops without kicking: no
# piece that still fails.) It runs in about 3 s on two processes.
MOVE = 0.06

def _step(entry: dict) -> tuple:
    """A step's identity in a sequential report: walk, step, place on the way to a piece's
    start (if any), the input moved and to what, the inputs after it."""
    return (entry["sequence"], entry["step"], entry.get("prefix"), entry["moving"],
            entry["to"], tuple(sorted(entry["inputs"].items())))


def _step_kinds(r: ProofReport) -> dict[tuple, list[str]]:
    """Each failing step's kinds, from a report that lists every failure."""
    assert r.failure_count == len(r.failures)
    out: dict[tuple, set[str]] = {}
    for f in r.failures:
        out.setdefault(_step(f), set()).add(f["kind"])
    return {k: sorted(v) for k, v in out.items()}


def _in_piece(key: tuple, p) -> bool:
    seq, step, prefix = key[:3]
    return seq == p.walk and (step == p.start if prefix is not None
                              else p.start < step <= p.end)


@pytest.fixture(scope="module")
def latch():
    spec = parse_fsm_file(str(EXAMPLES / "gated_latch.fsm"))
    return compile_sequential(spec, library=LIB), spec


def test_sequential_failing_pieces_rerun_at_twice_the_iterations(latch):
    design, spec = latch
    st = dyn_settings(design, LIB, iterations=1, move_time=MOVE)
    seen: list[tuple[int, int]] = []
    on = prove_sequential_dynamic(design, spec, LIB, st, jobs=2,
                                  progress=lambda d, t: seen.append((d, t)))
    off = prove_sequential_dynamic(design, spec, LIB, st, jobs=2, recheck=False)
    assert not on.passed and not off.passed
    assert "recheck" not in off.figures and not any("finer" in f for f in off.failures)
    failing = {k for k, kinds in _step_kinds(off).items() if RECHECKED & set(kinds)}
    # the first RECHECK_MAX pieces holding such a step are the ones re-run, whole
    pieces = split_walks(spec, transition_tour(spec, seed=0, random_walks=2))
    held = [p for p in pieces if any(_in_piece(k, p) for k in failing)]
    assert len(held) > RECHECK_MAX
    chosen = held[:RECHECK_MAX]
    rechecked = {k for k in failing if any(_in_piece(k, p) for p in chosen)}
    assert any(k[2] is not None for k in rechecked)  # a prefix step is matched too
    # an independent proof at two iterations runs the same pieces: a piece with no failing
    # step there is proved, and every failure of it leaves the report
    truth = _step_kinds(prove_sequential_dynamic(
        design, spec, LIB, dyn_settings(design, LIB, iterations=2, move_time=MOVE), jobs=2,
        recheck=False))
    whole = [p for p in chosen if not any(_in_piece(k, p) for k in truth)]
    assert 0 < len(whole) < len(chosen)  # both kinds of piece, for real
    proved = {k for k in rechecked if any(_in_piece(k, p) for p in whole)}
    assert [f for f in _without_finer(on)] == [
        f for f in _without_finer(off)
        if "sequence" not in f or not any(_in_piece(_step(f), p) for p in whole)]
    assert on.failure_count == len(on.failures) < off.failure_count
    # what is left of a re-run piece says what the independent run says of that step
    assert {_step(f) for f in on.failures if "finer" in f} == rechecked - proved
    for f in on.failures:
        if "finer" in f:
            want = truth.get(_step(f), [])
            assert f["finer"]["failure_kinds"] == want and f["finer"]["passed"] == (not want)
            assert f["finer"]["iterations"] == 2 and f["finer"]["piece_passed"] is False
    rc = dict(on.figures["recheck"])
    assert {_step(p) for p in rc.pop("proved_finer")} == proved
    loose = sum(not truth.get(k) for k in rechecked - proved)  # pass in a failing piece
    assert loose > 0
    assert rc == {
        "iterations": 2, "changes": len(rechecked), "passed_finer": len(proved),
        "failed_finer": len(rechecked) - len(proved) - loose, "passed_unproved": loose,
        "not_rechecked": len(failing - rechecked), "cap": RECHECK_MAX}
    text = on.summary_text()
    assert (f"re-run at 2 iterations: {len(proved)} of {len(rechecked)} failing changes pass "
            f"there (the solver's: proved at 2 iterations, they count as passed), {loose} pass "
            "there in a piece of walk that still fails at another step (not proved), "
            f"{len(rechecked) - len(proved) - loose} still fail") in text
    assert text.count("  proved at 2 iterations: ") == len(proved)
    for f in on.failures:  # a step passing in a piece that does not says so
        if "finer" in f and f["finer"]["passed"]:
            assert failure_text(f).endswith("passes, but its piece of walk still fails there")
    assert f"{len(failing - rechecked)} more such failing changes were not re-run" in text
    # the progress goes on from the proof's steps to the re-run pieces', never back
    done = [d for d, _ in seen]
    main = on.cases + on.coverage["prefix_steps"]
    assert done == sorted(done)
    assert seen[-1][0] == seen[-1][1] == main + sum(len(p.sequence) - 1 for p in chosen)


@pytest.mark.parametrize("recheck", [True, False])
def test_the_sequential_screened_level_passes_the_setting_on(latch, recheck):
    design, spec = latch
    r = prove(design, spec, LIB, "screened", ProofSettings(iterations=1, jobs=2, move_time=MOVE,
                                                           recheck=recheck))
    assert not r.passed and r.figures["screen"]["applied"] is False
    assert ("recheck" in r.figures) == recheck
    assert any("finer" in f for f in r.failures) == recheck
