"""Random multi-output PLAs shaped like the MCNC two-level ones, for the minimiser's held-out set.

The MCNC PLAs are few (18 of at most 16 inputs); a minimiser tuned on them may still be slow
or worse than espresso on PLAs it never saw. These are drawn the way those files look: a
list of ``.type fd`` rows, each an input cube (every input 0, 1 or '-', the share of '-'
drawn per PLA so some PLAs have long products and some short ones) with an output part
feeding one to a few outputs ('1'), a few rows being don't-cares for some outputs ('-').
The same seed gives the same PLA text on every machine (numpy's PCG64).
"""

from __future__ import annotations

import numpy as np


def random_pla(rng: np.random.Generator, n: int, m: int, rows: int,
               free: float | None = None, dc_rows: float = 0.1) -> str:
    """PLA text: ``n`` inputs, ``m`` outputs, ``rows`` rows; ``free`` the chance an input is
    '-' in a row (drawn in 0.25..0.65 when None); ``dc_rows`` the share of rows that are
    don't-cares (for one to two of their outputs). Every output has at least one on-row."""
    if free is None:
        free = float(rng.uniform(0.25, 0.65))
    lines = [f".i {n}", f".o {m}", ".type fd", f".p {rows}"]
    cubes = np.where(rng.random((rows, n)) < free, "-",
                     np.where(rng.random((rows, n)) < 0.5, "1", "0"))
    outs = np.full((rows, m), "0")
    dc = rng.random(rows) < dc_rows
    for r in range(rows):
        # most rows feed one output, some several (MCNC rows share products between outputs)
        k = min(m, int(rng.geometric(0.55)))
        outs[r, rng.choice(m, size=k, replace=False)] = "-" if dc[r] else "1"
    on_rows = np.flatnonzero(~dc) if (~dc).any() else np.arange(rows)
    for j in np.flatnonzero(~(outs == "1").any(axis=0)):  # every output gets an on-row
        outs[int(rng.choice(on_rows)), j] = "1"
    for r in range(rows):
        lines.append("".join(cubes[r]) + " " + "".join(outs[r]))
    lines.append(".e")
    return "\n".join(lines) + "\n"


def random_set(count: int, seed: int, min_inputs: int = 8, max_inputs: int = 16,
               min_outputs: int = 5, max_outputs: int = 40, min_rows: int = 20,
               max_rows: int = 500) -> list[tuple[str, str]]:
    """``count`` (name, PLA text) pairs, sizes drawn uniformly in the given ranges."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        n = int(rng.integers(min_inputs, max_inputs + 1))
        m = int(rng.integers(min_outputs, max_outputs + 1))
        rows = int(rng.integers(min_rows, max_rows + 1))
        out.append((f"r{seed}_{k}_i{n}o{m}p{rows}", random_pla(rng, n, m, rows)))
    return out
