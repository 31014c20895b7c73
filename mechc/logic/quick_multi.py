"""A quick multi-output cover: espresso's EXPAND and IRREDUNDANT once, on the ternary table.

The multi-output step (``multi.py``) finds the fewest distinct products, but its preparation
(every multi-output prime, the whole covering matrix) has no time check; when the hard end
of the minimisation stops it, the per-output covers were all that was left (on random
MCNC-shaped PLAs 10-30 % more products than espresso). This is the cheap answer to keep in
hand first: every cube of the given covers (each output's own cover, a PLA's rows with the
outputs they feed) is raised to a multi-output prime by the ternary table (literals dropped
while every output it serves keeps it inside its region: EXPAND), and a cover of every
(output, on-minterm) row is chosen among those primes by greedy set cover and redundancy
removal (IRREDUNDANT), or each given cover's raised cubes made irredundant, whichever has
fewest products. Only the given cubes' primes enter the matrix, so it stays small.
"""

from __future__ import annotations

import numpy as np

from mechc.logic.cubes import Cube
from mechc.logic.implicants import (
    cover_matrix,
    decode,
    raise_to_primes,
    region_sets,
    table_fits,
    ternary_table,
)
from mechc.logic.setcover import heuristic_cover

#: Past this many (cube, minterm) pairs the matrix is not built (None is returned).
MAX_PAIRS = 20_000_000


def quick_multi_cover(n: int, on: np.ndarray, region: np.ndarray,
                      covers: list[list[list[Cube]]],
                      time_limit: float = 0.0) -> list[list[Cube]] | None:
    """Cubes per output of a multi-output cover built from the cubes of ``covers`` (each a
    valid cover per output; a cube listed for several outputs serves them all).

    ``on`` and ``region`` are (m, 2**n) booleans (region = on ∪ dc). ``time_limit`` > 0 adds
    that long of row weighting local search after the greedy cover. None when the ternary
    table or the matrix would be too large."""
    m = on.shape[0]
    if m == 0 or not table_fits(n, m):
        return None
    T = ternary_table(region_sets(region), n, m)
    raised = []  # each cover's cubes raised to primes (ternary indices)
    for cover in covers:
        merged: dict[Cube, int] = {}
        for i, cubes in enumerate(cover):
            for c in cubes:
                merged[c] = merged.get(c, 0) | (1 << i)
        if merged:
            cm = np.array([c.mask for c in merged], dtype=np.int64)
            cv = np.array([c.value for c in merged], dtype=np.int64)
            raised.append(raise_to_primes(
                cm, cv, np.array(list(merged.values()), dtype=np.int64), T, n))
    if not raised:
        return [[] for _ in range(m)]
    idx = np.unique(np.concatenate(raised))
    masks, values = decode(idx, n)
    outs = T[idx].astype(np.int64)
    free = n - np.bitwise_count(masks.astype(np.uint64)).astype(np.int64)
    if float(np.ldexp(1.0, free).sum()) > MAX_PAIRS:
        return None
    A = cover_matrix(masks, values, outs, on, n)
    if A.shape[0] == 0:
        return [[] for _ in range(m)]
    cost = 1 + np.bitwise_count(masks.astype(np.uint64)).astype(np.int64)
    A = A.tocsr()
    # greedy, and each given cover raised (made irredundant): the fewest products wins, so
    # the result never has more than any cover it was given
    tries = [heuristic_cover(A, cost, time_limit)]
    tries += [heuristic_cover(A, cost, 0.0, start=np.searchsorted(idx, np.unique(r)))
              for r in raised]
    chosen = min(tries, key=lambda c: (len(c), int(cost[c].sum())))
    full = A.tocsc()
    blocks = np.concatenate([[0], np.cumsum(on.sum(axis=1))]).astype(np.int64)
    result = []
    for i in range(m):
        # output i ORs the chosen products it may use that cover one of its on-minterms
        rows = full[blocks[i]:blocks[i + 1]][:, chosen]
        useful = chosen[np.asarray(rows.sum(axis=0)).ravel() > 0]
        result.append([Cube(int(masks[k]), int(values[k])) for k in useful])
    return result
