"""Independent proof cases on several processes (``--jobs``) or on a Dask distributed cluster
(``--scheduler``), their results handed back in the serial order.

A case function is a module-level function ``fn(shared, lib, case)``: ``shared`` is what every
case needs (the design, the settings), sent to each worker once (a forked worker inherits it,
a spawned or a cluster worker unpickles it); ``case`` is one case's own arguments. Cell
classes are code, so the library is not sent: each worker loads the standard cells and the
design's user cell files itself (:class:`Work`), as a freshly started process must. The caller
merges the results in case order, so what a proof reports cannot depend on how many workers
ran or in which order they finished.
"""

from __future__ import annotations

import hashlib
import multiprocessing
import os
import pickle
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass
from typing import Any

from mechc.cells.library import Library, load_library
from mechc.errors import UsageError

#: Called as (done, total) while cases run; done counts case weights.
OnProgress = Callable[[int, int], None]
CaseFn = Callable[[Any, Library, Any], Any]
#: Seconds to wait for a Dask scheduler to answer before saying it cannot be reached.
CONNECT_TIMEOUT_S = 5


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


@dataclass(frozen=True)
class Work:
    """What a worker needs to run cases: the case function, the shared data and the user cell
    files to load the library from (the standard cells every worker finds itself)."""

    fn: CaseFn
    shared: Any
    cell_files: tuple[str, ...]

    def library(self) -> Library:
        return load_library(files=self.cell_files)


def cell_files(lib: Library) -> tuple[str, ...]:
    """The files of ``lib``'s user cells: what a worker loads to have the same library."""
    files = set()
    for name, cls in lib.cells.items():
        if getattr(cls, "standard", True):
            continue
        src = getattr(cls, "source", None)
        if not src:
            raise UsageError(f"cell '{name}' has no source file: proofs with --jobs > 1 or "
                             "--scheduler load every cell from its file (use --jobs 1)")
        files.add(str(src))
    return tuple(sorted(files))


def run_cases(fn: CaseFn, shared: Any, cases: Sequence[Any], lib: Library, jobs: int = 1,
              scheduler: str | None = None, progress: OnProgress | None = None,
              weights: Sequence[int] | None = None) -> list[Any]:
    """``[fn(shared, lib, c) for c in cases]``, on ``jobs`` processes, or on the Dask cluster
    at ``scheduler``; ``progress`` hears of every finished case (``weights``: how much each
    counts, 1 by default; the heaviest cases start first)."""
    w = list(weights) if weights is not None else [1] * len(cases)
    total = sum(w)
    if scheduler is None and (jobs <= 1 or len(cases) <= 1):
        out, done = [], 0
        for c, k in zip(cases, w):
            out.append(fn(shared, lib, c))
            done += k
            if progress:
                progress(done, total)
        return out
    work = Work(fn, shared, cell_files(lib))
    if scheduler is not None:
        blob = pickle.dumps(work, protocol=pickle.HIGHEST_PROTOCOL)
        return _on_cluster(scheduler, blob, list(cases), w, progress)
    return _on_pool(min(jobs, len(cases)), work, list(cases), w, progress)


def longest_first(weights: Sequence[int]) -> list[int]:
    """Case indices, the heaviest first (ties in case order): started in this order, the
    long cases do not end up alone at the end while the other workers idle (the longest-
    processing-time rule)."""
    return sorted(range(len(weights)), key=lambda i: (-weights[i], i))


# ---- a process pool ---------------------------------------------------------------------------
_WORKER: tuple[CaseFn, Any, Library] | None = None
#: CPU seconds each worker process (by id) spent in the cases of the last pool run: how evenly
#: the cases fell, a figure the machine's load does not move as it moves wall time (read by
#: benchmarks/parallel.py).
pool_cpu: dict[int, float] = {}


def _start_worker(work: Work | bytes) -> None:
    """Pool initializer: the work (a forked worker inherits it as it is; a spawned one gets it
    pickled) and the library, once per process."""
    global _WORKER
    if not isinstance(work, Work):
        work = pickle.loads(work)
    _WORKER = (work.fn, work.shared, work.library())


