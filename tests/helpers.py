"""Shared test helpers: subprocess runs, random truth tables, spec text writers."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def run_subprocess(*args: str, cwd=None):
    return subprocess.run([sys.executable, "-m", "mechc", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd)


def random_table(rng: np.random.Generator, n: int, p_on=0.4, p_dc=0.1) -> np.ndarray:
    """0/1/2 truth table (2 = don't care)."""
    return rng.choice([0, 1, 2], size=1 << n, p=[1 - p_on - p_dc, p_on, p_dc]).astype(np.int8)


def bool_text(inputs, tables: dict[str, np.ndarray]) -> str:
    lines = ["inputs " + " ".join(inputs), "outputs " + " ".join(tables)]
    for name, t in tables.items():
        on = ", ".join(str(i) for i in np.flatnonzero(t == 1))
        dc = ", ".join(str(i) for i in np.flatnonzero(t == 2))
        lines.append(f"{name} = minterms({on})" + (f" dontcare({dc})" if dc else ""))
    return "\n".join(lines) + "\n"


def pla_text(inputs, tables: dict[str, np.ndarray], shuffle_rng=None) -> str:
    """Type fd PLA with one minterm row per on/dc minterm and output (each row names one output)."""
    n = len(inputs)
    outs = list(tables)
    rows = []
    for j, (_name, t) in enumerate(tables.items()):
        for m in np.flatnonzero(t != 0):
            bits = format(int(m), f"0{n}b")
            plane = ["~"] * len(outs)  # '~': not in any set for this output
            plane[j] = "1" if t[m] == 1 else "-"
            rows.append(f"{bits} {''.join(plane)}")
    if shuffle_rng is not None:
        shuffle_rng.shuffle(rows)
    return "\n".join([f".i {n}", f".o {len(outs)}", ".ilb " + " ".join(inputs),
                      ".ob " + " ".join(outs), ".type fd", f".p {len(rows)}", *rows, ".e"]) + "\n"


def amplified_and(lib):
    """(netlist, spec) of z = a & b with a force AMPLIFIER on a: the smallest design whose
    timing goes through a toggle, built by hand because compile puts none on so light a load."""
    from mechc.frontends.boolfile import parse_bool
    from mechc.ir.netlist import CellInst, Netlist

    nl = Netlist(["a", "b"])
    nl.add_cell(CellInst("g1", "amplifier", "AMPLIFIER", ("a",), ("n1",), {"reason": "force"}),
                pin_names=lib["amplifier"].input_names(1))
    nl.add_cell(CellInst("g2", "and", "AND", ("n1", "b"), ("z",)),
                pin_names=lib["and"].input_names(2))
    nl.set_output("z", "z")
    return nl, parse_bool("inputs a b\noutputs z\nz = a & b\n", "<amplified>")
