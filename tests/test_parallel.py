"""Proof cases on several processes and on a Dask cluster: every case's figures, the failures
in their order and the report are the serial run's (``mechc.proofs.parallel``)."""

from __future__ import annotations

import json
import multiprocessing
import os

import pytest

from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.frontends.fsm import parse_fsm_file
from mechc.pipeline import compile_spec
from mechc.proofs import parallel
from mechc.proofs.dynamic import Change, ChangeJob, prove_dynamic, run_segment
from mechc.proofs.seq_mechanism import prove_sequential_dynamic
from mechc.proofs.settings import dyn_settings
from tests.helpers import EXAMPLES

LIB = load_library()


@pytest.fixture(scope="module")
def sorter():
    return compile_spec(load_spec(EXAMPLES / "sorter.bool"))


@pytest.fixture(scope="module")
def toggle():
    return compile_spec(parse_fsm_file(EXAMPLES / "toggle.fsm"))


def _timeless(report) -> dict:
    return {k: v for k, v in report.to_json().items() if k != "seconds"}


def _combinational(design, **kw):
    rec: list = []
    # a tolerance no settled output meets: every case fails, so the order of the listed
    # failures is compared too, not only figures
    report = prove_dynamic(design, design.spec, LIB, extra=2, tolerance=1e-5, record=rec, **kw)
    return rec, report


def test_process_pool_gives_the_serial_proof_case_by_case(sorter):
    serial, one = _combinational(sorter, jobs=1)
    pooled, two = _combinational(sorter, jobs=2)
    assert len(serial) == one.cases == 17
    assert one.failure_count > 0 and one.failures  # the comparison covers failures
    assert pooled == serial  # each change: inputs, final outputs, stretch, overrun, settle, steps
    assert _timeless(two) == _timeless(one)


def test_every_change_starts_from_its_own_rest_so_a_case_alone_is_the_same(sorter):
    """A case does not depend on the cases before it: the tour's last change run alone (its
    start state the closed form's) gives the figures it has in the whole tour."""
    whole, _ = _combinational(sorter)
    vectors = [int("".join(str(c["inputs"][k]) for k in sorter.spec.inputs), 2)
               for c in whole]
    job = ChangeJob(sorter, list(sorter.spec.inputs),
                    {c.id: c.cell for c in sorter.netlist.cells.values()},
                    dyn_settings(sorter), None, False, None, None)
    [run] = run_segment(job, LIB, [Change(vectors[-2], vectors[-1], {}, {})])
    assert run.result.final == whole[-1]["final"]
    assert run.result.max_violation == whole[-1]["max_violation_mm"]


@pytest.mark.slow
def test_sequential_walks_on_spawned_processes_match_the_serial_walks(toggle, monkeypatch):
    """The workers get everything through their initializer: a spawned process (no memory
    shared with this one) gives the serial figures."""
    monkeypatch.setattr(parallel, "_pool_context", lambda: multiprocessing.get_context("spawn"))
    serial: list = []
    one = prove_sequential_dynamic(toggle, toggle.spec, LIB, random_walks=1, record=serial)
    spawned: list = []
    two = prove_sequential_dynamic(toggle, toggle.spec, LIB, random_walks=1, record=spawned,
                                   jobs=2)
    assert one.coverage["sequences"] >= 2 and len(serial) == one.cases > 0
    assert spawned == serial
    assert _timeless(two) == _timeless(one)


@pytest.mark.slow
def test_a_dask_cluster_gives_the_serial_proof_case_by_case(sorter, toggle):
    import distributed  # in the test extra: a missing install fails here, never skips
    serial, one = _combinational(sorter)
    seq_serial: list = []
    seq_one = prove_sequential_dynamic(toggle, toggle.spec, LIB, random_walks=1,
                                       record=seq_serial)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        address = cluster.scheduler_address
        on_cluster, two = _combinational(sorter, scheduler=address)
        seq_cluster: list = []
        seq_two = prove_sequential_dynamic(toggle, toggle.spec, LIB, random_walks=1,
                                           record=seq_cluster, scheduler=address)
    assert on_cluster == serial and _timeless(two) == _timeless(one)
    assert seq_cluster == seq_serial and _timeless(seq_two) == _timeless(seq_one)


def test_cli_jobs_report_is_the_serial_report(cli, tmp_path):
    reports = []
    for jobs in ("1", "2"):
        out = tmp_path / f"r{jobs}.json"
        code, stdout, _ = cli("simulate", EXAMPLES / "sorter.bool", "--cases", "1", "--jobs",
                              jobs, "--report", out)
        assert code == 0, stdout
        r = json.loads(out.read_text())
        r.pop("seconds")
        reports.append(r)
    assert reports[0] == reports[1] and reports[0]["cases"] == 16


def test_cli_unreachable_scheduler_is_a_clear_error(cli, monkeypatch):
    import distributed  # noqa: F401 -- in the test extra: missing fails, never skips
    monkeypatch.setattr(parallel, "CONNECT_TIMEOUT_S", 1)
    code, _, err = cli("simulate", EXAMPLES / "sorter.bool", "--cases", "0",
                       "--scheduler", "tcp://127.0.0.1:1")
    assert code == 2
    assert "cannot reach the Dask scheduler at tcp://127.0.0.1:1" in err
    assert "Traceback" not in err


@pytest.mark.parametrize("args, message", [
    (("--jobs", "0"), "--jobs must be at least 1"),
    (("--level", "kinematic", "--scheduler", "tcp://127.0.0.1:1"), "--scheduler runs"),
])
def test_cli_refuses_bad_parallel_options(cli, args, message):
    code, _, err = cli("simulate", EXAMPLES / "sorter.bool", *args)
    assert code == 2 and message in err


def test_default_jobs_are_the_cores_this_process_may_use():
    if hasattr(os, "sched_getaffinity"):
        assert parallel.available_cores() == len(os.sched_getaffinity(0))
    else:
        assert parallel.available_cores() == (os.cpu_count() or 1)


def test_user_cells_are_loaded_from_their_files_in_each_worker(tmp_path, monkeypatch):
    """A spawned worker shares nothing with this process: it loads the design's user cell
    from its file, and its changes give the serial figures."""
    from mechc.cells.library import load_library as load
    from mechc.frontends.blif import parse_blif_file
    from tests.test_user_cells import MAJ_BLIF, maj_dir

    cells = maj_dir(tmp_path)
    lib = load([str(cells)])
    assert not lib["maj3"].standard
    blif = tmp_path / "maj.blif"
    blif.write_text(MAJ_BLIF)
    design = compile_spec(parse_blif_file(str(blif)), library=lib)
    assert [c.cell for c in design.netlist.cells.values()] == ["maj3"]
    assert parallel.cell_files(lib) == (str(cells / "maj3.py"),)
    monkeypatch.setattr(parallel, "_pool_context", lambda: multiprocessing.get_context("spawn"))
    serial: list = []
    one = prove_dynamic(design, design.spec, lib, extra=0, max_cases=4, record=serial)
    spawned: list = []
    two = prove_dynamic(design, design.spec, lib, extra=0, max_cases=4, record=spawned, jobs=2)
    assert len(serial) == 4 and spawned == serial
    assert _timeless(two) == _timeless(one)