def _pool_case(case: Any) -> tuple[int, float, Any]:
    """The case's result, with the worker's process id and the CPU seconds it took."""
    fn, shared, lib = _WORKER
    t0 = time.process_time()
    out = fn(shared, lib, case)
    return os.getpid(), time.process_time() - t0, out


def _pool_context():
    """fork where the OS has it (a worker starts without importing mechc again); the worker
    gets everything through its initializer, so spawn works the same."""
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


def _on_pool(jobs: int, work: Work, cases: list, weights: list[int],
             progress: OnProgress | None, context=None) -> list[Any]:
    out: list[Any] = [None] * len(cases)
    total, done = sum(weights), 0
    busy = pool_cpu
    busy.clear()
    ctx = context or _pool_context()
    # a forked worker is handed the parent's objects without pickling (the design of an
    # 81-cell circuit takes 0.07 s to pickle and 0.12 s to unpickle in every worker);
    # a spawned one starts empty and gets them pickled
    arg = work if ctx.get_start_method() == "fork" else pickle.dumps(
        work, protocol=pickle.HIGHEST_PROTOCOL)
    with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx,
                             initializer=_start_worker, initargs=(arg,)) as pool:
        pending = {pool.submit(_pool_case, cases[i]): i for i in longest_first(weights)}
        try:
            while pending:
                finished, _ = wait(pending, return_when=FIRST_COMPLETED)
                for f in finished:
                    i = pending.pop(f)
                    pid, cpu, out[i] = f.result()
                    busy[pid] = busy.get(pid, 0.0) + cpu
                    done += weights[i]
                    if progress:
                        progress(done, total)
        except BaseException:
            for f in pending:
                f.cancel()
            raise
    return out


# ---- a Dask cluster ---------------------------------------------------------------------------
_CLUSTER_WORK: dict[str, tuple[CaseFn, Any, Library]] = {}
CLUSTER_KEEP = 4  # proofs' work a cluster worker keeps unpacked


def _cluster_case(blob: bytes, key: str, case: Any) -> Any:
    """A case on a cluster worker: the work is unpacked once per worker process (by key)."""
    if key not in _CLUSTER_WORK:
        work: Work = pickle.loads(blob)
        while len(_CLUSTER_WORK) >= CLUSTER_KEEP:  # a long-lived worker: the newest proofs
            del _CLUSTER_WORK[next(iter(_CLUSTER_WORK))]
        _CLUSTER_WORK[key] = (work.fn, work.shared, work.library())
    fn, shared, lib = _CLUSTER_WORK[key]
    return fn(shared, lib, case)


def _on_cluster(address: str, blob: bytes, cases: list, weights: list[int],
                progress: OnProgress | None) -> list[Any]:
    # dask.distributed is an optional dependency (the `cluster` extra), needed only here
    try:
        from distributed import Client, as_completed
    except ModuleNotFoundError:
        raise UsageError("--scheduler needs dask.distributed: pip install 'mechc[cluster]'") \
            from None
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError, TypeError) as e:
        raise UsageError(f"cannot reach the Dask scheduler at {address}: {e}") from None
    try:
        with client.as_current():  # as_completed finds its client as the current one
            return _gather(client, as_completed, blob, cases, weights, progress)
    finally:
        client.close()


def _gather(client, as_completed, blob: bytes, cases: list, weights: list[int],
            progress: OnProgress | None) -> list[Any]:
    """Each case a task on the cluster (the work sent once to every worker); results in case
    order."""
    key = hashlib.sha256(blob).hexdigest()
    [shared] = client.scatter([blob], broadcast=True)
    order = longest_first(weights)
    futures = [client.submit(_cluster_case, shared, key, cases[i], pure=False) for i in order]
    index = {f.key: i for i, f in zip(order, futures)}
    out: list[Any] = [None] * len(cases)
    total, done = sum(weights), 0
    for f in as_completed(futures):
        i = index[f.key]
        out[i] = f.result()
        done += weights[i]
        if progress:
            progress(done, total)
    return out
