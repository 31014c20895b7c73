"""Compile time and parts against circuit size: two-level against multi-level synthesis.

    python benchmarks/scale.py [--time-limit 120] [--max-two-level-inputs 16]
                               [--mcnc DIR] [--only NAME,...] [--methods two-level,multi-level]
                               [--markdown] [--chart FILE]

Circuits (``mechc.bench.scale_circuits``): ripple adders of 2-32 bits, a 74181-style ALU, a
BCD-to-7-segment decoder, magnitude comparators of 8-32 bits, array multipliers 4x4-12x12;
and, with ``--mcnc DIR`` (default: an ``mcnc`` directory beside the repository, skipped when
absent; the MCNC PLAs are not shipped with mechc), every PLA there of at most
``--max-two-level-inputs`` inputs. Each circuit is compiled by ``mechc compile`` in a process of
its own, stopped after ``--time-limit`` CPU seconds (or ``--wall-factor`` times that in wall):
two-level from its ``.bool`` (or the PLA), and multi-level from its structural Verilog with
``--levels multi`` where ``mechc compile --help`` offers ``--levels`` (else that column stays
empty and the run says why). A two-level compile is not attempted above
``--max-two-level-inputs`` inputs (an n-bit adder's two-level form has
about 2**n products); the table says so instead of hanging.

Compile time is the CPU time (user + system) of the ``mechc compile`` process, less the CPU time
of starting mechc (measured in the same run, ``mechc compile --help``), so other load on a
shared machine does not inflate it: parse, minimise or synthesise, map, place, assemble,
checks, proofs, write. The fitted exponent is the slope
of log(time) against log(cells) by least squares, per method. ``--markdown`` prints the table
in Markdown and rewrites it in docs/performance.md, keeping the rows and columns this run did
not measure (``--only``, ``--methods``) as they were, and fits over the whole table;
``--chart`` (default docs/perf/scale.png) draws time and parts against cells on log-log axes.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import resource
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mechc.bench.scale_circuits import Circuit, suite

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- scale table begin -->", "<!-- scale table end -->"
SUMMARY = re.compile(r"-> .*?: (\d+) cells \(.*?\), (\d+) parts, .*, ([\d.]+) s$")


@dataclass
class Run:
    """One compile: cells, parts, seconds, or why there are none."""

    cells: int | None = None
    parts: int | None = None
    seconds: float | None = None
    note: str = ""
    status: int | None = None

    def cell_text(self, key: str) -> str:
        v = getattr(self, key)
        if v is None:
            return self.note if key == "cells" else ""
        if key == "seconds":
            return f"{v:.2f}" + (f" ({self.note})" if self.note else "")
        return str(v)


@dataclass
class Row:
    name: str
    inputs: int
    outputs: int
    runs: dict[str, Run] = field(default_factory=dict)


#: The wall-clock allowance of a compile, as a multiple of its CPU limit (a loaded machine;
#: ``--wall-factor`` sets it).
WALL_FACTOR = [5.0]


def mechc(*args: str, cpu_limit: float | None = None) -> subprocess.CompletedProcess:
    """``mechc ARGS`` in a fresh interpreter on this checkout's code, stopped by the kernel
    after ``cpu_limit`` CPU seconds (so other load on the machine does not cut it short);
    ``.cpu`` on the result is the CPU seconds it took."""
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)

    def limit() -> None:
        if cpu_limit is not None:
            secs = int(math.ceil(cpu_limit))
            resource.setrlimit(resource.RLIMIT_CPU, (secs, secs + 5))

    p = subprocess.run([sys.executable, "-m", "mechc", *args], capture_output=True, text=True,
                       timeout=cpu_limit * WALL_FACTOR[0] if cpu_limit else None, env=env,
                       preexec_fn=limit)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    p.cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return p


#: The columns, in the table's order.
METHODS = ("two-level", "multi-level")


def table_rows(doc: str) -> list[Row]:
    """The rows of the table in ``doc`` (between the markers), read back into runs."""
    if BEGIN not in doc or END not in doc:
        return []
    lines = [ln for ln in doc.split(BEGIN, 1)[1].split(END, 1)[0].splitlines()
             if ln.startswith("|")]
    if len(lines) < 2:
        return []
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    out = []
    for ln in lines[2:]:
        cells = dict(zip(head, (c.strip() for c in ln.strip("|").split("|"))))
        row = Row(cells["circuit"], int(cells["inputs"]), int(cells["outputs"]))
        for m in METHODS:
            if f"{m} cells" not in cells or cells[f"{m} cells"] in ("", "—"):
                continue
            row.runs[m] = parse_run(cells[f"{m} cells"], cells[f"{m} parts"], cells[f"{m} s"])
        out.append(row)
    return out


def parse_run(cells: str, parts: str, seconds: str) -> Run:
    """A table entry back into a ``Run`` (the inverse of ``Run.cell_text``)."""
    if not cells.isdigit():
        return Run(note=cells)
    m = re.fullmatch(r"([\d.]+)(?: \((.*)\))?", seconds)
    if m is None:
        raise ValueError(f"unreadable seconds entry {seconds!r}")
    return Run(int(cells), int(parts) if parts.isdigit() else None, float(m.group(1)),
               note=m.group(2) or "")


def merge(old: list[Row], new: list[Row]) -> tuple[list[Row], int]:
    """The old table's rows with this run's measurements over them (rows in the old order,
    new circuits after), and how many entries (circuit and column) kept the old value."""
    fresh = {r.name: r for r in new}
    out, kept = [], 0
    for r in old:
        if r.name in fresh:
            n = fresh.pop(r.name)
            kept += sum(1 for m in r.runs if m not in n.runs)
            r = Row(n.name, n.inputs, n.outputs, {**r.runs, **n.runs})
        else:
            kept += len(r.runs)
        out.append(r)
    return out + list(fresh.values()), kept


#: CPU seconds of starting mechc (set by main: the least of three runs).
STARTUP = [0.0]


def has_levels() -> bool:
    """Whether this mechc's compile offers multi-level synthesis (``--levels``)."""
    return "--levels" in mechc("compile", "--help").stdout


