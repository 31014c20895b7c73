"""The dynamic proof runs the changes failing on a joint stretch, contact overrun or late settle
again at twice the iterations, and says which failures went away there (the solver's) and
which did not (the mechanism's); it never changes the verdict. Real failures of the full
adder: one iteration per step breaks joints (a few changes pass at two), inputs thrown in
10 ms do not settle (at 60 iterations nor at 120). The sequential proof runs its failing
pieces of walks again (each from power-up) and counts the steps: the gated latch at one
iteration."""

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


def _check_finer(r: ProofReport, truth: dict[tuple, list[str]]) -> set[tuple]:
    """Every failure entry of a rechecked change says what the independent finer run says;
    the rechecked changes are the first failing ones (solver, contact, settle) in plan order."""
    rechecked = {_key(f) for f in r.failures if "finer" in f}
    for f in r.failures:
        if "finer" in f:
            want = truth[_key(f)]
            assert f["finer"]["failure_kinds"] == want, f
            assert f["finer"]["passed"] == (not want)
    first: list[tuple] = []
    for f in r.failures:
        if f.get("kind") in RECHECKED and _key(f) not in first:
            first.append(_key(f))
    assert rechecked == set(first[:RECHECK_MAX])
    return rechecked


def test_one_iteration_failures_are_told_apart_at_two(adder):
    st = dyn_settings(adder, iterations=1)
    on = prove_dynamic(adder, adder.spec, LIB, st, jobs=2)
    off = prove_dynamic(adder, adder.spec, LIB, st, jobs=2, recheck=False)
    assert _verdict(on) == _verdict(off) and not on.passed and "solver" in on.failure_kinds
    assert "recheck" not in off.figures and not any("finer" in f for f in off.failures)
    truth = _finer_truth(adder, 2)
    rechecked = _check_finer(on, truth)
    rc = on.figures["recheck"]
    solver_s = sum(not truth[k] for k in rechecked)
    assert (rc["iterations"], rc["changes"]) == (2, len(rechecked)) == (2, RECHECK_MAX)
    assert (rc["passed_finer"], rc["failed_finer"]) == (solver_s, RECHECK_MAX - solver_s)
    assert 0 < solver_s < RECHECK_MAX  # both kinds of failure, for real
    failing = {_key(f) for f in off.failures if f["kind"] in RECHECKED}
    assert rc["not_rechecked"] == len(failing) - RECHECK_MAX > 0
    text = on.summary_text()
    assert (f"re-run at 2 iterations: {solver_s} of {RECHECK_MAX} failing changes "
            f"{'passes' if solver_s == 1 else 'pass'} there (the solver's), "
            f"{RECHECK_MAX - solver_s} still fail") in text
    # the changes beyond the cap keep the generic hint
    assert f"{rc['not_rechecked']} more such failing changes were not re-run" in text
    assert "run again with --iterations 2 or --dt" in text
    # each listed failure of a re-run change says what the re-run gave; the others say nothing
    for f in on.failures:
        line = failure_text(f)
        if "finer" in f:
            assert line.endswith("; at 2 iterations: "
                                 + ("passes" if f["finer"]["passed"] else "still fails"))
        else:
            assert "iterations:" not in line
    assert any(failure_text(f) in text for f in on.failures if "finer" in f)


def test_a_settle_failure_of_the_mechanism_still_fails_finer_in_the_screened_proof(adder):
    """Inputs thrown in 10 ms: the screened proof (its own rounds, then one recheck) keeps the
    dynamic proof's verdict, and its re-run at 120 iterations still fails every change."""
    seen: list[tuple[int, int]] = []
    scr = prove(adder, adder.spec, LIB, "screened",
                ProofSettings(move_time=0.01, jobs=2), lambda d, t: seen.append((d, t)))
    full = prove_dynamic(adder, adder.spec, LIB, dyn_settings(adder, move_time=0.01), jobs=2,
                         recheck=False)
    assert (scr.passed, scr.failure_count, scr.failure_kinds) == \
        (full.passed, full.failure_count, full.failure_kinds) == (False, 8, {"settle": 8})
    rechecked = _check_finer(scr, _finer_truth(adder, 120, move_time=0.01))
    rc = scr.figures["recheck"]
    assert rc == {"iterations": 120, "changes": len(rechecked), "passed_finer": 0,
                  "failed_finer": len(rechecked), "not_rechecked": 0, "cap": RECHECK_MAX}
    assert "re-run at 120 iterations: 0 of 3 failing changes pass there, all still fail " \
           "(the mechanism's" in scr.summary_text()
    assert "can be the solver's" not in scr.summary_text()  # every such failure re-ran
    # the progress goes on from the proof's changes to the re-run's, never back
    done = [d for d, _ in seen]
    assert done == sorted(done) and seen[-1][0] == seen[-1][1] == 23 + len(rechecked)


