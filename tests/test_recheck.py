"""The dynamic proof runs the changes failing on a joint stretch, contact overrun or late settle
again at twice the iterations, and says which failures went away there (the solver's) and
which did not (the mechanism's); it never changes the verdict. Real failures of the full
adder: one iteration per step breaks joints (a few changes pass at two), inputs thrown in
10 ms do not settle (at 60 iterations nor at 120)."""

from __future__ import annotations

import json

import pytest

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.pipeline import compile_spec
from mechc.proofs import ProofSettings, dyn_settings, prove
from mechc.proofs.dynamic import RECHECK_MAX, RECHECKED, prove_dynamic
from mechc.proofs.report import ProofReport, recheck_text
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
            f"{'passes' if solver_s == 1 else 'pass'} there (the solver's: use --iterations 2), "
            f"{RECHECK_MAX - solver_s} still fail") in text
    # the changes beyond the cap keep the generic hint
    assert f"{rc['not_rechecked']} more such failing changes were not re-run" in text
    assert "run again with --iterations 2 or --dt" in text


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
        "re-run at 120 iterations: 3 of 4 failing changes pass there (the solver's: use "
        "--iterations 120), 1 still fails (the mechanism's, or the solver's at finer settings "
        "still)"]
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