def compile_once(src: Path, out: Path, extra: list[str], limit: float) -> Run:
    """Compile ``src``; the summary line gives cells, parts and seconds."""
    try:
        p = mechc("compile", str(src), "-o", str(out), "--quiet", *extra,
                  cpu_limit=limit + STARTUP[0])
    except subprocess.TimeoutExpired:
        return Run(note=f"over {limit * WALL_FACTOR[0]:g} s wall")
    if p.returncode < 0:  # SIGXCPU (or SIGKILL past the hard limit): the CPU limit ran out
        return Run(note=f"over {limit:g} CPU s")
    m = next((SUMMARY.search(line) for line in p.stdout.splitlines() if SUMMARY.search(line)),
             None)
    if m is None:
        err = (p.stderr.strip().splitlines() or ["no summary"])[-1]
        err = re.sub(r"^\S*?:\d+:\d+: error: ", "", err)  # the temporary file's place
        return Run(note=f"error: {err[:80].replace('|', '/')}", status=p.returncode)
    run = Run(int(m.group(1)), int(m.group(2)), max(p.cpu - STARTUP[0], 0.0),
              status=p.returncode)
    if p.returncode != 0:  # a whole compile still: its time counts, the table says so
        run.note = "design checks failed" if "DESIGN CHECKS FAILED" in p.stderr \
            else "proof failed"
    elif out.exists():  # the file agrees with the summary line
        stats = json.loads(out.read_text())["stats"]
        assert stats["cells"] == run.cells and stats["parts"] == run.parts
    return run


def pla_size(path: Path) -> tuple[int, int]:
    n = m = 0
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts[:1] == [".i"]:
            n = int(parts[1])
        elif parts[:1] == [".o"]:
            m = int(parts[1])
    return n, m


