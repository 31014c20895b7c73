"""Terminal output: progress for long jobs and plain tables for summaries (stderr/stdout)."""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Sequence


class Progress:
    """A progress bar on stderr that appears only once a job has run for ``delay`` seconds.

    On a terminal it redraws one line; elsewhere (CI logs) it prints a line every 10 %.
    """

    def __init__(self, total: int, label: str, delay: float = 1.5, stream=None,
                 enabled: bool = True):
        self.total, self.label, self.delay = max(1, total), label, delay
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.t0 = time.perf_counter()
        self.last_draw = 0.0
        self.last_decile = -1
        self.shown = False
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()

    def update(self, done: int, note: str = "") -> None:
        if not self.enabled:
            return
        now = time.perf_counter()
        if now - self.t0 < self.delay:
            return
        frac = min(1.0, done / self.total)
        if self.tty:
            if now - self.last_draw < 0.1 and done < self.total:
                return
            self.last_draw = now
            width = 30
            fill = int(frac * width)
            eta = (now - self.t0) / frac * (1 - frac) if frac > 0 else 0
            line = (f"\r{self.label} [{'#' * fill}{'.' * (width - fill)}] {done}/{self.total}"
                    f" {frac:4.0%} eta {eta:4.0f}s {note}")
            self.stream.write(line[:120].ljust(80))
            self.stream.flush()
            self.shown = True
        else:
            decile = int(frac * 10)
            if decile > self.last_decile:
                self.last_decile = decile
                self.stream.write(f"{self.label}: {done}/{self.total} ({frac:.0%}) {note}\n")
                self.stream.flush()
                self.shown = True

    def retotal(self, total: int) -> None:
        """A job that finds more work on the way (a screened proof's fallback round, a
        re-run of failures) grows its total: the count goes on, and off a terminal the next
        update prints at once (else the lines would wait for a decile already passed)."""
        total = max(1, total)
        if total != self.total:
            self.total = total
            self.last_decile = -1

    def counter(self, unit: str) -> Callable[..., None]:
        """The callback a job reports to as ``(done, total)`` in ``unit``, or ``(done, total,
        what)`` for other work on the way (a proof's progress, ``mechc.proofs.registry``)."""

        def tick(done: int, total: int, what: str = "") -> None:
            self.retotal(total)
            self.update(done, what or unit)

        return tick

    def close(self) -> None:
        if self.shown and self.tty:
            self.stream.write("\n")
            self.stream.flush()


def table(rows: Sequence[Sequence[object]], header: Sequence[str]) -> str:
    cells = [[str(h) for h in header]] + [[_fmt(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _fmt(v: object) -> str:
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def finite_float(text: str) -> float:
    """An argparse type: a finite number. ``float()`` alone accepts 'nan' and 'inf', which slip
    through every ``<= 0`` range check and fail much later, deep in a solver."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got '{text}'") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, got '{text}'")
    return v


def int_at_least(lo: int):
    """An argparse type: a whole number no smaller than ``lo`` (a clear message otherwise)."""
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'") from None
        if v < lo:
            raise argparse.ArgumentTypeError(f"must be at least {lo}")
        return v

    return parse
