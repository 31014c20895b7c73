"""Multi-output minimisation on MCNC two-level PLAs against espresso, run in the same process.

    python benchmarks/mcnc.py DIR [--max-inputs 16] [--markdown]
    python benchmarks/mcnc.py            # the small PLAs under tests/logic/pla (for CI)
    python benchmarks/mcnc.py --random 40 --seed 1 [--markdown]   # held-out random PLAs

For every .pla in DIR with at most ``--max-inputs`` inputs: mechc's distinct products (what
espresso's ``.p`` counts) and minimisation seconds; espresso's product count from the original
espresso through pyeda (``pip install -e '.[bench]'``), or, where pyeda is not installed, the
published count from the table below; and the parts of the mapped design (AND/OR/NOT-family
cells, before amplifiers) with the per-output minimiser of before multi-output minimisation
(``multi_output=False``) and with the default one. Every cover is checked against the spec on
every vector by the minimiser itself, and the mapped design of the default one is simulated
on every input vector against the spec (the run stops at a mismatch). ``--markdown``
rewrites the table in docs/minimisation.md. The MCNC PLAs (the LGSynth'91 two-level suite)
are not shipped with mechc.

``--random N --seed S``: N random PLAs shaped like the MCNC ones (``random_pla.py``: 8-16
inputs, 5-40 outputs, 20-500 rows, don't-care rows), which the minimiser was never tuned on:
mechc's distinct products and seconds against espresso's (through pyeda, required here),
without the mapping. ``--markdown`` then rewrites the random table in docs/minimisation.md.
Exit status 1 if mechc has more products than espresso on any PLA, or (``--random``) takes
over 10 s on any.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from mechc.cells.library import load_library
from mechc.errors import MechcError
from mechc.frontends.pla import parse_pla_file
from mechc.passes.map import map_equations
from mechc.passes.minimise import MinimiseOptions, minimise
from mechc.proofs.logic import prove_logic

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "minimisation.md"
#: The same measurements before the minimiser's speed-up (products, parts, seconds per PLA):
#: the reference for "no more parts than before".
BASELINE = Path(__file__).with_name("mcnc_baseline.json")
BEGIN, END = "<!-- mcnc table begin -->", "<!-- mcnc table end -->"
RBEGIN, REND = "<!-- random table begin -->", "<!-- random table end -->"
#: The minimisation of one PLA must end within this many seconds (wall clock).
MAX_SECONDS = 10.0
#: espresso's product counts on the MCNC PLAs (multi-output heuristic cover), used only when
#: pyeda is not installed.
PUBLISHED = {"5xp1": 65, "9sym": 86, "Z5xp1": 76, "alu4": 575, "apex4": 435, "b12": 42,
             "clip": 119, "ex1010": 286, "ex_dc2": 39, "ex_f51m": 77, "ex_root": 57,
             "ex_sqr6": 53, "rd53": 31, "rd73": 127, "rd84": 255, "sao2": 58, "t481": 481,
             "table3": 175, "misex1": 12, "bw": 22, "ex5": 74, "misex2": 28, "misex3c": 197}


def espresso_products(path: Path) -> tuple[int | None, float, str]:
    """(products, seconds, source) from pyeda's espresso on the PLA's own rows."""
    try:  # benchmark-only dependency (the bench extra)
        from pyeda.boolalg.espresso import DTYPE, FTYPE, RTYPE, espresso, set_config
    except ImportError:
        return PUBLISHED.get(path.stem), 0.0, "published"
    n = m = 0
    kind = "fd"
    rows = set()
    for raw in path.read_text().splitlines():
        line = raw.split("#")[0].strip()
        if not line:
            continue
        if line.startswith("."):
            parts = line.split()
            if parts[0] == ".i":
                n = int(parts[1])
            elif parts[0] == ".o":
                m = int(parts[1])
            elif parts[0] == ".type":
                kind = parts[1]
            continue
        chars = [c for c in line if c not in " \t|"]
        inp = tuple({"0": 1, "1": 2}.get(c, 3) for c in chars[:n])
        out = tuple({"1": 1, "4": 1, "-": 2, "2": 2}.get(c, 0) for c in chars[n:n + m])
        if kind in ("fr", "fdr"):
            out = tuple({"1": 1, "4": 1, "-": 2, "2": 2, "0": 0, "3": 0}.get(c, 3)
                        for c in chars[n:n + m])
        rows.add((inp, out))
    intype = {"f": FTYPE, "fd": FTYPE | DTYPE, "fr": FTYPE | RTYPE,
              "fdr": FTYPE | DTYPE | RTYPE}.get(kind)
    if intype is None:
        return PUBLISHED.get(path.stem), 0.0, "published"
    if kind in ("fr", "fdr"):
        # pyeda reads 0 as off, 1 as on, 2 as don't care; a '~' (3 here) is left out
        rows = {(i, tuple(2 if v == 3 else v for v in o)) for i, o in rows}
    set_config(single_expand=False, remove_essential=True, force_irredundant=True,  # defaults
               unwrap_onset=True, recompute_onset=False, use_super_gasp=False,
               skip_make_sparse=False)
    t0 = time.perf_counter()
    cover = espresso(n, m, rows, intype=intype)
    return len({inp for inp, _ in cover}), time.perf_counter() - t0, "pyeda"


#: pyeda's espresso ran for over 10 minutes on some random PLAs (14 inputs, 34 outputs);
#: the random set gives it this long in a child process, then counts it as timed out.
ESPRESSO_TIMEOUT_S = 60.0


def _espresso_child(path: str, conn) -> None:
    conn.send(espresso_products(Path(path)))
    conn.close()


def espresso_products_timed(path: Path, timeout: float = ESPRESSO_TIMEOUT_S
                            ) -> tuple[int | None, float, str]:
    """``espresso_products`` in a forked child stopped after ``timeout`` seconds (espresso
    is C code: it cannot be interrupted in this process). Source "timeout" when stopped."""
    import multiprocessing
    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_espresso_child, args=(str(path), send))
    child.start()
    send.close()
    if recv.poll(timeout):
        got = recv.recv()
        child.join()
        return got
    child.kill()
    child.join()
    return None, timeout, "timeout"


def mapped(eq, lib, spec=None) -> tuple[int, int]:
    """(parts, distinct products) of the design the mapper builds (it may take the
    per-output covers the equations carry as their alternative, where those cost fewer).
    With ``spec`` the mapped netlist is also simulated on every input vector against it."""
    m = map_equations(eq, lib)
    built = m.equations if m.equations is not None else eq
    if spec is not None:
        report = prove_logic(m.netlist, spec, method="exhaustive")
        if not report.passed:
            raise SystemExit(f"{spec.path}: mapped design differs from the spec: "
                             f"{report.failures[:1]}")
    return sum(lib[c.cell].cost(len(c.inputs)) for c in m.netlist.cells.values()), built.products


def baseline() -> dict:
    """Per PLA name the recorded measurements of before (empty without the file)."""
    if not BASELINE.exists():
        return {}
    return json.loads(BASELINE.read_text())["plas"]


def run(paths: list[Path]) -> list[dict]:
    lib = load_library()
    base = baseline()
    out = []
    for path in paths:
        spec = parse_pla_file(path)
        t0, c0 = time.perf_counter(), time.process_time()
        eq = minimise(spec)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
        t1 = time.perf_counter()
        before = minimise(spec, MinimiseOptions(multi_output=False))
        before_seconds = time.perf_counter() - t1
        esp, esp_s, source = espresso_products(path)
        parts_after, built = mapped(eq, lib, spec)  # simulated on every vector
        row = {"name": path.stem, "inputs": spec.n, "outputs": len(spec.outputs),
               "products": eq.products, "espresso": esp, "espresso_s": esp_s, "source": source,
               "seconds": seconds, "cpu": cpu, "proven": eq.proven,
               "limited": len(eq.time_limited),
               "before_products": before.products, "before_s": before_seconds,
               "parts_before": mapped(before, lib)[0], "parts_after": parts_after,
               "built_products": built,
               "parts_baseline": base.get(path.stem, {}).get("parts"),
               "seconds_baseline": base.get(path.stem, {}).get("seconds"),
               "cpu_baseline": base.get(path.stem, {}).get("cpu"),
               "time_limited": list(eq.time_limited)}
        out.append(row)
        print(f"{row['name']:>10} {row['inputs']:>3} {row['outputs']:>3} "
              f"products {row['products']:>4} (espresso {esp}, before {row['before_products']})"
              f" {seconds:6.2f} s (cpu {cpu:.2f} s){' proven' if eq.proven else ''}"
              f"{f' [{len(eq.time_limited)} time limits]' if eq.time_limited else ''}"
              f"  parts {row['parts_before']} -> {row['parts_after']} "
              f"(built with {built} products; before the speed-up {row['parts_baseline']})"
              f"{' ' + '; '.join(eq.time_limited) if eq.time_limited else ''}", flush=True)
    return out


def run_random(count: int, seed: int, opts: MinimiseOptions | None = None) -> list[dict]:
    """Minimise ``count`` random MCNC-shaped PLAs (seed ``seed``) and run espresso on each."""
    import tempfile

    from random_pla import random_set  # benchmarks/ is on the path when run as a script
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, text in random_set(count, seed):
            path = Path(tmp) / f"{name}.pla"
            path.write_text(text)
            spec = parse_pla_file(path)
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                eq = minimise(spec, opts)
            except MechcError as e:  # reported as a row, the run goes on
                out.append({"name": name, "inputs": spec.n, "outputs": len(spec.outputs),
                            "error": str(e)})
                print(f"{name}: {e}", flush=True)
                continue
            seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
            esp, esp_s, source = espresso_products_timed(path)
            row = {"name": name, "inputs": spec.n, "outputs": len(spec.outputs),
                   "rows": text.count("\n") - 5, "products": eq.products, "espresso": esp,
                   "espresso_s": esp_s, "source": source, "seconds": seconds, "cpu": cpu,
                   "proven": eq.proven, "time_limited": list(eq.time_limited)}
            out.append(row)
            print(f"{name:>22} products {eq.products:>4} (espresso {esp} in {esp_s:.2f} s) "
                  f"{seconds:6.2f} s (cpu {cpu:.2f} s){' proven' if eq.proven else ''}"
                  f"{' ' + '; '.join(eq.time_limited) if eq.time_limited else ''}", flush=True)
    return out


def markdown_random(rows: list[dict], count: int, seed: int) -> str:
    lines = [f"`python benchmarks/mcnc.py --random {count} --seed {seed}`", "",
             "| PLA | in | out | rows | mechc products | espresso products | mechc s "
             "| mechc cpu s | espresso s | proven | time limits |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['name']} | {r['inputs']} | {r['outputs']} | error: "
                         f"{r['error']} |||||||")
            continue
        lines.append(f"| {r['name']} | {r['inputs']} | {r['outputs']} | {r['rows']} | "
                     f"{r['products']} | {r['espresso'] or 'out of time'} | "
                     f"{r['seconds']:.1f} | {r['cpu']:.1f} | {r['espresso_s']:.2f} | "
                     f"{'yes' if r['proven'] else 'no'} | {len(r['time_limited'])} |")
    return "\n".join(lines)


def markdown(rows: list[dict]) -> str:
    lines = ["| PLA | in | out | mechc products | espresso products | per-output products "
             "| mechc s | mechc cpu s | s before (cpu) | proven | parts per-output | parts now "
             "| parts before | products built |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]

    def opt(v, fmt="{}"):
        return "–" if v is None else fmt.format(v)

    for r in rows:
        lines.append(f"| {r['name']} | {r['inputs']} | {r['outputs']} | {r['products']} | "
                     f"{r['espresso']} | {r['before_products']} | {r['seconds']:.1f} | "
                     f"{r['cpu']:.1f} | {opt(r['seconds_baseline'], '{:.1f}')} "
                     f"({opt(r['cpu_baseline'], '{:.1f}')}) | "
                     f"{'yes' if r['proven'] else 'no'} | {r['parts_before']} | "
                     f"{r['parts_after']} | {opt(r['parts_baseline'])} | {r['built_products']} |")
    sources = sorted({r["source"] for r in rows})
    lines.append("")
    lines.append(f"espresso counts: {', '.join(sources)} (pyeda: the original espresso run "
                 "in the same process).")
    return "\n".join(lines)


def write_doc(table: str, begin: str = BEGIN, end: str = END) -> None:
    text = DOC.read_text()
    a, b = text.index(begin) + len(begin), text.index(end)
    DOC.write_text(text[:a] + "\n" + table + "\n" + text[b:])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dir", nargs="?", default=str(ROOT / "tests" / "logic" / "pla"),
                    help="directory of .pla files (default: the small PLAs of the tests)")
    ap.add_argument("--max-inputs", type=int, default=16)
    ap.add_argument("--only", nargs="*", help="PLA names (file stems) to run")
    ap.add_argument("--json", metavar="FILE", help="write every row (and the steps whose "
                    "time limit ran out) to FILE")
    ap.add_argument("--markdown", action="store_true",
                    help="rewrite the table in docs/minimisation.md")
    ap.add_argument("--random", type=int, metavar="N",
                    help="N random MCNC-shaped PLAs instead of DIR (needs pyeda)")
    ap.add_argument("--seed", type=int, default=1, help="seed of --random")
    ap.add_argument("--wall-limit", type=float, metavar="S",
                    help="the minimiser's hard end in seconds (0: none; default: its own), "
                    "to see what a PLA needs apart from the load")
    args = ap.parse_args(argv)
    if args.random:
        return main_random(args)
    paths = sorted(Path(args.dir).glob("*.pla"))
    if args.only:
        paths = [p for p in paths if p.stem in args.only]
    paths = [p for p in paths if parse_pla_file(p).n <= args.max_inputs]
    if not paths:
        print(f"no PLA of at most {args.max_inputs} inputs in {args.dir}", file=sys.stderr)
        return 2
    rows = run(paths)
    worse = [r["name"] for r in rows if r["espresso"] is not None
             and r["products"] > r["espresso"]]
    slow = [r["name"] for r in rows if r["seconds"] > MAX_SECONDS]
    more_parts = [r["name"] for r in rows if r["parts_after"] > r["parts_before"]]
    above = [r["name"] for r in rows if r["parts_baseline"] is not None
             and r["parts_after"] > r["parts_baseline"]]
    print(f"more products than espresso: {worse or 'none'}; over 10 s: {slow or 'none'}; "
          f"more parts than per-output: {more_parts or 'none'}; "
          f"more parts than before the speed-up: {above or 'none'}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    if args.markdown:
        write_doc(markdown(rows))
        print(f"wrote the table in {DOC.relative_to(ROOT)}")
    return 1 if worse else 0


def main_random(args) -> int:
    opts = None
    if args.wall_limit is not None:
        opts = MinimiseOptions(wall_limit=args.wall_limit or None)
    rows = run_random(args.random, args.seed, opts)
    done = [r for r in rows if "error" not in r]
    if any(r["source"] == "published" for r in done):
        print("--random needs pyeda (pip install -e '.[bench]')", file=sys.stderr)
        return 2
    worse = [r["name"] for r in done if r["espresso"] is not None
             and r["products"] > r["espresso"]]
    timeouts = [r["name"] for r in done if r["espresso"] is None]
    slow = [r["name"] for r in done if r["seconds"] > MAX_SECONDS]
    failed = [r["name"] for r in rows if "error" in r]
    fewer = sum(r["espresso"] is not None and r["products"] < r["espresso"] for r in done)
    print(f"{len(done)} PLAs: fewer products than espresso on {fewer}, more on "
          f"{worse or 'none'}; over {MAX_SECONDS:g} s: {slow or 'none'} (slowest "
          f"{max((r['seconds'] for r in done), default=0):.1f} s); errors: {failed or 'none'}"
          f"; espresso out of time ({ESPRESSO_TIMEOUT_S:g} s): {timeouts or 'none'}")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    if args.markdown:
        write_doc(markdown_random(rows, args.random, args.seed), RBEGIN, REND)
        print(f"wrote the random table in {DOC.relative_to(ROOT)}")
    return 1 if worse or slow or failed else 0


if __name__ == "__main__":
    sys.exit(main())