def fit(rows: list[Row], method: str) -> tuple[float, int] | None:
    """Slope of log(seconds) on log(cells), and the number of points (every compile that
    finished, also one whose design checks failed: it did all the work)."""
    pts = [(r.runs[method].cells, r.runs[method].seconds) for r in rows
           if method in r.runs and r.runs[method].seconds and r.runs[method].cells]
    if len(pts) < 3:
        return None
    x = np.log([p[0] for p in pts])
    y = np.log([max(p[1], 1e-3) for p in pts])
    return float(np.polyfit(x, y, 1)[0]), len(pts)


def markdown(rows: list[Row], methods: list[str]) -> str:
    head = "| circuit | inputs | outputs |"
    rule = "|---|---|---|"
    for m in methods:
        head += f" {m} cells | {m} parts | {m} s |"
        rule += "---|---|---|"
    lines = [head, rule]
    for r in rows:
        line = f"| {r.name} | {r.inputs} | {r.outputs} |"
        for m in methods:
            run = r.runs.get(m, Run(note="—"))
            line += f" {run.cell_text('cells')} | {run.cell_text('parts')} | " \
                    f"{run.cell_text('seconds')} |"
        lines.append(line)
    return "\n".join(lines)


def chart(rows: list[Row], methods: list[str], fits: dict, path: Path) -> None:
    import matplotlib  # the chart only: matplotlib loads in a second

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    for m, colour in zip(methods, ("tab:blue", "tab:orange")):
        pts = [(r.runs[m].cells, r.runs[m].seconds, r.runs[m].parts, r.name) for r in rows
               if m in r.runs and r.runs[m].cells and r.runs[m].seconds is not None]
        if not pts:
            continue
        c = np.array([p[0] for p in pts], dtype=float)
        ax1.scatter(c, [max(p[1], 1e-3) for p in pts], color=colour, label=m)
        ax2.scatter(c, [p[2] for p in pts], color=colour, label=m)
        for p in pts:
            ax1.annotate(p[3], (p[0], max(p[1], 1e-3)), fontsize=6, alpha=0.7)
        if fits.get(m):
            b = fits[m][0]
            x = np.log(c)
            a = float(np.mean(np.log([max(p[1], 1e-3) for p in pts]) - b * x))
            xs = np.geomspace(c.min(), c.max(), 20)
            ax1.plot(xs, np.exp(a) * xs ** b, color=colour, lw=1,
                     label=f"{m}: time ~ cells^{b:.2f}")
    for ax, what in ((ax1, "compile CPU time (s)"), (ax2, "parts")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("cells of the compiled design")
        ax.set_ylabel(what)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    ax1.set_title("mechc compile: CPU time against size")
    ax2.set_title("parts against size")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--time-limit", type=float, default=120.0, metavar="S",
                    help="CPU seconds one compile may take, start-up aside (default: "
                    "%(default)s; and --wall-factor times that in wall time)")
    ap.add_argument("--wall-factor", type=float, default=WALL_FACTOR[0], metavar="F",
                    help="wall-clock allowance of a compile as a multiple of its CPU limit "
                    "(default: %(default)s; more on a machine busy with other work)")
    ap.add_argument("--max-two-level-inputs", type=int, default=16, metavar="N",
                    help="two-level compiles are not attempted above N inputs (default: "
                    "%(default)s)")
    ap.add_argument("--mcnc", type=Path, default=ROOT.parent / "shared" / "mcnc",
                    help="directory of MCNC PLAs (skipped when absent)")
    ap.add_argument("--only", help="comma-separated circuit names")
    ap.add_argument("--markdown", action="store_true",
                    help="print the table in Markdown and rewrite it in docs/performance.md")
    ap.add_argument("--methods", default=",".join(METHODS),
                    help="comma-separated columns to measure (default: %(default)s)")
    ap.add_argument("--chart", type=Path, default=ROOT / "docs" / "perf" / "scale.png")
    args = ap.parse_args(argv)
    WALL_FACTOR[0] = args.wall_factor
    wanted = [m for m in METHODS if m in args.methods.split(",")]
    if not wanted or set(args.methods.split(",")) - set(METHODS):
        ap.error(f"--methods: choose from {', '.join(METHODS)}")
    levels = has_levels()
    STARTUP[0] = min(mechc("compile", "--help").cpu for _ in range(3))
    print(f"start-up: {STARTUP[0]:.2f} CPU s (subtracted from every compile)")
    methods = [m for m in wanted if m == "two-level" or levels]
    if not levels:
        print("note: this mechc's compile has no --levels option: multi-level synthesis is not "
              "there yet, so only two-level is measured (the multi-level column stays empty)")
    circuits: list[tuple[str, Circuit | Path]] = [(c.name, c) for c in suite()]
    if args.mcnc.is_dir():
        circuits += [(p.stem, p) for p in sorted(args.mcnc.glob("*.pla"))
                     if pla_size(p)[0] <= args.max_two_level_inputs]
    else:
        print(f"note: no MCNC directory at {args.mcnc}: the MCNC PLAs are left out")
    if args.only:
        keep = set(args.only.split(","))
        circuits = [c for c in circuits if c[0] in keep]
    rows: list[Row] = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for name, c in circuits:
            if isinstance(c, Path):
                n, m = pla_size(c)
                two_src, multi_src = c, c
            else:
                n, m = c.n, len(c.outputs)
                text = c.bool_text()
                two_src = None
                if text is not None and n <= args.max_two_level_inputs:
                    two_src = work / f"{name}.bool"
                    two_src.write_text(text)
                multi_src = work / f"{name}.v"
                multi_src.write_text(c.verilog_text())
            row = Row(name, n, m)
            if "two-level" not in methods:
                pass
            elif two_src is None or n > args.max_two_level_inputs:
                row.runs["two-level"] = Run(note=f"not attempted (> {args.max_two_level_inputs}"
                                            " inputs)")
            else:
                row.runs["two-level"] = compile_once(two_src, work / f"{name}.2.json",
                                                     ["--levels", "2"] if levels else [],
                                                     args.time_limit)
            if "multi-level" in methods:
                row.runs["multi-level"] = compile_once(multi_src, work / f"{name}.m.json",
                                                       ["--levels", "multi"], args.time_limit)
            rows.append(row)
            print(f"{name:>10}: {n} inputs, " + "; ".join(
                f"{k} {r.cells or '-'} cells {r.parts or '-'} parts "
                f"{'' if r.seconds is None else f'{r.seconds:.2f} s'} {r.note}".rstrip()
                for k, r in row.runs.items()), flush=True)
    kept = 0
    if args.markdown:  # the table's other rows and columns stay as the run before left them
        rows, kept = merge(table_rows(DOC.read_text()), rows)
        methods = [m for m in METHODS if any(m in r.runs for r in rows)]
    fits = {m: fit(rows, m) for m in methods}
    for m, f in fits.items():
        if f is None:
            print(f"{m}: too few compiles to fit an exponent")
        else:
            print(f"{m}: compile time ~ cells^{f[0]:.2f} (least squares on {f[1]} circuits)")
    big = [r for r in rows for m in methods if r.runs.get(m) and (r.runs[m].cells or 0) >= 900]
    for r in big:
        for m in methods:
            run = r.runs.get(m)
            if run and run.cells and run.cells >= 900:
                print(f"largest: {r.name} {m}: {run.cells} cells in {run.seconds:.1f} s")
    if args.chart:
        chart(rows, methods, fits, args.chart)
        print(f"chart: {args.chart}")
    if args.markdown:
        table = markdown(rows, methods)
        exps = "; ".join(f"{m}: time ~ cells^{f[0]:.2f} ({f[1]} circuits)"
                         for m, f in fits.items() if f)
        text = table + (f"\n\nFitted exponent: {exps}." if exps else "")
        if kept:
            text += (f" {kept} of the table's entries were not measured in this run: they "
                     "are the run before's.")
        print(text)
        doc = DOC.read_text()
        if BEGIN in doc and END in doc:
            head, rest = doc.split(BEGIN, 1)
            DOC.write_text(head + BEGIN + "\n" + text + "\n" + END + rest.split(END, 1)[1])
    return 0 if all(not math.isnan(f[0]) for f in fits.values() if f) else 1


if __name__ == "__main__":
    sys.exit(main())
