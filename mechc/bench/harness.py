"""What every study of the speed benchmark shares: the run's record (:class:`Bench`, rows in
the CSV's :data:`COLUMNS` and the summary), the clock studies are timed with, and a timed
dynamic proof, so each study's rows are measured and written the same way.
"""

from __future__ import annotations

import csv
import time
from dataclasses import dataclass, field
from pathlib import Path

from mechc.bench.circuits import Circuit
from mechc.cells.library import Library
from mechc.ir.design import Design
from mechc.physics.scene import DynSettings
from mechc.proofs.dynamic import prove_dynamic
from mechc.proofs.report import ProofReport

clock = time.process_time  # CPU seconds of this process: the machine is shared, and every
#                            timed path here is single-threaded
BREAKING = ("solver", "contact", "settle")  # failure kinds that say the numerics did not hold
COLUMNS = ["section", "circuit", "level", "variant", "dt_s", "iterations", "move_time_s",
           "spring_factor", "mass_factor", "cases", "seconds", "seconds_per_case",
           "error_fraction", "max_violation_mm", "passed", "solver_ok", "failure_kinds",
           "steps", "default", "margin_deg"]


@dataclass
class Bench:
    """One run's record: every study adds its CSV rows, summary figures and printed lines here."""

    lib: Library
    quick: bool
    rows: list[dict] = field(default_factory=list)
    summary: dict[str, object] = field(default_factory=dict)
    log: list[str] = field(default_factory=list)

    def say(self, text: str) -> None:
        print(text, flush=True)
        self.log.append(text)

    def row(self, **kw) -> dict:
        r = {c: kw.get(c, "") for c in COLUMNS}
        self.rows.append(r)
        return r



def cell_count(d: Design) -> int:
    return len(d.netlist.cells)


def solver_ok(r: ProofReport) -> bool:
    return not any(r["failure_kinds"].get(k) for k in BREAKING)


def time_dynamic(b: Bench, c: Circuit, st: DynSettings, prune: bool | None = None,
                 max_cases: int | None = None,
                 freeze: str | None = None) -> tuple[ProofReport, float]:
    """A dynamic proof of ``c`` (its own case count unless given) and the CPU seconds it took
    (at ``st`` only: no re-run of its failures at finer settings)."""
    kw: dict = {"recheck": False} if prune is None else {"recheck": False, "prune": prune}
    if freeze is not None:
        kw["freeze"] = freeze
    t0 = clock()
    r = prove_dynamic(c.design, c.design.spec, b.lib, st, extra=0,
                      max_cases=max_cases if max_cases is not None else c.max_cases, **kw)
    return r, clock() - t0



def failure_kinds(r: ProofReport) -> str:
    return " ".join(f"{k}={v}" for k, v in r["failure_kinds"].items())


def scene_types(d: Design) -> dict[str, str]:
    return {c.id: c.cell for c in d.netlist.cells.values()}


def write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
