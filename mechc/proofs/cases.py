"""Which input changes a proof exercises: every vector, every single-input change, Gray tours."""

from __future__ import annotations

import numpy as np


def bits(rows: np.ndarray, n: int) -> np.ndarray:
    """(n, len(rows)) 0/1 matrix, input 0 the most significant bit."""
    shifts = np.arange(n - 1, -1, -1, dtype=np.int64)[:, None]
    return ((rows[None, :] >> shifts) & 1).astype(float)


def single_changes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Every single-input change as (row with the input off, input index)."""
    rows, ks = [], []
    idx = np.arange(1 << n, dtype=np.int64)
    for k in range(n):
        bit = 1 << (n - 1 - k)
        low = idx[(idx & bit) == 0]
        rows.append(low)
        ks.append(np.full(len(low), k))
    return np.concatenate(rows), np.concatenate(ks)


def gray_tour(n: int) -> list[int]:
    """All 2**n vectors, each differing from the last in one input (reflected Gray code)."""
    return [i ^ (i >> 1) for i in range(1 << n)]


def random_walk(n: int, start: int, steps: int, seed: int) -> list[int]:
    """Seeded random single-input changes from ``start`` (deterministic for a seed)."""
    rng = np.random.default_rng(seed)
    out, cur = [], int(start)
    for _ in range(steps):
        cur ^= 1 << int(rng.integers(n))  # Python ints: any number of inputs
        out.append(cur)
    return out