def test_the_recheck_line_reads_plainly():
    rc = {"iterations": 120, "changes": 4, "passed_finer": 3, "failed_finer": 1,
          "not_rechecked": 0, "cap": RECHECK_MAX}
    assert recheck_text({"recheck": rc}) == [
        "re-run at 120 iterations: 3 of 4 failing changes pass there (the solver's), 1 still "
        "fails (the mechanism's, or the solver's at finer settings still)"]
    one = {**rc, "changes": 1, "passed_finer": 1, "failed_finer": 0}
    assert recheck_text({"recheck": one}) == [
        "re-run at 120 iterations: 1 of 1 failing change passes there (the solver's: use "
        "--iterations 120)"]
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
# The gated latch at one iteration per step: 42 of its 66 steps (3 of them on the way to a
# piece's start) break a joint; at two, 20 do. It runs in about 3 s on two processes.

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
    st = dyn_settings(design, LIB, iterations=1)
    seen: list[tuple[int, int]] = []
    on = prove_sequential_dynamic(design, spec, LIB, st, jobs=2,
                                  progress=lambda d, t: seen.append((d, t)))
    off = prove_sequential_dynamic(design, spec, LIB, st, jobs=2, recheck=False)
    assert _verdict(on) == _verdict(off) and not on.passed
    assert "recheck" not in off.figures and not any("finer" in f for f in off.failures)
    failing = {k for k, kinds in _step_kinds(off).items() if RECHECKED & set(kinds)}
    # the first RECHECK_MAX pieces holding such a step are the ones re-run, whole
    pieces = split_walks(spec, transition_tour(spec, seed=0, random_walks=2))
    held = [p for p in pieces if any(_in_piece(k, p) for k in failing)]
    assert len(held) > RECHECK_MAX
    chosen = held[:RECHECK_MAX]
    rechecked = {k for k in failing if any(_in_piece(k, p) for p in chosen)}
    assert {_step(f) for f in on.failures if "finer" in f} == rechecked
    assert any(k[2] is not None for k in rechecked)  # a prefix step is matched too
    # each says what an independent proof at two iterations says of that step
    truth = _step_kinds(prove_sequential_dynamic(
        design, spec, LIB, dyn_settings(design, LIB, iterations=2), jobs=2, recheck=False))
    for f in on.failures:
        if "finer" in f:
            want = truth.get(_step(f), [])
            assert f["finer"]["failure_kinds"] == want and f["finer"]["passed"] == (not want)
            assert f["finer"]["iterations"] == 2
    ok = sum(not truth.get(k) for k in rechecked)
    assert 0 < ok < len(rechecked)  # both kinds of failure, for real
    assert on.figures["recheck"] == {
        "iterations": 2, "changes": len(rechecked), "passed_finer": ok,
        "failed_finer": len(rechecked) - ok, "not_rechecked": len(failing - rechecked),
        "cap": RECHECK_MAX}
    text = on.summary_text()
    assert (f"re-run at 2 iterations: {ok} of {len(rechecked)} failing changes pass there "
            f"(the solver's), {len(rechecked) - ok} still fail") in text
    assert f"{len(failing - rechecked)} more such failing changes were not re-run" in text
    # the progress goes on from the proof's steps to the re-run pieces', never back
    done = [d for d, _ in seen]
    main = on.cases + on.coverage["prefix_steps"]
    assert done == sorted(done)
    assert seen[-1][0] == seen[-1][1] == main + sum(len(p.sequence) - 1 for p in chosen)


@pytest.mark.parametrize("recheck", [True, False])
def test_the_sequential_screened_level_passes_the_setting_on(latch, recheck):
    design, spec = latch
    r = prove(design, spec, LIB, "screened", ProofSettings(iterations=1, jobs=2,
                                                           recheck=recheck))
    assert not r.passed and r.figures["screen"]["applied"] is False
    assert ("recheck" in r.figures) == recheck
    assert any("finer" in f for f in r.failures) == recheck
