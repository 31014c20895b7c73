"""The minimiser's time: a CPU budget handed out as wall-clock limits, and a hard wall-clock end.

The solvers' limits (HiGHS, espresso's loop, local search) are wall clock, but on a shared
machine a wall second buys a fraction of a CPU second, so a wall-clock budget made the result
depend on the load. ``Clock`` counts the process's CPU seconds and stretches what is left by
the slowdown seen so far (wall over CPU seconds, at most ``SLOWDOWN_CAP``), never past the
hard end ``wall`` seconds after the call started.

Steps whose preparation has no time check of its own (prime tables, the covering matrix,
its reductions) can still pass their limit, and under load 4-5 on 2 cores a few CPU seconds
of them are 10-20 s of wall clock. ``hard_stop`` bounds those too: in the main thread it
arms a SIGALRM timer that raises ``WallClockOut`` inside the step at the end, so the caller
keeps the best answer it had before the step (every step here works on its own copies, so
nothing is left half-changed). Elsewhere (worker threads, or when SIGALRM already has a
handler) the steps keep to their own limits only.
"""

from __future__ import annotations

import contextvars
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

#: The stretch of CPU seconds into wall seconds is at most this (a stall early in the call
#: must not let later steps run on for long once the machine is quiet again).
SLOWDOWN_CAP = 2.5
#: The slowdown is counted only after this many CPU seconds (1 before).
SLOWDOWN_MIN_CPU = 0.3


#: Work floors (local search's ``min_steps``, which make a result independent of the load)
#: give way this many seconds before the hard end, so the step returns its best answer
#: instead of being stopped with nothing.
FLOOR_MARGIN = 0.5

_END: contextvars.ContextVar[float | None] = contextvars.ContextVar("minimise_end",
                                                                    default=None)


def floors_hold() -> bool:
    """Whether work floors still hold: False within ``FLOOR_MARGIN`` of the hard end of the
    ``hard_stop`` around the caller (always True outside one)."""
    end = _END.get()
    return end is None or time.perf_counter() < end - FLOOR_MARGIN


class WallClockOut(Exception):
    """The hard end of the minimisation came in the middle of a step."""


class Clock:
    """What is left of ``budget`` CPU seconds and of ``wall`` wall seconds since it was made
    (either None: no such limit)."""

    def __init__(self, budget: float | None, wall: float | None = None):
        self.budget, self.wall = budget, wall
        self.wall0, self.cpu0 = time.perf_counter(), time.process_time()

    def elapsed(self) -> float:
        return time.perf_counter() - self.wall0

    def cpu(self) -> float:
        return time.process_time() - self.cpu0

    def slowdown(self) -> float:
        """Wall seconds per CPU second of this call so far, between 1 and ``SLOWDOWN_CAP``."""
        cpu = self.cpu()
        if cpu < SLOWDOWN_MIN_CPU:
            return 1.0
        return min(SLOWDOWN_CAP, max(1.0, self.elapsed() / cpu))

    def wall_left(self, reserve: float = 0.0) -> float:
        """Wall seconds left before the hard end less ``reserve`` (negative when past it;
        infinite without one)."""
        if not self.wall:
            return float("inf")
        return self.wall - reserve - self.elapsed()

    def cap(self, seconds: float, reserve: float = 0.0) -> float:
        """A step's own limit stretched by the slowdown, never past the wall clock left."""
        return max(0.0, min(seconds * self.slowdown(), self.wall_left(reserve)))

    def floor(self, seconds: float, reserve: float = 0.0) -> float:
        """The least a step is given: ``seconds`` while the wall clock lasts, then 0.05."""
        return max(0.05, min(seconds, self.wall_left(reserve)))

    def left(self, reserve: float = 0.0) -> float:
        """Seconds a step may still be given: the CPU budget left, stretched, within the wall
        clock left."""
        wall = max(0.0, self.wall_left(reserve))
        if not self.budget:
            return wall
        return min(wall, max(0.0, self.budget - self.cpu()) * self.slowdown())

    def end(self, reserve: float = 0.0) -> float | None:
        """The hard end less ``reserve`` as a ``time.perf_counter`` time (None without one)."""
        return None if not self.wall else self.wall0 + self.wall - reserve


def _can_alarm() -> bool:
    if threading.current_thread() is not threading.main_thread():
        return False
    return signal.getsignal(signal.SIGALRM) in (signal.SIG_DFL, signal.SIG_IGN, None) \
        and signal.getitimer(signal.ITIMER_REAL)[0] == 0.0


@contextmanager
def hard_stop(until: float | None) -> Iterator[bool]:
    """Raise ``WallClockOut`` in the body once ``time.perf_counter()`` passes ``until``
    (None: never). Yields whether the stop is armed (False off the main thread or when
    SIGALRM is in use already: the body then only has its own limits). A body that starts
    after ``until`` is stopped at once."""
    if until is None:
        yield False
        return
    token = _END.set(until)
    try:
        if not _can_alarm():
            yield False
            return
        with _alarm(until):
            yield True
    finally:
        _END.reset(token)


@contextmanager
def _alarm(until: float) -> Iterator[None]:
    """SIGALRM raising ``WallClockOut`` in the body at ``until``."""
    state = {"armed": True}

    def ring(_signum, _frame) -> None:
        if state["armed"]:
            state["armed"] = False
            raise WallClockOut()

    old = signal.signal(signal.SIGALRM, ring)
    try:
        signal.setitimer(signal.ITIMER_REAL, max(1e-4, until - time.perf_counter()))
        yield
    finally:
        state["armed"] = False
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)
