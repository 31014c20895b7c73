"""Size, write and load time of a large design file: the compact layout and jsonschema-rs
against the indented layout and pure-Python jsonschema, measured in one run on one design.

    python benchmarks/design_file.py [--inputs 10] [--outputs 2] [--seed 1] [--examples]

Compiles a random spec (``--inputs`` inputs, ``--outputs`` outputs, each a random truth table
with 30 % ones and 5 % don't-cares) once in memory, then measures on that design:

- the file: bytes of the indented layout (``json.dumps(indent=2)``, what mechc wrote before)
  and of the compact one (:func:`mechc.backends.design_json.dumps_design`);
- writing it as compile does: serialise, check against the schema and the references, write;
  before: indented text, jsonschema; now: compact text re-read and checked with jsonschema-rs;
- loading it as simulate and draw do: read, parse, check numbers, schema and references, and
  build the Design; before with jsonschema, now with :func:`load_design_json`, on both layouts
  (an indented file of an earlier version still loads);
- ``mechc simulate FILE --level logic`` as a user runs it (a new process: start-up, load, the
  logic proof), on both layouts, and the logic proof alone;
- with ``--examples``, what the proofs compile now runs before writing (logic and kinematic)
  add to the compile of every example.

Every figure is CPU seconds of one run (other load on a shared machine does not inflate them);
ratios are against the "before" figure measured in the same run.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import jsonschema
import numpy as np

from mechc.backends.design_json import (
    check_cell_types,
    check_design,
    check_references,
    design_bytes,
    design_from_json,
    design_to_json,
    dumps_design,
    load_design_json,
    schema,
)
from mechc.cells.library import load_library
from mechc.frontends import load_spec
from mechc.passes.minimise import MinimiseOptions
from mechc.pipeline import CompileOptions, compile_spec
from mechc.proofs import prove

MECHC = Path(sys.executable).with_name("mechc")
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def random_spec(n: int, m: int, seed: int) -> str:
    """A .bool spec of ``m`` random outputs over ``n`` inputs (minterms and don't-cares)."""
    rng = np.random.default_rng(seed)
    names = [f"i{k}" for k in range(n)]
    lines = ["inputs " + " ".join(names), "outputs " + " ".join(f"o{j}" for j in range(m))]
    for j in range(m):
        t = rng.choice([0, 1, 2], size=1 << n, p=[0.65, 0.30, 0.05])
        on = ", ".join(str(i) for i in np.flatnonzero(t == 1))
        dc = ", ".join(str(i) for i in np.flatnonzero(t == 2))
        lines.append(f"o{j} = minterms({on})" + (f" dontcare({dc})" if dc else ""))
    return "\n".join(lines) + "\n"


def timed(fn, *args):
    """``fn(*args)`` and the CPU seconds it took (this process; other load on a shared machine
    does not count)."""
    t0 = time.process_time()
    out = fn(*args)
    return out, time.process_time() - t0


def old_numbers(obj) -> None:
    """The number check as it was: one walk that carries every value's path."""
    todo: list[tuple[object, tuple]] = [(obj, ())]
    while todo:
        o, path = todo.pop()
        if isinstance(o, dict):
            todo.extend((v, (*path, k)) for k, v in o.items())
        elif isinstance(o, list):
            todo.extend((v, (*path, i)) for i, v in enumerate(o))
        elif isinstance(o, float) and not (math.isfinite(o) and abs(o) <= 1e9):
            raise AssertionError(path)


def old_check(obj: dict, where: str) -> None:
    """The checks as they were: every number, the schema with jsonschema, the references."""
    old_numbers(obj)
    errors = list(jsonschema.Draft202012Validator(schema()).iter_errors(obj))
    assert not errors, errors[0].message
    check_references(obj, where)
    check_cell_types(obj, where)


def old_write(obj: dict, path: Path) -> None:
    old_check(obj, str(path))
    path.write_text(json.dumps(obj, indent=2, ensure_ascii=False) + "\n")


def new_write(obj: dict, path: Path) -> None:
    text = dumps_design(obj)
    check_design(json.loads(text), str(path))
    data = design_bytes(text, path)  # gzip-compressed for a .gz name
    path.write_bytes(data if isinstance(data, bytes) else data.encode())


def old_load(path: Path):
    obj = json.loads(path.read_bytes())
    old_check(obj, str(path))
    return design_from_json(obj, str(path))


def new_load(path: Path):
    return design_from_json(load_design_json(path), str(path))


def cli_seconds(*args) -> float:
    """CPU seconds of ``mechc ARGS`` run as a new process (start-up included)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([str(MECHC), *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"mechc {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def proofs_at_compile() -> list[tuple[str, int, float, float]]:
    """Per example: cells, CPU seconds of its compile, and of the proofs compile now runs on
    it (logic, and kinematic: every example is under the compile budget)."""
    lib = load_library()
    rows = []
    for path in sorted(EXAMPLES.iterdir()):
        if path.suffix not in (".bool", ".pla", ".blif", ".fsm", ".kiss2"):
            continue
        design, t_compile = timed(compile_spec, load_spec(str(path)))
        t_prove = 0.0
        for level in ("logic", "kinematic"):
            rep, t = timed(prove, design, design.spec, lib, level)
            t_prove += t
        rows.append((path.name, design.stats["cells"], t_compile, t_prove))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--inputs", type=int, default=10)
    ap.add_argument("--outputs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--keep", metavar="DIR", help="keep the spec and both files in DIR")
    ap.add_argument("--examples", action="store_true",
                    help="also the time compile's proofs add on every example")
    a = ap.parse_args()
    tmp = Path(a.keep) if a.keep else Path(tempfile.mkdtemp(prefix="design_file."))
    tmp.mkdir(parents=True, exist_ok=True)
    try:
        spec_path = tmp / "random.bool"
        spec_path.write_text(random_spec(a.inputs, a.outputs, a.seed))
        print(f"compiling {a.inputs}-input, {a.outputs}-output random spec (seed {a.seed}) ...",
              flush=True)
        opts = CompileOptions(minimise=MinimiseOptions(time_limit=1.0))
        design, t_compile = timed(compile_spec, load_spec(str(spec_path)), opts)
        obj = design_to_json(design)
        print(f"  {design.stats['cells']} cells, compiled in {t_compile:.1f} s")
        old, new, gz = tmp / "indented.json", tmp / "compact.json", tmp / "compact.json.gz"
        _, w_old = timed(old_write, obj, old)
        _, w_new = timed(new_write, obj, new)
        _, w_gz = timed(new_write, obj, gz)
        s_old, s_new, s_gz = old.stat().st_size, new.stat().st_size, gz.stat().st_size
        assert json.loads(old.read_bytes()) == json.loads(new.read_bytes())  # same content
        d_old, l_old = timed(old_load, old)
        _, l_new = timed(new_load, new)
        _, l_new_old = timed(new_load, old)
        _, l_gz = timed(new_load, gz)
        lib = load_library()
        rep, t_proof = timed(prove, d_old, d_old.spec, lib, "logic")
        assert rep.passed, rep.summary_text()
        sim_old = cli_seconds("simulate", old, "--level", "logic")
        sim_new = cli_seconds("simulate", new, "--level", "logic")
        sim_gz = cli_seconds("simulate", gz, "--level", "logic")
        rows = [
            ("file size (MB)", s_old / 1e6, s_new / 1e6, s_gz / 1e6),
            ("write: serialise + check + write (s)", w_old, w_new, w_gz),
            ("load: parse + check + Design (s)", l_old, l_new, l_gz),
            ("simulate --level logic, whole command (s)", l_old + t_proof, sim_new, sim_gz),
        ]
        print(f"\n| {a.inputs}-input random spec, {design.stats['cells']} cells | before | now "
              "| before / now | now, .json.gz |\n|---|---:|---:|---:|---:|")
        for name, b, n, z in rows:
            print(f"| {name} | {b:.2f} | {n:.2f} | {b / n:.1f}x | {z:.2f} |")
        print(f"\nCPU seconds. before = indented JSON, jsonschema; now = compact layout, "
              "jsonschema-rs. "
              f"The logic proof alone: {t_proof:.2f} s. 'simulate' before is its load plus the "
              f"proof (in this process); now is the whole command in a new process "
              f"({sim_new:.2f} s; on the indented file of before: {sim_old:.2f} s). An indented "
              f"file loads now in {l_new_old:.2f} s.")
        if a.examples:
            rows = proofs_at_compile()
            print("\n| example | cells | compile (s) | proofs at compile (s) | added |\n"
                  "|---|---:|---:|---:|---:|")
            for name, cells, tc, tp in rows:
                print(f"| {name} | {cells} | {tc:.2f} | {tp:.2f} | {100 * tp / tc:.0f} % |")
            tc, tp = sum(r[2] for r in rows), sum(r[3] for r in rows)
            print(f"| all | | {tc:.2f} | {tp:.2f} | {100 * tp / tc:.0f} % |")
    finally:
        if not a.keep:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
